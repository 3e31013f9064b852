// `diverse export RUN --bvh --gltf [--fps 30|60]`: every motion of a finished run for
// animation and 3D tools: RUN/export/m<i>.bvh (a skeleton and its channels, io/bvh.h) and
// RUN/export/m<i>.glb (glTF 2.0: a skinned character, a bone per body with the bodies' own
// meshes and colours, animated, io/gltf.h), plus RUN/export/all.glb with every motion side
// by side. Metres, Y up; see docs/guide/engines.md for Blender and game engines.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "command.h"
#include "options.h"
#include "core/error.h"
#include "finished/run_view.h"
#include "io/bvh.h"
#include "io/gltf.h"

namespace diverse::cli {
namespace {

struct ExportArgs {
  std::string run;
  bool bvh = false;
  bool gltf = false;
  int fps = 30;
};

void install(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* cmd = app.add_subcommand("export", "Export a finished run's motions for animation tools");
  cmd->footer("Example:\n"
              "  diverse export runs/jump_high --bvh --gltf");
  cmd->add_option("run", args->run, "Run directory written by `diverse run`")->required();
  cmd->add_flag("--bvh", args->bvh, "BVH files (RUN/export/m<i>.bvh), metres, Y up");
  cmd->add_flag("--gltf", args->gltf,
                "glTF 2.0 binary files of skinned characters, a bone per body (RUN/export/m<i>.glb "
                "and all.glb, every motion side by side), metres, Y up");
  cmd->add_option("--fps", args->fps, "Frames per second: 30 or 60")->capture_default_str();
  cmd->callback([args] {
    if (!args->bvh && !args->gltf) throw UserError("export: choose a format: --bvh, --gltf or both");
    if (args->fps != 30 && args->fps != 60)
      throw UserError("--fps: expected 30 or 60, got " + std::to_string(args->fps));
    const RunView run = load_run_view(args->run);
    const auto stem = [](const RunMotion& m) { return std::string("m").append(std::to_string(m.index)); };
    std::vector<GltfMotion> all;
    for (const RunMotion& m : run.motions) {
      const auto frames = m.sample(args->fps);
      if (args->bvh) {
        const Bvh bvh = bvh_from_model(m.model->get(), frames, args->fps);
        const auto path = run.dir / "export" / (stem(m) + ".bvh");
        write_bvh(path, bvh);
        std::printf("%s  (%d joints, %d frames at %d fps)\n", path.string().c_str(),
                    static_cast<int>(bvh.joints.size()), bvh.frame_count(), args->fps);
      }
      if (args->gltf) {
        GltfOptions options;
        options.fps = args->fps;
        const auto path = run.dir / "export" / (stem(m) + ".glb");
        write_glb(path, {GltfMotion{m.model->get(), frames, m.label, {0, 0, 0}}}, options);
        std::printf("%s  (%d bodies, %d frames at %d fps)\n", path.string().c_str(),
                    m.model->get()->nbody - 1, static_cast<int>(frames.size()), args->fps);
        all.push_back(GltfMotion{m.model->get(), frames, m.label, {0, 0, 0}});
      }
    }
    if (args->gltf) {
      // Side by side along MuJoCo's -y (to the characters' right), M0 nearest the origin.
      const double spacing = side_by_side_spacing(all);
      for (std::size_t i = 0; i < all.size(); ++i) all[i].offset = {0, -spacing * static_cast<double>(i), 0};
      GltfOptions options;
      options.fps = args->fps;
      const auto path = run.dir / "export" / "all.glb";
      write_glb(path, all, options);
      std::printf("%s  (%d motions side by side, %.2f m apart)\n", path.string().c_str(),
                  static_cast<int>(all.size()), spacing);
    }
  });
}

const bool registered = register_command(62, install);

}  // namespace
}  // namespace diverse::cli
