// 3D motions for the viewing and export tests, made without a 3D task: a character of
// assets/characters standing under stance control (control/stance_controller.h) from an
// initial root velocity (a push; never an external force), or walking under SIMBICON
// control (skills/walk3d.toml on the skill engine), recorded for exact replay, and run directories of
// such motions laid out as `diverse run` writes one (run.json, summary.json,
// motions/m<i>.json with model/m<i>.xml), so render, gallery and export read them as any
// run. Stance motions have no phases; walks have their states. Neither has distances.
#pragma once

#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "physics/model.h"
#include "physics/rollout.h"

namespace diverse::test_support {

struct StanceMotion {
  std::shared_ptr<const SharedModel> model;
  StepRecorder record;
};

// `character` names assets/characters/<character>.toml; `push` is the root's initial linear
// velocity (m/s, world); `seconds` of simulation at the model's timestep.
StanceMotion stance_motion(const std::string& character, const std::array<double, 3>& push,
                           double seconds);

// A run directory at `dir` (made, or emptied first) with one motion per push, M0 first.
void write_stance_run(const std::filesystem::path& dir, const std::string& character,
                      const std::vector<std::array<double, 3>>& pushes, double seconds);

// A walk: `character` under SIMBICON walking (its walk task's skill file) with the parameters
// of tasks/<parameters> from its static start, until `steps` swing-foot touch-downs (or a
// fall), recorded for exact replay. Its phases are every state the walk entered, in order
// (the names repeat stride after stride).
struct WalkMotion {
  std::shared_ptr<const SharedModel> model;
  StepRecorder record;
  std::vector<std::pair<std::string, double>> phases;  // state name, begin time (s)
};
WalkMotion walk_motion(const std::string& character, const std::string& parameters, int steps);

// A run directory of one walk per entry of `parameters` (tasks/ files), M0 first.
void write_walk_run(const std::filesystem::path& dir, const std::string& character,
                    const std::vector<std::string>& parameters, int steps);

}  // namespace diverse::test_support
