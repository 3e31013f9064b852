// Shared pieces of the libFuzzer targets (fuzz/*_fuzzer.cc).
//
// Every target hands one input to one of the readers users feed files to, written to a
// file first because the readers take paths (and resolve the paths inside the file
// relative to it). A reader may throw UserError (a clean one-line error, exit code 2 in
// the tool): that is the expected answer to a bad file. Any other exception escapes the
// target, so libFuzzer reports it as a crash: the tool would have printed "internal
// error" for that input.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace diverse::fuzz {

// A private scratch directory (removed at exit) holding `subdir`, in which every file
// of the source tree's `mirror` directory appears as a symbolic link, so that relative
// paths in the corpus ("../assets/characters/human2d.toml") resolve as they do in the
// source tree.
class Scratch {
 public:
  Scratch(const std::string& subdir, const std::string& mirror) {
    namespace fs = std::filesystem;
    std::string pattern = (fs::temp_directory_path() / "diverse-fuzz-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) std::abort();
    root_ = pattern;
    const fs::path source(DIVERSE_SOURCE_DIR);
    fs::create_symlink(source / "assets", root_ / "assets");
    fs::create_directories(root_ / subdir);
    if (!mirror.empty()) {
      for (const auto& entry : fs::directory_iterator(source / mirror)) {
        const fs::path link = root_ / subdir / entry.path().filename();
        if (!fs::exists(link)) fs::create_symlink(entry.path(), link);
      }
    }
    dir_ = root_ / subdir;
  }
  ~Scratch() {
    std::error_code ec;
    std::filesystem::remove_all(root_, ec);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;

  const std::filesystem::path& dir() const { return dir_; }

  // Writes the input to dir()/name and returns its path.
  std::string write(const std::string& name, const uint8_t* data, size_t size) const {
    const std::filesystem::path path = dir_ / name;
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    return path.string();
  }

 private:
  std::filesystem::path root_, dir_;
};

}  // namespace diverse::fuzz
