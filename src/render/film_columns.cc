#include "render/film_columns.h"

#include "render/film_strip.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "task/term_landing.h"

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

bool last_stride(const PhaseTimes& p, int* first, int* length) {
  // The phases reached, in order.
  std::vector<int> reached;
  for (std::size_t k = 0; k < p.names.size() && k < p.begin.size(); ++k)
    if (p.begin[k] >= 0) reached.push_back(static_cast<int>(k));
  const int n = static_cast<int>(reached.size());
  const auto name = [&](int i) -> const std::string& { return p.names[static_cast<std::size_t>(reached[static_cast<std::size_t>(i)])]; };
  // A stride begins where the cycle first began: at the name of the earliest phase that
  // comes again (a walk's first state, not whichever state the motion ended in).
  int start = -1;
  for (int i = 0; i < n && start < 0; ++i)
    for (int j = i + 1; j < n; ++j)
      if (name(j) == name(i)) {
        start = i;
        break;
      }
  if (start < 0) return false;
  for (int s = n - 2; s >= 0; --s) {
    if (name(s) != name(start)) continue;
    for (int len = 2; s + len < n; ++len) {
      bool distinct = true;
      for (int a = s; a < s + len && distinct; ++a)
        for (int b = a + 1; b < s + len; ++b)
          if (name(a) == name(b)) distinct = false;
      if (!distinct) break;
      if (name(s + len) == name(s)) {
        *first = reached[static_cast<std::size_t>(s)];
        *length = reached[static_cast<std::size_t>(s + len)] - reached[static_cast<std::size_t>(s)];
        // Phases never reached inside the stride would leave gaps: not a clean cycle.
        if (*length != len) continue;
        return true;
      }
    }
  }
  return false;
}

FilmColumns motion_film_columns(const PhaseTimes& p, const StepRecorder& record) {
  if (p.rise >= 0 || p.fall >= 0 || p.land >= 0) {
    Evaluation e;
    e.phases = p;
    return jump_film_columns(e, record);
  }
  FilmColumns columns;
  const double dt = record.timestep;
  const double end = record.steps() * dt;
  auto frame_at = [&](double t) {
    const int steps = record.steps();
    const long k = std::lround(t / dt) - 1;
    if (k < 0 || steps == 0) return record.qpos0;
    const long row = std::min<long>(k, steps - 1);
    return std::vector<double>(record.qpos.begin() + row * record.nq,
                               record.qpos.begin() + (row + 1) * record.nq);
  };
  auto add = [&](const std::string& name, double t) {
    columns.names.push_back(name);
    columns.frames.push_back(frame_at(t));
  };
  int first = 0, length = 0;
  if (last_stride(p, &first, &length)) {
    // A column at each state's start, and one in its middle unless the state is short (a
    // strike state that ends at once would show the same moment three times).
    const double mean = (p.at(first + length) - p.at(first)) / length;
    for (int k = first; k < first + length; ++k) {
      const double begin = p.at(k), next = p.at(k + 1);
      const std::string& name = p.names[static_cast<std::size_t>(k)];
      add(name, begin);
      if (next - begin >= 0.5 * mean) add(std::string("mid ").append(name), 0.5 * (begin + next));
    }
    add(p.names[static_cast<std::size_t>(first)], p.at(first + length));
    return columns;
  }
  // In the order they began (a controller that keeps each phase's latest begin, such as a
  // walk's, then shows the last time through each).
  std::vector<std::pair<double, std::size_t>> reached;
  for (std::size_t k = 0; k < p.names.size() && k < p.begin.size(); ++k)
    if (p.begin[k] >= 0) reached.emplace_back(p.begin[k], k);
  std::stable_sort(reached.begin(), reached.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [begin, k] : reached) add(p.names[k], begin);
  if (!reached.empty()) {
    add("end", end);
    return columns;
  }
  for (int k = 0; k < kEvenColumns; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "%.2f s", end * k / (kEvenColumns - 1));
    add(name, end * k / (kEvenColumns - 1));
  }
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
  const LandingConstraint* c = task.constraints.find<LandingConstraint>();
  if (c != nullptr && c->radius > 0) {
    GroundStrip disc{c->center - c->radius, c->center + c->radius};
    disc.radius = c->radius;
    disc.y = c->lateral;
    strips.push_back(disc);
  } else if (c != nullptr) {
    strips.push_back({c->center - c->half_width, c->center + c->half_width});
  }
  return strips;
}

}  // namespace diverse
