// 3D motions for the viewing and export tests, made without a 3D task: a character of
// assets/characters standing under stance control (control/stance_controller.h) from an
// initial root velocity (a push; never an external force), recorded for exact replay, and
// a run directory of such motions laid out as `diverse run` writes one (run.json,
// summary.json, motions/m<i>.json with model/m<i>.xml), so render, gallery and export read
// it as any run. The motions have no phases (stance control has none) and no distances.
#pragma once

#include <array>
#include <filesystem>
#include <memory>
#include <string>
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

}  // namespace diverse::test_support
