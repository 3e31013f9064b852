// Which moments of a motion a film strip shows: the phase events, the same in every row
// (paper figure 5 labels its columns A-F by phase, not by time); for a walk, one stride.
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

// The film strip's columns for any motion, from the phases its controller reported (names
// and begin times, -1 for a phase never reached; which ones are a jump's events):
//   - a jump (take-off, peak and touch-down events): jump_film_columns;
//   - a cyclic motion, whose phase names repeat (a walk's states, stride after stride): the
//     last complete stride, from the cycle's first state, each of its phases at its begin
//     and half-way through it, then the next stride's begin ("mid <phase>" names the
//     half-way columns);
//   - other phases: each phase reached at its begin, in the order they began, then the end
//     (a controller that keeps only each phase's latest begin, as a walk's does, shows the
//     last time through each);
//   - no phases: kEvenColumns moments evenly spaced from the start to the end.
constexpr int kEvenColumns = 6;
FilmColumns motion_film_columns(const PhaseTimes& phases, const StepRecorder& record);

// The last complete stride of a cyclic motion: the phases [first, first + length) whose
// names are distinct and whose next phase, first + length, has begun and repeats the name of
// `first`, which is the name of the earliest phase that comes again (the cycle's first
// state). Returns false when the phases do not repeat.
bool last_stride(const PhaseTimes& phases, int* first, int* length);

// "PREFIX:  A crouch  B extend ...": the title line that names a film strip's columns.
std::string film_title(const std::string& prefix, const std::vector<std::string>& column_names);

// The parts of the floor a task's pictures mark: its landing region, if it has one.
std::vector<GroundStrip> task_ground_strips(const Task& task);

}  // namespace diverse
