// Which moments of a jump a film strip shows: the phase events, the same in every row
// (paper figure 5 labels its columns A-F by phase, not by time).
#pragma once

#include <string>
#include <vector>

#include "physics/rollout.h"
#include "task/evaluate.h"

namespace diverse {

// The film strip's columns for one motion: qpos at the phase events of a jump
// (crouch, extend, take-off, half-way up, peak, half-way down, touch-down, end).
struct FilmColumns {
  std::vector<std::string> names;
  std::vector<std::vector<double>> frames;
};
FilmColumns jump_film_columns(const Evaluation& evaluation, const StepRecorder& record);

}  // namespace diverse
