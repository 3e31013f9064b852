#include "task/walk_audit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace diverse {
namespace {

std::string format(const char* fmt, double a, double b = 0, double c = 0, double d = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c, d);
  return buf;
}

// World "up" expressed in body b's frame at the model's qpos0.
std::array<double, 3> standing_up(const mjData* d, int b) {
  const double* R = d->xmat + 9 * b;
  return {R[6], R[7], R[8]};
}

double tilt_of(const mjData* d, int b, const std::array<double, 3>& up) {
  const double* R = d->xmat + 9 * b;
  const double z = R[6] * up[0] + R[7] * up[1] + R[8] * up[2];
  return std::acos(std::clamp(z, -1.0, 1.0));
}

double yaw_of(const mjData* d, int b) {
  const double* R = d->xmat + 9 * b;
  return std::atan2(R[3], R[0]);
}

}  // namespace

int walk_torso(const Character& body) {
  int torso = -1;
  size_t depth = 0;
  for (size_t k = 0; k < body.joints.size(); ++k) {
    const CharacterJoint& j = body.joints[k];
    if (body.groups[static_cast<size_t>(j.group)].role != JointRole::kWaist || j.side != Side::kCenter) continue;
    const size_t dd = body.chain(static_cast<int>(k)).size();
    if (torso < 0 || dd > depth) {
      torso = j.body;
      depth = dd;
    }
  }
  return torso;
}

WalkAudit audit_walk(const mjModel* model, const StepRecorder& record, const Character& body, const TaskWalk& walk) {
  WalkAudit a;
  mjModel* m = mj_copyModel(nullptr, model);
  mjData* d = mj_makeData(m);

  // Standing: the model's qpos0.
  mj_kinematics(m, d);
  const int torso = walk_torso(body);
  const std::array<double, 3> root_up = standing_up(d, body.root_body);
  const std::array<double, 3> torso_up = torso >= 0 ? standing_up(d, torso) : root_up;
  const double standing_yaw = yaw_of(d, body.root_body);

  const int steps = std::min(record.steps(), static_cast<int>(record.qpos.size()) / std::max(1, record.nq));
  std::array<bool, 2> down{true, true};
  std::array<double, 2> lifted{0, 0};           // time each foot last left the ground
  int last_leg = -1;
  std::array<std::array<double, 2>, 2> footprint{};  // each foot's body origin at its last touch-down
  double airborne_since = -1;
  double heading = 0, start_heading = 0, last_yaw = 0, tilt = 0;
  bool first = true;
  for (int s = 0; s <= steps; ++s) {
    // State s: the initial state, then the state after recorded step s - 1.
    const double* q = s == 0 ? record.qpos0.data() : record.qpos.data() + static_cast<long>(s - 1) * record.nq;
    std::copy(q, q + m->nq, d->qpos);
    mj_kinematics(m, d);
    mj_collision(m, d);
    const double t = s * record.timestep;

    const double yaw = yaw_of(d, body.root_body) - standing_yaw;
    if (first) {
      heading = start_heading = yaw;
      first = false;
    } else {
      heading += std::remainder(yaw - last_yaw, 2 * M_PI);
    }
    last_yaw = yaw;
    tilt = std::max({tilt, tilt_of(d, body.root_body, root_up), torso >= 0 ? tilt_of(d, torso, torso_up) : 0.0});

    if (s == 0) {
      for (size_t f = 0; f < 2; ++f) footprint[f] = {d->xpos[3 * body.feet[f]], d->xpos[3 * body.feet[f] + 1]};
    }
    std::array<bool, 2> now{false, false};
    for (int c = 0; c < d->ncon; ++c) {
      const mjContact& con = d->contact[c];
      for (int side = 0; side < 2; ++side) {
        const int g = side == 0 ? con.geom1 : con.geom2, other = side == 0 ? con.geom2 : con.geom1;
        if (!body.is_link(m, m->geom_bodyid[g]) || body.is_link(m, m->geom_bodyid[other])) continue;
        int foot = -1;
        if (body.is_foot_geom(m, g, &foot)) {
          now[static_cast<size_t>(foot)] = true;
        } else if (!a.fell) {
          a.fell = true;
          a.fall_time = t;
          const char* name = mj_id2name(m, mjOBJ_BODY, m->geom_bodyid[g]);
          a.fall_body = name != nullptr ? name : "body " + std::to_string(m->geom_bodyid[g]);
        }
      }
    }
    if (now[0] || now[1]) {
      airborne_since = -1;
    } else if (airborne_since < 0) {
      airborne_since = t;
    } else if (t - airborne_since > a.longest_flight) {
      a.longest_flight = t - airborne_since;
      a.flight_time = airborne_since;
    }
    for (int f = 0; f < 2; ++f) {
      const size_t i = static_cast<size_t>(f);
      if (down[i] && !now[i]) lifted[i] = t;
      if (!down[i] && now[i] && t - lifted[i] >= kMinAirTime) {
        const double* p = d->xpos + 3 * body.feet[i];
        if (f == last_leg) {
          ++a.relandings;
        } else {
          // The other foot now, or its footprint, as the task measures steps.
          const double* from = walk.from_footprint ? footprint[1 - i].data() : d->xpos + 3 * body.feet[1 - i];
          const double dx = p[0] - from[0], dy = p[1] - from[1];
          WalkAudit::Step step;
          step.leg = f;
          step.sim_step = s - 1;
          step.time = t;
          step.forward = std::cos(yaw) * dx + std::sin(yaw) * dy;
          step.lateral = -std::sin(yaw) * dx + std::cos(yaw) * dy;
          const double fx = p[0] - footprint[1 - i][0], fy = p[1] - footprint[1 - i][1];
          step.footprint_forward = std::cos(yaw) * fx + std::sin(yaw) * fy;
          step.footprint_lateral = -std::sin(yaw) * fx + std::cos(yaw) * fy;
          step.heading = heading;
          step.tilt = tilt;
          a.steps.push_back(step);
          tilt = 0;
          last_leg = f;
        }
        footprint[i] = {p[0], p[1]};
      }
      down[i] = now[i];
    }
  }
  mj_deleteData(d);
  mj_deleteModel(m);

  // The rules over the evaluated steps.
  const int taken = static_cast<int>(a.steps.size());
  if (a.fell) a.violations.push_back("fell: " + a.fall_body + format(" touched the ground at %.3f s", a.fall_time));
  if (a.longest_flight > walk.max_flight) {
    a.violations.push_back(format("both feet off the ground for %.3f s from %.3f s, expected at most %.3f s",
                                  a.longest_flight, a.flight_time, walk.max_flight));
  }
  if (taken < walk.steps) {
    a.violations.push_back(format("took %.0f steps, the task asks for %.0f", taken, walk.steps));
  }
  const int first_eval = walk.settle_steps;  // index of the first evaluated step
  if (taken > first_eval) {
    const int last = std::min(taken, walk.steps) - 1;
    a.forward_min = a.forward_max = a.steps[static_cast<size_t>(first_eval)].forward;
    a.lateral_min = a.lateral_max = a.steps[static_cast<size_t>(first_eval)].lateral;
    a.footprint_forward_min = a.footprint_forward_max = a.steps[static_cast<size_t>(first_eval)].footprint_forward;
    const double tilt_limit = walk.max_tilt_deg * M_PI / 180;
    for (int k = first_eval; k <= last; ++k) {
      const WalkAudit::Step& st = a.steps[static_cast<size_t>(k)];
      a.forward_min = std::min(a.forward_min, st.forward);
      a.forward_max = std::max(a.forward_max, st.forward);
      a.lateral_min = std::min(a.lateral_min, st.lateral);
      a.lateral_max = std::max(a.lateral_max, st.lateral);
      a.footprint_forward_min = std::min(a.footprint_forward_min, st.footprint_forward);
      a.footprint_forward_max = std::max(a.footprint_forward_max, st.footprint_forward);
      a.max_tilt = std::max(a.max_tilt, st.tilt);
      if (std::fabs(st.forward - walk.forward_center) > walk.forward_half_width) {
        a.violations.push_back(format("step %.0f: forward %.3f m, expected %.2f +- %.2f", k + 1, st.forward,
                                      walk.forward_center, walk.forward_half_width));
      }
      if (std::fabs(st.lateral - walk.lateral_center) > walk.lateral_half_width) {
        a.violations.push_back(format("step %.0f: lateral %.3f m, expected %.2f +- %.2f", k + 1, st.lateral,
                                      walk.lateral_center, walk.lateral_half_width));
      }
      if (st.tilt > tilt_limit) {
        a.violations.push_back(format("step %.0f: tilt %.1f deg, expected at most %.1f", k + 1, st.tilt * 180 / M_PI,
                                      walk.max_tilt_deg));
      }
    }
  }
  // The heading at every touch-down, from the start's.
  for (const WalkAudit::Step& st : a.steps) a.turn = std::max(a.turn, std::fabs(st.heading - start_heading));
  if (a.turn > walk.max_turn_deg * M_PI / 180) {
    a.violations.push_back(format("heading %.1f deg from the start's at a touch-down, expected at most %.1f",
                                  a.turn * 180 / M_PI, walk.max_turn_deg));
  }
  return a;
}

}  // namespace diverse
