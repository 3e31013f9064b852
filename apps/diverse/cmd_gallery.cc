// `diverse gallery RUN [--no-paths] [--no-blends] [--threads N]`: one self-contained HTML page,
// RUN/gallery.html, with all motions of a finished run side by side in 3D, their
// constraint values and distances, each variation's optimization path, and the run's
// blends when `diverse blend RUN` made them. Opens from disk
// in any browser, without network. See render/gallery.h and docs/guide/viewing-results.md.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "command.h"
#include "options.h"
#include "core/error.h"
#include "render/gallery.h"

namespace diverse::cli {
namespace {

struct GalleryArgs {
  std::string run;
  bool no_paths = false;
  bool no_blends = false;
  int threads = 0;
};

void install(CLI::App& app) {
  auto args = std::make_shared<GalleryArgs>();
  CLI::App* cmd = app.add_subcommand("gallery", "Interactive 3D gallery of a finished run (one HTML file)");
  cmd->footer("Example:\n"
              "  diverse gallery runs/jump_high       # writes runs/jump_high/gallery.html");
  cmd->add_option("run", args->run, "Run directory written by `diverse run`")->required();
  cmd->add_flag("--no-paths", args->no_paths,
                "Leave out the optimization paths (they are simulated from the run's task file)");
  cmd->add_flag("--no-blends", args->no_blends, "Leave out the run's blends (made by `diverse blend RUN`)");
  cmd->add_option("--threads", args->threads, "Simulation threads (0 = one per core)")
      ->check(integer_in(0, kMaxThreads))
      ->capture_default_str();
  cmd->callback([args] {
    if (args->threads < 0) throw UserError("--threads: expected 0 or more, got " + std::to_string(args->threads));
    GalleryOptions options;
    options.paths = !args->no_paths;
    options.blends = !args->no_blends;
    options.threads = args->threads;
    const std::filesystem::path page = write_gallery(args->run, options);
    std::printf("%s  (%.1f MB; open it in a browser)\n", page.string().c_str(),
                static_cast<double>(std::filesystem::file_size(page)) / 1e6);
  });
}

const bool registered = register_command(61, install);

}  // namespace
}  // namespace diverse::cli
