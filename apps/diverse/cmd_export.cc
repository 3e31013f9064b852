// `diverse export RUN --bvh [--fps 30|60]`: every motion of a finished run as a BVH file,
// RUN/export/m<i>.bvh, for animation tools (Blender: File > Import > Motion Capture (.bvh)).
// Metres, Y up; see io/bvh.h and docs/viewing-results.md.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>
#include <string>

#include "command.h"
#include "options.h"
#include "core/error.h"
#include "io/bvh.h"
#include "render/run_media.h"

namespace diverse::cli {
namespace {

struct ExportArgs {
  std::string run;
  bool bvh = false;
  int fps = 30;
};

void install(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* cmd = app.add_subcommand("export", "Export a finished run's motions for animation tools");
  cmd->add_option("run", args->run, "Run directory written by `diverse run`")->required();
  cmd->add_flag("--bvh", args->bvh, "BVH files (RUN/export/m<i>.bvh), metres, Y up");
  cmd->add_option("--fps", args->fps, "Frames per second: 30 or 60")->capture_default_str();
  cmd->callback([args] {
    if (!args->bvh) throw UserError("export: choose a format: --bvh");
    if (args->fps != 30 && args->fps != 60)
      throw UserError("--fps: expected 30 or 60, got " + std::to_string(args->fps));
    const RunView run = load_run_view(args->run);
    for (const RunMotion& m : run.motions) {
      const Bvh bvh = bvh_from_model(m.model->get(), m.sample(args->fps), args->fps);
      const auto path = run.dir / "export" / (std::string("m").append(std::to_string(m.index)).append(".bvh"));
      write_bvh(path, bvh);
      std::printf("%s  (%d joints, %d frames at %d fps)\n", path.string().c_str(),
                  static_cast<int>(bvh.joints.size()), bvh.frame_count(), args->fps);
    }
  });
}

const bool registered = register_command(62, install);

}  // namespace
}  // namespace diverse::cli
