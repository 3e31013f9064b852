#include "task/scene_check.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/toml_reader.h"
#include "task/term_fall.h"

namespace diverse {
namespace {

void check_physics(const Task& task, const mjModel* m) {
  const double* g = m->opt.gravity;
  const double down = -g[2];
  if (!(g[0] == 0 && g[1] == 0 && down >= 0.1 && down <= 100))
    throw_field_error(task.model, "option.gravity",
                      "expected gravity pointing down, \"0 0 -g\" with g in [0.1, 100] m/s^2, got \"" +
                          num(g[0]) + " " + num(g[1]) + " " + num(g[2]) + "\"");
  const double dt = m->opt.timestep;
  if (!(dt >= 1e-5 && dt <= 0.01))
    throw_field_error(task.simulation.timestep > 0 ? task.file : task.model,
                      task.simulation.timestep > 0 ? "simulation.timestep" : "option.timestep",
                      "expected a timestep in [1e-05, 0.01] s, got " + num(dt));
  if (task.simulation.max_time / dt > kMaxRolloutSteps)
    throw_field_error(task.file, "simulation.max_time",
                      "expected at most " + num(kMaxRolloutSteps) + " steps of " + num(dt) +
                          " s, got " + num(task.simulation.max_time) + " s");
}

// Scene objects the character overlaps in its start pose (the model's qpos0).
void check_start_pose(const Task& task, const mjModel* m, const Character& body) {
  if (task.objects.empty()) return;
  mjData* d = mj_makeData(m);
  mj_forward(m, d);
  std::string overlap, part;
  double depth = 0;
  for (int c = 0; c < d->ncon && overlap.empty(); ++c) {
    const mjContact& k = d->contact[c];
    for (int side = 0; side < 2; ++side) {
      const int object_geom = side == 0 ? k.geom1 : k.geom2;
      const int other_geom = side == 0 ? k.geom2 : k.geom1;
      const char* name = mj_id2name(m, mjOBJ_GEOM, object_geom);
      if (name == nullptr || task.find_object(name) == nullptr) continue;
      if (!body.is_link(m, m->geom_bodyid[other_geom]) || k.dist > -1e-3) continue;
      overlap = name;
      const char* b = mj_id2name(m, mjOBJ_BODY, m->geom_bodyid[other_geom]);
      part = b != nullptr ? b : "body " + std::to_string(m->geom_bodyid[other_geom]);
      depth = -k.dist;
      break;
    }
  }
  mj_deleteData(d);
  if (overlap.empty()) return;
  for (std::size_t i = 0; i < task.objects.size(); ++i) {
    if (task.objects[i].name != overlap) continue;
    throw_field_error(task.file, "objects[" + std::to_string(i) + "]",
                      "expected an object clear of the character's start pose, but \"" + overlap +
                          "\" overlaps its " + part + " by " + num(std::round(depth * 1000)) + " mm");
  }
}

void check_constraints(const Task& task) {
  const TaskConstraints& c = task.constraints;
  const TaskSimulation& s = task.simulation;
  for (const auto& term : c.terms) term->check(task);
  // Where the feet may end: the intersection of every landing constraint's x interval.
  double lo = -INFINITY, hi = INFINITY;
  std::string fields;
  for (const auto& term : c.terms) {
    const auto range = term->feet_x_range(task);
    if (!range) continue;
    lo = std::max(lo, range->first);
    hi = std::min(hi, range->second);
    fields += (fields.empty() ? "" : ", ") + term->field();
  }
  if (lo > hi)
    throw_field_error(task.file, fields,
                      "expected landing constraints that some x satisfies, but they leave nowhere to "
                      "land (the feet would need x >= " + num(lo) + " and x <= " + num(hi) + ")");
  if (!(s.max_time > s.settle_time))
    throw_field_error(task.file, "simulation.max_time",
                      "expected more than simulation.settle_time (" + num(s.settle_time) +
                          " s): a rollout must have time to land and stand, got " + num(s.max_time));
}

}  // namespace

void check_scene(const Task& task, const mjModel* m, const Character& body) {
  check_physics(task, m);
  check_constraints(task);
  allowed_contact_bodies(m, body, task.constraints, task.file);  // names bodies of the character
  check_start_pose(task, m, body);
}

}  // namespace diverse
