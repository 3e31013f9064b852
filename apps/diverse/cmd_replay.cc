// `diverse replay DIR/motion.json`: loads the motion's saved model in plain MuJoCo, sets
// the recorded initial state, replays the recorded inputs with mj_step and reports the
// largest |qpos difference| from the recorded trajectory. Exits 1 if it exceeds 1e-6.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "command.h"
#include "io/motion_record.h"

namespace diverse::cli {
namespace {

constexpr double kTolerance = 1e-6;

void install(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("replay", "Replay a motion record in plain MuJoCo and compare qpos");
  cmd->add_option("motion", *path, "motion.json written by simulate or run")->required();
  cmd->callback([path] {
    int steps = 0;
    const double diff = replay_motion_file(*path, &steps);
    std::printf("replayed %d steps, max |qpos difference| = %.3g\n", steps, diff);
    if (!(diff <= kTolerance)) {
      std::fprintf(stderr, "diverse: replay differs from the record by more than %g\n", kTolerance);
      std::exit(1);
    }
  });
}

const bool registered = register_command(51, install);

}  // namespace
}  // namespace diverse::cli
