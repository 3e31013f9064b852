#include "task/pushes.h"

#include <algorithm>

namespace diverse {

GroundWindows ground_windows(const Task& task, const Evaluation& e) {
  const double end = std::max(e.stats.time, 0.0);
  const GroundWindow whole{0, end, "motion"};
  if (task.walk.enabled) {
    const auto& steps = e.summary.walk.steps;
    const auto settle = static_cast<std::size_t>(std::max(0, task.walk.settle_steps));
    if (steps.size() > settle) {
      const double begin = settle > 0 ? steps[settle - 1].time : 0.0;
      const double last = steps.back().time;
      if (last > begin) return {GroundWindow{begin, last, "steps"}, GroundWindow{begin, last, "steps"}};
    }
    return {whole, whole};
  }
  const double takeoff = e.phases.rise >= 0 ? e.phases.takeoff() : -1;
  const double landing = e.phases.land >= 0 ? e.phases.landing() : -1;
  const GroundWindow before = takeoff > 0 ? GroundWindow{0, takeoff, "takeoff"} : whole;
  GroundWindow after = before;
  if (landing >= 0 && landing < end) {
    after = GroundWindow{landing, std::min(end, landing + task.simulation.settle_time), "landing"};
  }
  return {before, after};
}

namespace {
constexpr PushDirection kDirections[4] = {
    {"forward", {1, 0, 0}}, {"backward", {-1, 0, 0}}, {"left", {0, 1, 0}}, {"right", {0, -1, 0}}};
}  // namespace

int push_directions(bool planar) { return planar ? 2 : 4; }

const PushDirection& push_direction(int k, bool planar) {
  const int n = push_directions(planar);
  return kDirections[((k % n) + n) % n];
}

PushDraw draw_push(const GroundWindows& windows, int k, bool planar, int first_window, double fraction,
                   double speed) {
  const PushDirection& d = push_direction(k, planar);
  const GroundWindow& w = windows[static_cast<std::size_t>((k / push_directions(planar) + first_window) % 2)];
  PushDraw out{{}, w.phase, d.name};
  out.push.time = w.begin + fraction * (w.end - w.begin);
  for (std::size_t a = 0; a < 3; ++a) out.push.dv[a] = speed * d.axis[a];
  return out;
}

}  // namespace diverse
