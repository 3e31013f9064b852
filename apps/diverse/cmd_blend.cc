// `diverse blend RUN [--samples K] [--seed S] [--path-points P] [--threads T]`: simulates
// K convex combinations of a finished run's controllers (and, for a run whose shape
// varied, of its bodies) and writes RUN/blend/: how much of the simplex between the found
// motions still meets the task, each blend's distance to every motion, and each blend as
// a motion file that `diverse gallery` plays. See run/blend.h.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "command.h"
#include "options.h"
#include "run/blend.h"

namespace diverse::cli {
namespace {

struct BlendArgs {
  std::string run;
  int samples = 64;
  std::uint64_t seed = 1;
  int path_points = 16;
  int threads = 0;
};

void install(CLI::App& app) {
  auto args = std::make_shared<BlendArgs>();
  CLI::App* cmd = app.add_subcommand("blend", "Simulate convex combinations of a finished run's controllers");
  cmd->footer("Example:\n"
              "  diverse blend runs/jump_high --samples 64");
  cmd->add_option("run", args->run, "Run directory written by `diverse run`")->required();
  cmd->add_option("--samples", args->samples, "Blends K, weights drawn uniformly on the simplex of M0..MN")
      ->check(integer_in(1, 100000))
      ->capture_default_str();
  cmd->add_option("--seed", args->seed, "Seed of the blends' weights")
      ->check(unsigned_integer())
      ->capture_default_str();
  cmd->add_option("--path-points", args->path_points,
                  "Points of each variation's optimization path simulated for comparison (0 = none)")
      ->check(integer_in(0, 10000))
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "Simulation threads (0 = one per core)")
      ->check(integer_in(0, kMaxThreads))
      ->capture_default_str();
  cmd->callback([args] {
    BlendOptions options;
    options.samples = args->samples;
    options.seed = args->seed;
    options.path_points = args->path_points;
    options.threads = args->threads;
    const auto start = std::chrono::steady_clock::now();
    const nlohmann::json s = write_blend(args->run, options);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const auto& paths = s["paths"];
    const std::string file = (std::filesystem::path(args->run) / "blend" / "summary.json").string();
    std::printf("%s: %d of %d blends meet the task (%.1f %%)", file.c_str(),
                s["feasible"].get<int>(), s["samples"].get<int>(), 100.0 * s["feasible_fraction"].get<double>());
    if (paths["points"].get<int>() > 0)
      std::printf("; path points: %d of %d (%.1f %%)", paths["feasible"].get<int>(), paths["points"].get<int>(),
                  100.0 * paths["feasible_fraction"].get<double>());
    std::printf("; %.1f s\n", seconds);
  });
}

const bool registered = register_command(63, install);

}  // namespace
}  // namespace diverse::cli
