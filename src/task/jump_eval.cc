#include "task/jump_eval.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "task/constraints.h"
#include "task/support.h"

namespace diverse {

JumpObserver::JumpObserver(const Task& task, const Character& body, const mjModel* m, Controller& controller,
                           JointDrive& drive, RolloutTerms& terms, int samples, bool end_when_decided,
                           Evaluation& out)
    : TaskObserver(task, body, controller, drive, terms, samples, end_when_decided, out),
      rise_(controller.phase_times().rise), fall_(controller.phase_times().fall),
      land_(controller.phase_times().land), extend_(controller.phase_times().extend) {
  (void)m;
  out_.summary.min_clearance = task.simulation.clearance_range;
}

bool JumpObserver::observe(const mjModel* m, const mjData* d) {
  MotionSummary& s = out_.summary;
  const double t = d->time;
  ++index_;
  const double pitch = root_pitch(m, d);
  last_pitch_ = pitch;
  const int phase = controller_.phase();
  const bool changed = controller_.phase_changed();
  if (first_) {
    pitch0_ = pitch;
    first_ = false;
    s.standing_com_z = controller_.com()[2];
    if (body_.root == RootKind::kFree) {
      // The root's standing "up" and forward axes in its own frame (from qpos0).
      const double* q0 = m->qpos0 + body_.root_qpos + 3;
      const double inv[4] = {q0[0], -q0[1], -q0[2], -q0[3]};
      const double z[3] = {0, 0, 1}, x[3] = {1, 0, 0};
      mju_rotVecQuat(up0_, z, inv);
      double fwd0[3];
      mju_rotVecQuat(fwd0, x, inv);
      // Forward pitch is measured against the standing forward axis's elevation.
      double w[3];
      mju_rotVecQuat(w, fwd0, q0);
      elevation0_ = std::atan2(w[2], std::hypot(w[0], w[1]));
      for (int i = 0; i < 3; ++i) fwd0_[i] = fwd0[i];
    }
  }
  s.max_forward_pitch = std::max(s.max_forward_pitch, forward_pitch(d, pitch));
  const double com_z = controller_.com()[2];

  // Events.
  if (phase == rise_ && changed) {
    s.took_off = true;
    pitch_takeoff_ = pitch;
    turn_takeoff_ = turn_;
  }
  const bool airborne = phase == rise_ || phase == fall_;
  if (airborne || (phase == land_ && changed && s.took_off)) {
    out_.flight_time.push_back(t);
    out_.flight_qpos.insert(out_.flight_qpos.end(), d->qpos, d->qpos + m->nq);
  }
  if (airborne) s.peak_com_z = std::max(s.peak_com_z, com_z);
  if (phase == fall_ && changed) decide_if(broken_at(task_, s, Moment::kPastPeak));
  if (phase == land_ && changed) {
    if (!s.took_off || controller_.gave_up()) return fall(t, "never left the ground", d);
    s.landed = true;
    s.rotation_flight = pitch - pitch_takeoff_;
    s.roll_flight = turn_.roll - turn_takeoff_.roll;
    s.vertical_flight = turn_.vertical - turn_takeoff_.vertical;
    s.touchdown_feet_x = feet_mean(d, 0);
    s.touchdown_feet_y = feet_mean(d, 1);
    s.touchdown_feet_z = feet_mean(d, 2);
    decide_if(touchdown_bound(task_, s) > 0);
  }

  // What the listed constraints measure themselves (an obstacle's clearance).
  terms_.observe(m, d, s);

  // Constraints that can only get worse (the obstacle clearance, the forward pitch).
  decide_if(broken_at(task_, s, Moment::kStep));
  if (end_when_decided_ && decided_ >= 0 && s.landed) {
    finish(t, d);
    s.ended_decided = true;
    for (const auto& term : task_.constraints.terms) term->assume_met_at_rest(s);
    return true;
  }

  // A hop before the jump: off the ground in a phase before the extend.
  if (task_.simulation.hop_is_fall && extend_ >= 0 && phase < extend_) {
    if (contacts_.any) {
      off_since_ = -1;
    } else if (off_since_ < 0) {
      off_since_ = t;
    } else if (t - off_since_ >= 0.02 - 1e-9) {
      return fall(t, "left the ground before the jump", d);
    }
  }

  // Falls.
  if (contacts_.non_foot && terms_.contact_is_fall(m, d))
    return fall(t, "a body other than the feet touched the ground or an object", d);
  if (!airborne) {
    const double feet_z = feet_mean(d, 2);
    if (com_z - feet_z < task_.simulation.fall_com_height) {
      return fall(t, "the centre of mass dropped to the feet", d);
    }
    if (task_.simulation.fall_tilt > 0 && tilt(d, pitch) > task_.simulation.fall_tilt) {
      return fall(t, "the body tipped over", d);
    }
    // A topple: both feet down, past the landing's first topple_after seconds, and the
    // COM and its capture point both topple_distance outside the soles.
    const TaskSimulation& rules = task_.simulation;
    if (rules.topple_distance > 0 && s.landed && contacts_.foot[0] && contacts_.foot[1] &&
        t - controller_.phase_times().landing() >= rules.topple_after - 1e-9) {
      const auto& x = controller_.com();
      const auto& v = controller_.com_velocity();
      const double g = std::max(1e-9, std::fabs(m->opt.gravity[2]));
      const double tc = std::sqrt(std::max(0.0, x[2] - feet_z) / g);
      const SoleOutline soles = sole_outline(m, d, body_, contacts_);
      if (soles.margin({x[0], x[1]}) < -rules.topple_distance &&
          soles.margin({x[0] + v[0] * tc, x[1] + v[1] * tc}) < -rules.topple_distance) {
        // Ranked as the fall it would become: most topples lie on the ground a second
        // or more after touch-down, where a fall's progress is full.
        return fall(t, "toppled over the edge of the feet", d, /*landed_fully=*/true);
      }
    }
  }

  // End of the motion.
  const TaskSimulation& sim = task_.simulation;
  if (s.landed) {
    const double since = t - controller_.phase_times().landing();
    const auto& v = controller_.com_velocity();
    // At rest: slow, and (balanced_rest) slow with the capture point over the feet for
    // the last rest_hold seconds.
    const bool slow = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) < sim.settle_speed;
    bool rest = slow;
    if (sim.balanced_rest) {
      const bool still = slow && capture_point_margin(m, d, body_, controller_.com(), v) >= 0;
      if (!still) {
        still_since_ = -1;
      } else if (still_since_ < 0) {
        still_since_ = t;
      }
      rest = still && t - still_since_ >= sim.rest_hold - 0.5 * m->opt.timestep;
    }
    if (since >= sim.settle_time && rest) {
      s.settled = true;
      return finish(t, d);
    }
    if (since >= sim.settle_max) return fall(t, "did not come to rest after landing", d);
  }
  if (t + m->opt.timestep > sim.max_time) {
    return fall(t, s.took_off ? "did not land in time" : "never left the ground", d);
  }
  return false;
}

// How far the motion got: the phase reached, then the time at rest after landing.
double JumpObserver::progress(double t) const {
  const int phase = controller_.phase();
  const double phases = static_cast<double>(controller_.phase_times().begin.size());
  if (phase == land_ && out_.summary.landed) {
    const double since = t - controller_.phase_times().landing();
    return (land_ + std::min(1.0, since / task_.simulation.settle_time)) / phases;
  }
  return static_cast<double>(std::min(phase, land_)) / phases;
}

// The root's forward pitch from standing (rad, positive forward): the planar root's
// hinge (positive backwards), or a free root's forward axis's elevation below standing.
double JumpObserver::forward_pitch(const mjData* d, double pitch) const {
  if (body_.root == RootKind::kPlanar) return -(pitch - pitch0_);
  double w[3];
  mju_mulMatVec(w, d->xmat + 9 * body_.root_body, fwd0_, 3, 3);
  return elevation0_ - std::atan2(w[2], std::hypot(w[0], w[1]));
}

// The root's tilt from standing upright (rad).
double JumpObserver::tilt(const mjData* d, double pitch) const {
  if (body_.root == RootKind::kPlanar) return std::fabs(pitch - pitch0_);
  double up[3];
  mju_mulMatVec(up, d->xmat + 9 * body_.root_body, up0_, 3, 3);
  return std::acos(std::clamp(up[2], -1.0, 1.0));
}

// Mean over the two feet's centres of mass of world coordinate `axis` (0 = x, 2 = z).
double JumpObserver::feet_mean(const mjData* d, int axis) const {
  return 0.5 * (d->xipos[3 * body_.feet[0] + axis] + d->xipos[3 * body_.feet[1] + axis]);
}

// The root's pitch (rad, positive backwards), unwrapped over the motion: the planar
// root's hinge angle, or for a free root the integral of its world angular velocity
// about -y (a full backward turn gives 2 pi), and its roll and vertical turns likewise.
double JumpObserver::root_pitch(const mjModel* m, const mjData* d) {
  if (body_.root == RootKind::kPlanar) return d->qpos[body_.root_pitch_qpos];
  if (!first_) turn_.add_step(d->xmat + 9 * body_.root_body, d->qvel + body_.root_dof + 3, m->opt.timestep);
  return turn_.pitch;
}

void RootTurn::add_step(const double* R, const double* w, double dt) {
  const double wy = R[3] * w[0] + R[4] * w[1] + R[5] * w[2];
  pitch += -wy * dt;
  roll += (R[0] * w[0] + R[1] * w[1] + R[2] * w[2]) * dt;
  vertical += (R[6] * w[0] + R[7] * w[1] + R[8] * w[2]) * dt;
}

// `landed_fully`: the fall's progress is that of a fall settle_time or more after
// touch-down, whenever it is called.
bool JumpObserver::fall(double t, const char* why, const mjData* d, bool landed_fully) {
  MotionSummary& s = out_.summary;
  s.fell = true;
  s.fall_reason = why;
  s.fall_progress = landed_fully ? (land_ + 1.0) / static_cast<double>(controller_.phase_times().begin.size())
                                 : progress(t);
  return finish(t, d);
}

bool JumpObserver::finish(double t, const mjData* d) {
  MotionSummary& s = out_.summary;
  s.end_time = t;
  s.feet_x = feet_mean(d, 0);
  s.feet_y = feet_mean(d, 1);
  s.feet_z = feet_mean(d, 2);
  if (!s.landed) {  // never touched down: the end position stands for both
    s.touchdown_feet_x = s.feet_x;
    s.touchdown_feet_y = s.feet_y;
    s.touchdown_feet_z = s.feet_z;
  }
  s.rotation_total = last_pitch_ - pitch0_;
  return true;
}

std::vector<PoseSample> JumpObserver::poses(SimWorker& worker) const {
  std::vector<PoseSample> out;
  if (samples_ <= 0 || !out_.has_flight() || !out_.summary.landed) return out;
  std::vector<double> taus;
  for (int k = 0; k < samples_; ++k) taus.push_back((k + 0.5) / samples_);
  for (int phase = 0; phase < 2; ++phase) {
    auto phase_poses = flight_poses(body_, out_, phase, taus, worker);
    out.insert(out.end(), phase_poses.begin(), phase_poses.end());
  }
  return out;
}

std::vector<PoseSample> flight_poses(const Character& body, const Evaluation& e, int phase,
                                     const std::vector<double>& taus, SimWorker& worker) {
  if (!e.has_flight() || e.flight_time.empty()) {
    throw std::logic_error("sample_poses: the evaluation has no flight");
  }
  const mjModel* m = worker.model();
  mjData* d = worker.data();
  const int nq = m->nq;
  const double a = phase == 0 ? e.phases.takeoff() : e.phases.peak();
  const double b = phase == 0 ? e.phases.peak() : e.phases.landing();
  std::vector<PoseSample> out;
  for (double tau : taus) {
    const double t = a + std::clamp(tau, 0.0, 1.0) * (b - a);
    // Bracketing recorded states; linear interpolation (hinges and slides; a free root's
    // quaternion is interpolated linearly and normalized, exact enough between two steps).
    const auto& ts = e.flight_time;
    size_t hi = std::lower_bound(ts.begin(), ts.end(), t) - ts.begin();
    hi = std::min(hi, ts.size() - 1);
    const size_t lo = hi > 0 ? hi - 1 : 0;
    const double w = (hi == lo || ts[hi] == ts[lo]) ? 1.0 : std::clamp((t - ts[lo]) / (ts[hi] - ts[lo]), 0.0, 1.0);
    for (int i = 0; i < nq; ++i) {
      d->qpos[i] = (1 - w) * e.flight_qpos[lo * nq + i] + w * e.flight_qpos[hi * nq + i];
    }
    if (body.root == RootKind::kFree) mju_normalize4(d->qpos + body.root_qpos + 3);
    mj_kinematics(m, d);
    PoseSample p;
    p.phase = phase;
    p.phase_time = tau;
    p.time = t;
    p.link_com.resize(3, static_cast<int>(body.links.size()));
    for (size_t k = 0; k < body.links.size(); ++k) {
      for (int c = 0; c < 3; ++c) p.link_com(c, static_cast<int>(k)) = d->xipos[3 * body.links[k] + c];
    }
    p.angles.resize(static_cast<int>(body.joints.size()));
    for (size_t k = 0; k < body.joints.size(); ++k) p.angles[static_cast<int>(k)] = d->qpos[body.joints[k].qpos];
    p.root = root_orientation(body, d->qpos);
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace diverse
