#include "control/jump_controller.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace diverse {
namespace {

constexpr const char* kPhaseNames[kNumJumpPhases] = {"start", "crouch", "extend",
                                                     "rise",  "fall",   "land"};
constexpr int kPoseTypes = 8;  // hip .. wrist; neck and head are not parameters
constexpr const char* kGainJoints[3] = {"hip", "knee", "ankle"};

bool is_stance(int phase) { return phase == kStart || phase == kCrouch || phase == kExtend || phase == kLand; }
bool has_balance(int phase) { return phase == kStart || phase == kCrouch || phase == kLand; }

double wrap(double a) { return std::remainder(a, 2 * M_PI); }

// Parameter name of a pose entry: stance phases name the world-frame quantities.
std::string pose_name(int phase, int type) {
  std::string joint = joint_type_name(type);
  if (is_stance(phase)) {
    if (type == kHip) joint = "pelvis";
    if (type == kAnkle) joint = "foot";
    if (type == kWaistUpper) joint = "chest";
  }
  return std::string(kPhaseNames[phase]) + "." + joint;
}

// Ranges (rad). Stance: world pitches for pelvis, foot and chest. Flight: joint ranges
// of the model.
ParamSpec pose_spec(int phase, int type) {
  static constexpr double kFlight[kPoseTypes][2] = {
      {-0.5, 2.4}, {-2.6, 0.0}, {-0.9, 0.7}, {-0.7, 0.4},
      {-0.7, 0.4}, {-1.0, 3.1}, {0.0, 2.6},  {-1.2, 1.2}};
  static constexpr double kStance[kPoseTypes][2] = {
      {-1.4, 1.4}, {-2.6, 0.0}, {-1.0, 0.4}, {-0.7, 0.4},
      {-1.4, 1.4}, {-1.0, 3.1}, {0.0, 2.6},  {-1.2, 1.2}};
  const auto& r = is_stance(phase) ? kStance[type] : kFlight[type];
  return {pose_name(phase, type), r[0], r[1], "rad"};
}

std::vector<ParamSpec> make_specs() {
  std::vector<ParamSpec> specs;
  for (int p = 0; p < kNumJumpPhases; ++p) {
    for (int t = 0; t < kPoseTypes; ++t) specs.push_back(pose_spec(p, t));
    for (int j = 0; j < 3; ++j) {
      const std::string prefix = std::string(kPhaseNames[p]) + ".";
      const double kp_hi = j == 2 ? 1500 : 2000;
      specs.push_back({prefix + "kp_" + kGainJoints[j], 50, kp_hi, "Nm/rad"});
      specs.push_back({prefix + "kd_" + kGainJoints[j], 2, 200, "Nm s/rad"});
    }
  }
  specs.push_back({"start.duration", 0.05, 0.6, "s"});
  specs.push_back({"crouch.duration", 0.1, 1.0, "s"});
  specs.push_back({"land.duration", 0.05, 0.8, "s"});
  specs.push_back({"land.balance_offset", -0.1, 0.1, "m"});
  specs.push_back({"landing.offset", -0.4, 0.4, "m"});
  specs.push_back({"landing.velocity_gain", -0.4, 0.4, "s"});
  return specs;
}

}  // namespace

const char* jump_phase_name(int phase) {
  return (phase >= 0 && phase < kNumJumpPhases) ? kPhaseNames[phase] : "?";
}

ContactState scan_contacts(const mjModel* m, const mjData* d, const PlanarHuman& body) {
  ContactState c;
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& con = d->contact[i];
    if (con.exclude != 0) continue;  // in the margin gap: near, not touching
    for (int g : {con.geom1, con.geom2}) {
      const int b = m->geom_bodyid[g];
      if (b == 0 || m->body_rootid[b] != body.pelvis) continue;
      c.any = true;
      if (g == body.foot_geom[0]) {
        c.foot[0] = true;
      } else if (g == body.foot_geom[1]) {
        c.foot[1] = true;
      } else {
        c.non_foot = true;
      }
    }
  }
  return c;
}

const std::vector<ParamSpec>& JumpController::parameter_specs() {
  static const std::vector<ParamSpec> specs = make_specs();
  return specs;
}

JumpController::JumpController(const PlanarHuman& body, const JumpControllerConfig& config)
    : body_(body), config_(config) {
  from_.assign(body_.joints.size(), 0.0);
  target_.assign(body_.joints.size(), 0.0);
  for (const PlanarJoint& j : body_.joints) damped_dofs_.push_back(j.dof);
}

void JumpController::set_parameters(const std::vector<double>& values) {
  const auto& specs = parameter_specs();
  if (values.size() != specs.size()) throw std::logic_error("JumpController: parameter count");
  size_t k = 0;
  for (int p = 0; p < kNumJumpPhases; ++p) {
    for (auto& v : pose_[p]) v = 0;
    for (int t = 0; t < kPoseTypes; ++t) pose_[p][t] = values[k++];
    for (int j = 0; j < 3; ++j) {
      kp_[p][j] = values[k++];
      kd_[p][j] = values[k++];
    }
  }
  start_duration_ = values[k++];
  crouch_duration_ = values[k++];
  land_duration_ = values[k++];
  balance_offset_ = values[k++];
  landing_offset_ = values[k++];
  landing_velocity_gain_ = values[k++];
}

void JumpController::reset(mjModel* m, const mjData* d) {
  q_ = d->qpos;
  from_is_world_ = true;  // start is a stance phase
  for (size_t i = 0; i < body_.joints.size(); ++i) {
    target_[i] = d->qpos[body_.joints[i].qpos];
    from_[i] = to_world(body_.joints[i].type, static_cast<int>(i), q_, target_[i]);
  }
  gravity_ = -m->opt.gravity[2];
  times_ = PhaseTimes();
  extend_timed_out_ = false;
  phase_ = kStart;
  phase_begin_ = d->time;
  phase_duration_ = start_duration_;
  times_.begin[kStart] = d->time;
  takeoff_com_z_ = 0;
  free_since_ = -1;
  for (size_t i = 0; i < body_.joints.size(); ++i) {
    const int type = body_.joints[i].type;
    m->dof_damping[body_.joints[i].dof] = type <= kAnkle ? kd_[kStart][type] : config_.kd[type];
  }
}

void JumpController::enter(int phase, double time, mjModel*) {
  phase_ = phase;
  phase_begin_ = time;
  phase_changed_ = true;
  times_.begin[phase] = time;
  from_ = target_;
  from_is_world_ = is_stance(phase);
  if (from_is_world_) {
    // World-frame joints interpolate in world pitch: start from the pitch that the last
    // commanded joint target implies for the tracked link in the current pose.
    for (size_t i = 0; i < body_.joints.size(); ++i) {
      from_[i] = to_world(body_.joints[i].type, static_cast<int>(i), q_, target_[i]);
    }
  }
  switch (phase) {
    case kCrouch: phase_duration_ = crouch_duration_; break;
    case kExtend: phase_duration_ = 1e-9; break;
    case kRise:
      takeoff_com_z_ = com_[2];
      phase_duration_ = std::max(com_vel_[2], 0.05) / gravity_;
      break;
    case kFall:
      phase_duration_ = std::sqrt(2 * std::max(com_[2] - takeoff_com_z_, 0.01) / gravity_);
      break;
    case kLand: phase_duration_ = land_duration_; break;
    default: phase_duration_ = start_duration_; break;
  }
}

// Joint target (rad) that makes joint i's tracked link reach world pitch `world`, for
// the world-frame joints of stance phases; other joints pass through.
double JumpController::to_local(int type, int i, const double* q, double world) const {
  const PlanarJoint& j = body_.joints[i];
  switch (type) {
    case kHip:  // pelvis world pitch; the pelvis is the hip's parent
      return q[j.qpos] + wrap(q[body_.root_pitch_qpos] - world);
    case kAnkle: {  // foot world pitch; the foot is the ankle's child
      const int side = (i == body_.by_type[kAnkle][0]) ? 0 : 1;
      return wrap(world - body_.child_pitch(q, body_.by_type[kKnee][side]));
    }
    case kWaistUpper:  // chest world pitch; the chest is the upper waist's child
      return wrap(world - body_.child_pitch(q, body_.by_type[kWaistLower][0]));
    default:
      return world;
  }
}

// Inverse of to_local: the world pitch a joint target implies in the current pose.
double JumpController::to_world(int type, int i, const double* q, double local) const {
  const PlanarJoint& j = body_.joints[i];
  switch (type) {
    case kHip:
      return q[body_.root_pitch_qpos] - (local - q[j.qpos]);
    case kAnkle: {
      const int side = (i == body_.by_type[kAnkle][0]) ? 0 : 1;
      return local + body_.child_pitch(q, body_.by_type[kKnee][side]);
    }
    case kWaistUpper:
      return local + body_.child_pitch(q, body_.by_type[kWaistLower][0]);
    default:
      return local;
  }
}

double JumpController::landing_hip_goal(int i, const mjData* d) const {
  const PlanarJoint& hip = body_.joints[i];
  const int side = (i == body_.by_type[kHip][0]) ? 0 : 1;
  // Where the COM crosses the landing surface on its ballistic path.
  const double z = std::max(com_[2] - config_.landing_height, 0.0);
  const double vz = com_vel_[2];
  const double t_cross = (vz + std::sqrt(vz * vz + 2 * gravity_ * z)) / gravity_;
  const double x_target =
      com_[0] + com_vel_[0] * t_cross + landing_offset_ + landing_velocity_gain_ * com_vel_[0];
  const double dx = x_target - d->xanchor[3 * hip.joint];
  // Two-link leg: ankle x offset = l1 sin(th) + l2 sin(th + qk) = R sin(th + psi).
  const double qk = target_[body_.by_type[kKnee][side]];
  const double a = body_.thigh_length + body_.shin_length * std::cos(qk);
  const double b = body_.shin_length * std::sin(qk);
  const double thigh = std::asin(std::clamp(dx / std::hypot(a, b), -0.9, 0.9)) - std::atan2(b, a);
  return wrap(thigh - d->qpos[body_.root_pitch_qpos]);
}

void JumpController::control(mjModel* m, mjData* d, const ContactState& contacts) {
  const double t = d->time;
  const double* q = d->qpos;
  q_ = q;
  const int root = body_.pelvis;
  mj_subtreeVel(m, d);
  for (int k = 0; k < 3; ++k) {
    com_[k] = d->subtree_com[3 * root + k];
    com_vel_[k] = d->subtree_linvel[3 * root + k];
  }

  // Transitions: at most one per step.
  phase_changed_ = false;
  const double elapsed = t - phase_begin_;
  switch (phase_) {
    case kStart:
      if (elapsed >= start_duration_) enter(kCrouch, t, m);
      break;
    case kCrouch:
      if (elapsed >= crouch_duration_) enter(kExtend, t, m);
      break;
    case kExtend:
      // Airborne: no contact for airborne_time with the COM rising (soft contacts can
      // flicker for a step while the legs push).
      if (contacts.any) free_since_ = -1;
      else if (free_since_ < 0) free_since_ = t;
      if (free_since_ >= 0 && t - free_since_ >= config_.airborne_time - 1e-9 && com_vel_[2] > 0) {
        enter(kRise, t, m);
      } else if (elapsed >= config_.extend_timeout) {
        extend_timed_out_ = true;
        enter(kLand, t, m);
      }
      break;
    case kRise:
      if (contacts.any) {
        // Touched down while still rising (a low, flat jump): the peak and the landing
        // coincide, a zero-length fall, so every jump has both airborne phases.
        times_.begin[kFall] = t;
        enter(kLand, t, m);
      } else if (com_vel_[2] <= 0) {
        enter(kFall, t, m);
      }
      break;
    case kFall:
      if (contacts.any) enter(kLand, t, m);
      break;
    default:
      break;
  }

  // Targets: linear from the phase's starting targets to its goal.
  const double s = phase_ == kExtend
                       ? 1.0
                       : std::clamp((t - phase_begin_) / std::max(phase_duration_, 1e-6), 0.0, 1.0);
  const bool landing = phase_ == kFall && config_.landing_control;
  for (size_t i = 0; i < body_.joints.size(); ++i) {
    const int type = body_.joints[i].type;
    if (landing && type == kHip) continue;  // needs this step's knee targets
    const double goal = pose_[phase_][type];
    if (from_is_world_) {
      // Interpolate the world pitch along the shorter way round, then turn it into a
      // joint target for the current pose.
      const bool world = type == kHip || type == kAnkle || type == kWaistUpper;
      const double step = world ? wrap(goal - from_[i]) : goal - from_[i];
      target_[i] = to_local(type, static_cast<int>(i), q, from_[i] + s * step);
    } else {
      target_[i] = from_[i] + s * (goal - from_[i]);
    }
  }
  if (landing) {
    const double pelvis = q[body_.root_pitch_qpos];
    const double w = std::clamp((std::cos(pelvis) - 0.5) / 0.5, 0.0, 1.0);
    for (int i : body_.by_type[kHip]) {
      double goal = pose_[kFall][kHip];
      if (w > 0) goal = (1 - w) * goal + w * landing_hip_goal(i, d);
      target_[i] = from_[i] + s * (goal - from_[i]);
    }
  }

  // Balance: tau = J^T F on the stance legs.
  std::array<double, 32> balance{};
  if (has_balance(phase_) && contacts.any) {
    const double support =
        0.5 * (d->geom_xpos[3 * body_.foot_geom[0]] + d->geom_xpos[3 * body_.foot_geom[1]]);
    const double fx = std::clamp(config_.balance_kp * (support + balance_offset_ - com_[0]) -
                                     config_.balance_kd * com_vel_[0],
                                 -config_.balance_max_force, config_.balance_max_force);
    const double fz = config_.gravity_compensation * body_.total_mass * gravity_;
    for (int type : {kAnkle, kKnee, kHip}) {
      for (int i : body_.by_type[type]) {
        const double* p = d->xanchor + 3 * body_.joints[i].joint;
        const double rx = com_[0] - p[0], rz = com_[2] - p[2];
        balance[i] = -0.5 * (rx * fz - rz * fx);
      }
    }
  }

  // PD torques, clamped; damping goes to dof_damping (implicit), the rest to ctrl.
  // World-frame joints of stance phases damp the tracked link's world pitch rate: the
  // joint damping -kd qdot (implicit) plus an explicit -kd * (rate of the link on the
  // other side of the joint), with the sign that makes the sum the tracked link's rate.
  const bool stance = is_stance(phase_);
  const double* v = d->qvel;
  for (size_t i = 0; i < body_.joints.size(); ++i) {
    const PlanarJoint& j = body_.joints[i];
    const bool phase_gain = j.type <= kAnkle;
    const double kp = phase_gain ? kp_[phase_][j.type] : config_.kp[j.type];
    const double kd = phase_gain ? kd_[phase_][j.type] : config_.kd[j.type];
    const double qd = v[j.dof];
    double world_damping = 0;
    if (stance) {
      const int side = (j.type == kHip || j.type == kAnkle) ? (i == static_cast<size_t>(body_.by_type[j.type][0]) ? 0 : 1) : 0;
      if (j.type == kHip) {  // pelvis rate = -(qdot_hip) + thigh rate
        world_damping = kd * body_.child_pitch_rate(v, body_.by_type[kHip][side]);
      } else if (j.type == kAnkle) {  // foot rate = qdot_ankle + shin rate
        world_damping = -kd * body_.child_pitch_rate(v, body_.by_type[kKnee][side]);
      } else if (j.type == kWaistUpper) {  // chest rate = qdot + abdomen rate
        world_damping = -kd * body_.child_pitch_rate(v, body_.by_type[kWaistLower][0]);
      }
    }
    double tau = kp * (target_[i] - q[j.qpos]) - kd * qd + world_damping + balance[i];
    tau = std::clamp(tau, -j.torque_limit, j.torque_limit);
    d->ctrl[j.actuator] = tau + kd * qd;
    m->dof_damping[j.dof] = kd;
  }
}

}  // namespace diverse
