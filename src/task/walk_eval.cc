#include "task/walk_eval.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "task/walk_audit.h"
#include "task/walk_task.h"

namespace diverse {
namespace {

// World orientation of every body at the model's qpos0 (hinges add no rotation there).
std::vector<std::array<double, 4>> standing_orientations(const mjModel* m) {
  std::vector<std::array<double, 4>> q(static_cast<size_t>(m->nbody), {1, 0, 0, 0});
  for (int b = 1; b < m->nbody; ++b) {
    mju_mulQuat(q[static_cast<size_t>(b)].data(), q[static_cast<size_t>(m->body_parentid[b])].data(),
                m->body_quat + 4 * b);
  }
  return q;
}

// World "up" in the frame of a body whose world orientation is q.
std::array<double, 3> up_in(const std::array<double, 4>& q) {
  double R[9];
  mju_quat2Mat(R, q.data());
  return {R[6], R[7], R[8]};  // R^T z
}

// Which feet touch something that is not the character (the audit's rule: a foot on the
// other foot or on the character's own body is not down).
std::array<bool, 2> feet_on_ground(const mjModel* m, const mjData* d, const Character& body) {
  std::array<bool, 2> down{false, false};
  for (int c = 0; c < d->ncon; ++c) {
    const mjContact& con = d->contact[c];
    for (int side = 0; side < 2; ++side) {
      const int g = side == 0 ? con.geom1 : con.geom2, other = side == 0 ? con.geom2 : con.geom1;
      if (body.is_link(m, m->geom_bodyid[other])) continue;
      int foot = -1;
      if (body.is_foot_geom(m, g, &foot)) down[static_cast<size_t>(foot)] = true;
    }
  }
  return down;
}

}  // namespace

WalkObserver::WalkObserver(const Task& task, const Character& body, const mjModel* m,
                           Controller& controller, JointDrive& drive, RolloutTerms& terms, int samples,
                           bool end_when_decided, Evaluation& out)
    : TaskObserver(task, body, controller, drive, terms, samples, end_when_decided, out) {
  nq_ = m->nq;
  const auto standing = standing_orientations(m);
  root_up_ = up_in(standing[static_cast<size_t>(body.root_body)]);
  torso_ = walk_torso(body);
  if (torso_ >= 0) torso_up_ = up_in(standing[static_cast<size_t>(torso_)]);
  double R[9];
  mju_quat2Mat(R, standing[static_cast<size_t>(body.root_body)].data());
  standing_heading_ = std::atan2(R[3], R[0]);
}

double WalkObserver::heading(const mjData* d) const {
  const double* R = d->xmat + 9 * body_.root_body;
  return std::atan2(R[3], R[0]) - standing_heading_;
}

double WalkObserver::tilt(const mjData* d, int b, const std::array<double, 3>& up) const {
  const double* R = d->xmat + 9 * b;
  const double z = R[6] * up[0] + R[7] * up[1] + R[8] * up[2];  // (R up) . world z
  return std::acos(std::clamp(z, -1.0, 1.0));
}

bool WalkObserver::fall(const mjData* d, const char* why) {
  MotionSummary& s = out_.summary;
  s.fell = true;
  s.fall_reason = why;
  s.fall_progress = std::min(1.0, static_cast<double>(s.walk.steps.size()) / task_.walk.steps);
  s.end_time = d->time;
  return true;
}

void WalkObserver::close_state(int state) {
  const size_t n = state_time_.size();
  if (n == 0 || samples_ <= 0) return;
  const double a = state_time_.front(), b = state_time_.back();
  for (int k = 0; k < samples_; ++k) {
    const double tau = (k + 0.5) / samples_;
    const double t = a + tau * (b - a);
    size_t hi = static_cast<size_t>(std::lower_bound(state_time_.begin(), state_time_.end(), t) - state_time_.begin());
    hi = std::min(hi, n - 1);
    const size_t lo = hi > 0 ? hi - 1 : 0;
    const double span = state_time_[hi] - state_time_[lo];
    const double w = span > 0 ? std::clamp((t - state_time_[lo]) / span, 0.0, 1.0) : 1.0;
    for (int i = 0; i < nq_; ++i) {
      sample_qpos_.push_back((1 - w) * state_qpos_[lo * static_cast<size_t>(nq_) + static_cast<size_t>(i)] +
                             w * state_qpos_[hi * static_cast<size_t>(nq_) + static_cast<size_t>(i)]);
    }
    sample_state_.push_back(state);
    sample_heading_.push_back(stride_heading_);
    sample_tau_.push_back(tau);
    sample_time_.push_back(t);
  }
}

bool WalkObserver::observe(const mjModel* m, const mjData* d) {
  MotionSummary& s = out_.summary;
  WalkSummary& walk = s.walk;
  const TaskWalk& w = task_.walk;
  const double t = d->time;
  // Heading, unwrapped.
  const double raw = heading(d);
  if (first_) {
    heading_ = raw;
    walk.start_heading = raw;
    state_ = controller_.phase();
    first_ = false;
    for (size_t f = 0; f < 2; ++f) footprint_[f] = {d->xpos[3 * body_.feet[f]], d->xpos[3 * body_.feet[f] + 1]};
  } else {
    heading_ += std::remainder(raw - last_raw_heading_, 2 * M_PI);
  }
  last_raw_heading_ = raw;
  tilt_ = std::max(tilt_, tilt(d, body_.root_body, root_up_));
  if (torso_ >= 0) tilt_ = std::max(tilt_, tilt(d, torso_, torso_up_));

  // Steps: touch-downs found from the feet's contacts, as the walk audit finds them
  // (task/walk_audit.h), not from the controller's states: a swing foot set down in the
  // middle of its swing is a step where it was set down. Times for the air-time test
  // are step index x timestep, as the audit computes them from the record.
  const double ta = static_cast<double>(index_++) * m->opt.timestep;
  const std::array<bool, 2> now = feet_on_ground(m, d, body_);
  for (int f = 0; f < 2; ++f) {
    const size_t i = static_cast<size_t>(f);
    if (ground_[i] && !now[i]) lifted_[i] = ta;
    if (!ground_[i] && now[i] && ta - lifted_[i] >= kMinAirTime) {
      if (f == last_leg_) {
        ++walk.relandings;
      } else if (static_cast<int>(walk.steps.size()) < w.steps) {
        // The step: from the other foot, where it is now, to the landing foot. (Not from
        // where the other foot landed: a foot that slides or shuffles back after landing
        // would let short or backward steps count as long ones.)
        const double* p = d->xpos + 3 * body_.feet[i];
        const double* o = w.from_footprint ? footprint_[1 - i].data() : d->xpos + 3 * body_.feet[1 - i];
        const double dx = p[0] - o[0], dy = p[1] - o[1];
        WalkStep step;
        step.leg = f;
        step.time = t;
        step.forward = std::cos(raw) * dx + std::sin(raw) * dy;
        step.lateral = -std::sin(raw) * dx + std::cos(raw) * dy;
        step.heading = heading_;
        step.tilt = tilt_;
        walk.steps.push_back(step);
        tilt_ = 0;
        // Every evaluated step adds its excess to C, so one out of range decides it.
        if (decided_ < 0 && static_cast<int>(walk.steps.size()) > w.settle_steps &&
            walk_constraints(task_, s).total > 0) {
          decided_ = index_;
          if (end_when_decided_) {
            s.ended_decided = true;
            s.end_time = t;
            return true;
          }
        }
      }
      last_leg_ = f;
      footprint_[i] = {d->xpos[3 * body_.feet[i]], d->xpos[3 * body_.feet[i] + 1]};
    }
    ground_[i] = now[i];
  }

  // Strides: the controller's states, for the pose samples.
  const int state = controller_.phase();
  if (controller_.phase_changed() && state != state_) {
    const int ended = state_;
    if (recording_) {
      state_time_.push_back(t);
      state_qpos_.insert(state_qpos_.end(), d->qpos, d->qpos + m->nq);
      close_state(ended);
    }
    state_time_.clear();
    state_qpos_.clear();
    state_ = state;
    if (controller_.swing_leg(state) != controller_.swing_leg(ended)) {
      // A step's last phase ended (the other leg swings now): a touch-down, or a swing
      // foot that never came down.
      if (!contacts_.foot[static_cast<size_t>(controller_.swing_leg(ended))]) {
        return fall(d, "the swing foot did not come down");
      }
      ++strikes_;
      if (state == 0) stride_heading_ = raw;  // a stride begins (the skill's first phase)
      if (strikes_ == w.steps) {
        complete_ = recording_;  // the last evaluated stride has ended
        recording_ = false;
      } else if (state == 0 && strikes_ >= w.settle_steps && strikes_ < w.steps) {
        recording_ = true;  // a stride begins after the walk has settled
      }
    }
  }
  // The walk is over when it has taken its steps and the controller its strides (for a
  // walk whose feet land only when its swings end, the same touch-down).
  if (static_cast<int>(walk.steps.size()) >= w.steps && strikes_ >= w.steps) {
    s.end_time = t;
    return true;
  }
  if (recording_) {
    state_time_.push_back(t);
    state_qpos_.insert(state_qpos_.end(), d->qpos, d->qpos + m->nq);
  }

  // Flight: a walk always has a foot on the ground (a moment's lift while the weight
  // passes from one foot to the other is allowed).
  if (contacts_.foot[0] || contacts_.foot[1]) {
    flight_start_ = -1;
  } else if (flight_start_ < 0) {
    flight_start_ = t;
  } else if (t - flight_start_ > w.max_flight) {
    return fall(d, "both feet were off the ground for longer than max_flight (a hop, not a walk)");
  }

  // What the listed constraints measure themselves.
  terms_.observe(m, d, s);

  // Falls.
  if (contacts_.non_foot && terms_.contact_is_fall(m, d))
    return fall(d, "a body other than the feet touched the ground or an object");
  const double feet_z = 0.5 * (d->xipos[3 * body_.feet[0] + 2] + d->xipos[3 * body_.feet[1] + 2]);
  if (controller_.com()[2] - feet_z < task_.simulation.fall_com_height) {
    return fall(d, "the centre of mass dropped to the feet");
  }
  if (t + m->opt.timestep > w.max_time) return fall(d, "did not take its steps in time");
  return false;
}

std::vector<PoseSample> WalkObserver::poses(SimWorker& worker) const {
  std::vector<PoseSample> out;
  if (!complete_) return out;
  const mjModel* m = worker.model();
  mjData* d = worker.data();
  for (size_t k = 0; k < sample_state_.size(); ++k) {
    mju_copy(d->qpos, sample_qpos_.data() + k * static_cast<size_t>(nq_), nq_);
    mju_normalize4(d->qpos + body_.root_qpos + 3);
    mj_kinematics(m, d);
    PoseSample p;
    p.phase = sample_state_[k];
    p.phase_time = sample_tau_[k];
    p.time = sample_time_[k];
    // In the stride's heading frame: the same gait walked in another direction gives the
    // same poses (the metric aligns the translation itself).
    const Eigen::Matrix3d to_heading =
        Eigen::AngleAxisd(-sample_heading_[k], Eigen::Vector3d::UnitZ()).toRotationMatrix();
    p.link_com.resize(3, static_cast<int>(body_.links.size()));
    for (size_t i = 0; i < body_.links.size(); ++i) {
      const double* x = d->xipos + 3 * body_.links[i];
      p.link_com.col(static_cast<int>(i)) = to_heading * Eigen::Vector3d(x[0], x[1], x[2]);
    }
    p.angles.resize(static_cast<int>(body_.joints.size()));
    for (size_t i = 0; i < body_.joints.size(); ++i) p.angles[static_cast<int>(i)] = d->qpos[body_.joints[i].qpos];
    p.root = Eigen::Quaterniond(to_heading) * root_orientation(body_, d->qpos);
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace diverse
