// `diverse render RUN [--half-speed] [--no-video] [--fps 30|60]`: the run's film strip
// (RUN/filmstrip.png, the paper's figure 5) and videos (RUN/videos/m<i>.mp4 per motion,
// RUN/videos/all.mp4 with all motions side by side), drawn from the recorded motions.
// See render/run_media.h and docs/guide/viewing-results.md.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>
#include <string>

#include "command.h"
#include "options.h"
#include "core/error.h"
#include "finished/run_view.h"
#include "render/run_media.h"

namespace diverse::cli {
namespace {

struct RenderArgs {
  std::string run;
  bool half_speed = false;
  bool no_video = false;
  int fps = 30;
};

void install(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "Film strip and videos of a finished run");
  cmd->footer("Example:\n"
              "  diverse render runs/jump_high --half-speed");
  cmd->add_option("run", args->run, "Run directory written by `diverse run`")->required();
  cmd->add_flag("--half-speed", args->half_speed, "Videos at half speed");
  cmd->add_flag("--no-video", args->no_video, "Only the film strip");
  cmd->add_option("--fps", args->fps, "Video frame rate: 30 or 60")->capture_default_str();
  cmd->callback([args] {
    if (args->fps != 30 && args->fps != 60)
      throw UserError("--fps: expected 30 or 60, got " + std::to_string(args->fps));
    const RunView run = load_run_view(args->run);
    if (!run.task_note.empty())
      std::fprintf(stderr, "diverse: warning: landing region not drawn: %s\n", run.task_note.c_str());
    const auto strip = run.dir / "filmstrip.png";
    write_run_film_strip(run, strip);
    std::printf("%s\n", strip.string().c_str());
    if (args->no_video) return;
    RunVideoOptions options;
    options.fps = args->fps;
    options.speed = args->half_speed ? 0.5 : 1.0;
    for (const auto& path : write_run_videos(run, options)) std::printf("%s\n", path.string().c_str());
  });
}

const bool registered = register_command(60, install);

}  // namespace
}  // namespace diverse::cli
