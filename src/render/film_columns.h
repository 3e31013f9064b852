// Which moments of a jump a film strip shows: the phase events, the same in every row
// (paper figure 5 labels its columns A-F by phase, not by time).
#pragma once

#include <string>
#include <vector>

#include "physics/rollout.h"
#include "render/offscreen.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {

// The film strip's columns for one motion: qpos at the phase events of a jump
// (crouch, extend, take-off, half-way up, peak, half-way down, touch-down, end).
struct FilmColumns {
  std::vector<std::string> names;
  std::vector<std::vector<double>> frames;
};
FilmColumns jump_film_columns(const Evaluation& evaluation, const StepRecorder& record);

// "PREFIX:  A crouch  B extend ...": the title line that names a film strip's columns.
std::string film_title(const std::string& prefix, const std::vector<std::string>& column_names);

// The parts of the floor a task's pictures mark: its landing region, if it has one.
std::vector<GroundStrip> task_ground_strips(const Task& task);

}  // namespace diverse
