#include "render/film_columns.h"

#include "render/film_strip.h"

#include <algorithm>
#include <cmath>

namespace diverse {

FilmColumns jump_film_columns(const Evaluation& e, const StepRecorder& record) {
  FilmColumns columns;
  const double dt = record.timestep;
  auto frame_at = [&](double t) {
    // qpos row k is the state after step k, at time (k + 1) dt; t = 0 is qpos0.
    const int steps = record.steps();
    const long k = std::lround(t / dt) - 1;
    if (k < 0 || steps == 0) return record.qpos0;
    const long row = std::min<long>(k, steps - 1);
    return std::vector<double>(record.qpos.begin() + row * record.nq,
                               record.qpos.begin() + (row + 1) * record.nq);
  };
  const PhaseTimes& p = e.phases;
  const double end = record.steps() * dt;
  // Every motion gets every column, so columns line up across rows; an event the motion
  // never reached leaves its tile empty.
  auto add = [&](const std::string& name, double t) {
    columns.names.push_back(name);
    columns.frames.push_back(t < 0 ? std::vector<double>() : frame_at(t));
  };
  // The stance phases between the start and take-off (a jump's crouch and extend).
  for (int phase = 1; phase < p.rise; ++phase) add(p.names[static_cast<size_t>(phase)], p.at(phase));
  add("take-off", p.takeoff());
  add("rising", p.takeoff() >= 0 && p.peak() >= 0 ? 0.5 * (p.takeoff() + p.peak()) : -1);
  add("peak", p.peak());
  add("falling", p.peak() >= 0 && p.landing() >= 0 ? 0.5 * (p.peak() + p.landing()) : -1);
  add("touch-down", p.landing());
  add("end", end);
  return columns;
}

std::string film_title(const std::string& prefix, const std::vector<std::string>& column_names) {
  std::string title = prefix;
  title.append(":");
  for (std::size_t c = 0; c < column_names.size(); ++c)
    title.append("  ").append(column_label(static_cast<int>(c))).append(" ").append(column_names[c]);
  return title;
}

std::vector<GroundStrip> task_ground_strips(const Task& task) {
  std::vector<GroundStrip> strips;
  const TaskConstraints& c = task.constraints;
  if (c.landing)
    strips.push_back({c.landing_center - c.landing_half_width, c.landing_center + c.landing_half_width});
  return strips;
}

}  // namespace diverse
