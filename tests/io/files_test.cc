#include "io/files.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <fstream>

#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/rng.h"
#include "support/scratch.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = test_files::scratch_dir("files_test_" + name);
  return dir;
}

TEST(WriteFileAtomic, CreatesParentsAndLeavesNoTemporaries) {
  const fs::path dir = scratch("atomic");
  write_file_atomic(dir / "a" / "b.txt", "hello");
  write_file_atomic(dir / "a" / "b.txt", "again");
  EXPECT_EQ(read_file(dir / "a" / "b.txt"), "again");
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir / "a")) {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 1);
}

TEST(WriteJsonAtomic, DoublesRoundTripBitExactly) {
  const fs::path dir = scratch("json");
  Rng rng(99);
  nlohmann::json values = nlohmann::json::array();
  std::vector<double> originals;
  for (int i = 0; i < 2000; ++i) {
    const double x = (rng.uniform() - 0.5) * std::pow(10.0, static_cast<int>(rng.uniform() * 40) - 20);
    originals.push_back(x);
    values.push_back(x);
  }
  originals.push_back(std::numeric_limits<double>::denorm_min());
  values.push_back(std::numeric_limits<double>::denorm_min());
  write_json_atomic(dir / "v.json", values);
  const nlohmann::json back = read_json(dir / "v.json");
  ASSERT_EQ(back.size(), originals.size());
  for (std::size_t i = 0; i < originals.size(); ++i)
    EXPECT_EQ(back[i].get<double>(), originals[i]) << i;
}

TEST(ReadFile, MissingFileIsAOneLineUserError) {
  try {
    read_file("/nonexistent/dir/x.json");
    FAIL();
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/dir/x.json: cannot read (No such file or directory)");
  }
}

TEST(ReadJson, MalformedJsonNamesTheFile) {
  const fs::path dir = scratch("bad");
  write_file_atomic(dir / "bad.json", "{\"a\": [1, 2,");
  try {
    read_json(dir / "bad.json");
    FAIL();
  } catch (const UserError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind((dir / "bad.json").string() + ": not valid JSON (parse error", 0), 0u)
        << what;
    EXPECT_EQ(what.find('\n'), std::string::npos);
  }
}

TEST(ReadJson, ANumberTooLargeForADoubleIsAnErrorNotACrash) {
  const fs::path dir = scratch("huge");
  write_file_atomic(dir / "huge.json", "{\"a\": 1e999}");
  try {
    read_json(dir / "huge.json");
    FAIL();
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()).rfind((dir / "huge.json").string() + ": not valid JSON (", 0), 0u) << e.what();
  }
}

TEST(ReadFile, DirectoriesAndDevicesAreOneLineErrors) {
  const fs::path dir = scratch("dir");
  fs::create_directories(dir);
  fs::create_directories(dir / "sub");
  try {
    read_file(dir / "sub");
    FAIL();
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()), (dir / "sub").string() + ": cannot read (it is a directory)");
  }
  try {
    read_file("/dev/zero");  // would never end
    FAIL();
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(), "/dev/zero: cannot read (not a regular file)");
  }
}

TEST(RemoveStaleTemporaries, RemovesOnlyThoseOfProcessesThatAreGone) {
  const fs::path dir = scratch("stale");
  fs::create_directories(dir);
  // PID 2^22 + 1 is above Linux's largest pid_max: no such process.
  const fs::path dead = dir / "checkpoint.json.tmp.4194305.0";
  const fs::path alive = dir / ("checkpoint.json.tmp." + std::to_string(::getpid()) + ".3");
  const fs::path other = dir / "notes.tmp.txt";
  for (const fs::path& p : {dead, alive, other}) std::ofstream(p) << "x";
  EXPECT_EQ(remove_stale_temporaries(dir), 1);
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_TRUE(fs::exists(alive));
  EXPECT_TRUE(fs::exists(other));
}

TEST(EnsureWritableDirectory, RefusesAPathThatIsAFile) {
  const fs::path dir = scratch("notdir");
  write_file_atomic(dir / "file", "x");
  EXPECT_THROW(ensure_writable_directory(dir / "file"), UserError);
  EXPECT_NO_THROW(ensure_writable_directory(dir / "sub" / "dir"));
}

}  // namespace
}  // namespace diverse
