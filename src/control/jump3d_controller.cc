#include "control/jump3d_controller.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/error.h"
#include "core/toml_reader.h"

namespace diverse {
namespace {


// m: how far along the heading a leg placed again while landing goes from beside the foot
// still on the ground, toward the COM's capture point.
constexpr double kSwingReach = 0.2;

bool is_stance(int phase) { return phase == kStart || phase == kCrouch || phase == kExtend || phase == kLand; }

// World-pitch ranges (rad) of the links tracked in stance: root, foot, chest.
constexpr double kRootRange[2] = {-1.2, 1.2};
constexpr double kFootRange[2] = {-1.0, 0.4};
constexpr double kChestRange[2] = {-1.2, 1.2};

using Vec3 = std::array<double, 3>;

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec3 scale(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
// Rodrigues: u turned by `angle` about the unit axis a.
Vec3 turn(const Vec3& a, double angle, const Vec3& u) {
  const double c = std::cos(angle), s = std::sin(angle);
  return add(add(scale(u, c), scale(cross(a, u), s)), scale(a, dot(a, u) * (1 - c)));
}
Vec3 in_frame(const std::array<double, 4>& inv, const std::array<double, 3>& v) {
  Vec3 out;
  mju_rotVecQuat(out.data(), v.data(), inv.data());
  return out;
}

// The groups a jump3d controller drives, by role.
struct Layout {
  int hip = -1, hip_roll = -1, knee = -1, ankle = -1, foot = -1, chest = -1;
  std::vector<int> posed;  // parameterized groups (sagittal, not neck or wrist)
};

bool on_feet(const Character& body, const JointGroup& g) {
  for (int k : g.joints) {
    const int b = body.joints[static_cast<size_t>(k)].body;
    if (b != body.feet[0] && b != body.feet[1]) return false;
  }
  return true;
}

Layout layout_of(const Character& body) {
  Layout l;
  l.hip = body.find_group(JointRole::kHip, JointPlane::kSagittal);
  l.hip_roll = body.find_group(JointRole::kHip, JointPlane::kCoronal);
  l.knee = body.find_group(JointRole::kKnee, JointPlane::kSagittal);
  l.ankle = body.find_group(JointRole::kAnkle, JointPlane::kSagittal);
  size_t depth = 0;
  for (size_t g = 0; g < body.groups.size(); ++g) {
    const JointGroup& group = body.groups[g];
    if (group.plane != JointPlane::kSagittal) continue;
    if (l.foot < 0 && group.joints.size() == 2 && on_feet(body, group)) l.foot = static_cast<int>(g);
    if (group.role == JointRole::kWaist) {
      const size_t d = body.chain(group.joints[0]).size();
      if (l.chest < 0 || d > depth) {
        l.chest = static_cast<int>(g);
        depth = d;
      }
    }
    if (group.role != JointRole::kNeck && group.role != JointRole::kWrist) l.posed.push_back(static_cast<int>(g));
  }
  return l;
}

std::string pose_name(int phase, const Character& body, const Layout& l, int group) {
  std::string name = body.groups[static_cast<size_t>(group)].name;
  if (is_stance(phase)) {
    if (group == l.hip) name = body.spec->root_body;
    if (group == l.foot) name = "foot";
    if (group == l.chest) name = "chest";
  }
  return std::string(jump_phase_name(phase)) + "." + name;
}

// Whether a posed group's value in `phase` is two parameters, _left and _right: every
// left/right pair when asymmetric, but for the hips in stance, whose value is the root's
// world pitch.
bool split(bool asymmetric, int phase, const Character& body, const Layout& l, int group) {
  return asymmetric && body.groups[static_cast<size_t>(group)].joints.size() == 2 &&
         !(is_stance(phase) && group == l.hip);
}

constexpr const char* kSideSuffix[2] = {"_left", "_right"};

ParamSpec pose_spec(int phase, const Character& body, const Layout& l, int group) {
  const CharacterJoint& j = body.joints[static_cast<size_t>(body.groups[static_cast<size_t>(group)].joints[0])];
  double lo = j.lower, hi = j.upper;
  if (!std::isfinite(lo) || !std::isfinite(hi)) {
    lo = -M_PI;
    hi = M_PI;
  }
  if (is_stance(phase)) {
    const double* r = group == l.hip ? kRootRange : group == l.foot ? kFootRange : group == l.chest ? kChestRange : nullptr;
    if (r != nullptr) {
      lo = r[0];
      hi = r[1];
    }
  }
  return {pose_name(phase, body, l, group), lo, hi, "rad"};
}

double clamp_to_range(const CharacterJoint& j, double q) {
  if (std::isfinite(j.lower) && std::isfinite(j.upper)) return std::clamp(q, j.lower, j.upper);
  return q;
}

}  // namespace

std::shared_ptr<const ControllerConfig> Jump3dControllerConfig::with_landing_height(double height) const {
  auto c = std::make_shared<Jump3dControllerConfig>(*this);
  c->landing_height_m = height;
  return c;
}

// ---------------------------------------------------------------------------------------
// The plug-in.

std::shared_ptr<const ControllerConfig> Jump3dControllerType::read_config(const TomlReader& r) const {
  r.only({"type", "landing_control", "landing_height", "extend_timeout", "com_kp", "com_kd", "asymmetric", "yaw_kp",
          "yaw_kd", "neck_attitude_kp", "neck_attitude_kd", "land_swing_placement", "joint_space_extend",
          "extend_root_kd"});
  auto c = std::make_shared<Jump3dControllerConfig>();
  c->landing_control = r.boolean("landing_control", c->landing_control);
  c->landing_height_m = r.number("landing_height", 0, 3, c->landing_height_m);
  c->extend_timeout = r.number("extend_timeout", 0.1, 3, c->extend_timeout);
  c->com_kp = r.number("com_kp", 0, 500, c->com_kp);
  c->com_kd = r.number("com_kd", 0, 100, c->com_kd);
  c->asymmetric = r.boolean("asymmetric", c->asymmetric);
  c->yaw_kp = r.number("yaw_kp", 0, 5000, c->yaw_kp);
  c->yaw_kd = r.number("yaw_kd", 0, 1000, c->yaw_kd);
  c->neck_attitude_kp = r.number("neck_attitude_kp", 0, 10, c->neck_attitude_kp);
  c->neck_attitude_kd = r.number("neck_attitude_kd", 0, 2, c->neck_attitude_kd);
  c->land_swing_placement = r.boolean("land_swing_placement", c->land_swing_placement);
  c->joint_space_extend = r.boolean("joint_space_extend", c->joint_space_extend);
  c->extend_root_kd = r.number("extend_root_kd", 0, 5000, c->extend_root_kd);
  if (c->extend_root_kd > 0 && !c->joint_space_extend) r.fail("extend_root_kd", "expected joint_space_extend = true with it");
  return c;
}

void Jump3dControllerType::check(const Character& body, const std::string& task_file) const {
  const std::string who = "the character " + body.spec->file;
  if (body.root != RootKind::kFree) {
    throw_field_error(task_file, "controller.type",
                      "expected a character with a free root for \"jump3d\", but " + who +
                          " has a planar root (use \"jump2d\")");
  }
  for (JointRole role : {JointRole::kHip, JointRole::kKnee, JointRole::kAnkle}) {
    const int g = body.find_group(role, JointPlane::kSagittal);
    if (g < 0) {
      throw_field_error(task_file, "controller.type",
                        std::string("expected a sagittal joint group with role \"") + to_string(role) +
                            "\" for \"jump3d\", but " + who + " has none");
    }
    if (body.groups[static_cast<size_t>(g)].joints.size() != 2) {
      throw_field_error(task_file, "controller.type",
                        std::string("expected a left/right pair in the sagittal \"") + to_string(role) +
                            "\" group for \"jump3d\" (two legs), in " + who);
    }
  }
  if (layout_of(body).foot < 0) {
    throw_field_error(task_file, "controller.type",
                      "expected a sagittal left/right joint group on the foot bodies for \"jump3d\" "
                      "(the feet's pitch), but " + who + " has none");
  }
}

std::vector<ParamSpec> Jump3dControllerType::parameter_specs(const Character& body,
                                                             const ControllerConfig& config) const {
  const auto* c = dynamic_cast<const Jump3dControllerConfig*>(&config);
  if (c == nullptr) throw std::logic_error("jump3d: configuration of another controller");
  return Jump3dController::parameter_specs(body, c->asymmetric);
}

std::unique_ptr<Controller> Jump3dControllerType::make(const Character& body, const ControllerConfig& config,
                                                       const std::vector<double>& values) const {
  const auto* c = dynamic_cast<const Jump3dControllerConfig*>(&config);
  if (c == nullptr) throw std::logic_error("jump3d: configuration of another controller");
  auto controller = std::make_unique<Jump3dController>(body, *c);
  controller->set_parameters(values);
  return controller;
}

// ---------------------------------------------------------------------------------------
// The controller.

std::vector<ParamSpec> Jump3dController::parameter_specs(const Character& body, bool asymmetric) {
  const Layout l = layout_of(body);
  std::vector<ParamSpec> specs;
  // One parameter, or two (NAME_left, NAME_right) with the same range.
  auto add = [&specs](const ParamSpec& spec, bool two) {
    if (!two) {
      specs.push_back(spec);
      return;
    }
    for (const char* suffix : kSideSuffix) {
      ParamSpec side = spec;
      side.name += suffix;
      specs.push_back(side);
    }
  };
  for (int p = 0; p < kNumJumpPhases; ++p) {
    for (int g : l.posed) add(pose_spec(p, body, l, g), split(asymmetric, p, body, l, g));
    std::vector<ParamSpec> gains;
    append_jump_gain_specs(p, gains);
    for (const ParamSpec& g : gains) add(g, asymmetric);
  }
  specs.push_back({"start.duration", 0.05, 0.6, "s"});
  specs.push_back({"crouch.duration", 0.1, 1.0, "s"});
  specs.push_back({"land.duration", 0.05, 0.8, "s"});
  specs.push_back({"crouch.lean", -0.15, 0.15, "m"});
  specs.push_back({"extend.lean", -0.4, 0.4, "m"});
  specs.push_back({"extend.speed", -6.0, 6.0, "m/s"});
  specs.push_back({"land.balance_offset", -0.1, 0.1, "m"});
  add({"landing.offset", -0.4, 0.4, "m"}, asymmetric);
  add({"landing.velocity_gain", -0.4, 0.4, "s"}, asymmetric);
  return specs;
}

Jump3dController::Jump3dController(const Character& body, const Jump3dControllerConfig& config)
    : body_(body), config_(config) {
  const Layout l = layout_of(body);
  hip_ = l.hip;
  knee_ = l.knee;
  ankle_ = l.ankle;
  foot_group_ = l.foot;
  chest_ = l.chest;
  neck_ = body.find_group(JointRole::kNeck, JointPlane::kSagittal);
  posed_ = l.posed;
  pose_slot_.assign(body.groups.size(), -1);
  for (size_t k = 0; k < posed_.size(); ++k) pose_slot_[static_cast<size_t>(posed_[k])] = static_cast<int>(k);
  gain_slot_.assign(body.groups.size(), -1);
  gain_slot_[static_cast<size_t>(hip_)] = 0;
  gain_slot_[static_cast<size_t>(knee_)] = 1;
  gain_slot_[static_cast<size_t>(ankle_)] = 2;
  for (auto& p : pose_) p.assign(posed_.size(), Sides{0, 0});
  const size_t n = body.joints.size();
  side_.assign(n, 0);
  for (size_t k = 0; k < n; ++k) side_[k] = body.joints[k].side == Side::kRight ? 1 : 0;
  for (int p = 0; p < kNumJumpPhases; ++p) {
    for (int g : posed_) {
      const bool two = split(config.asymmetric, p, body, l, g);
      split_[static_cast<size_t>(p)].push_back(two ? 1 : 0);
      param_count_ += two ? 2 : 1;
    }
  }
  param_count_ += kNumJumpPhases * (config.asymmetric ? 12 : 6) + (config.asymmetric ? 11 : 9);
  target_.assign(n, 0.0);
  flight_from_.assign(n, 0.0);
  from_.joints.assign(n, 0.0);
  goal_.joints.assign(n, 0.0);
  qpos0_.assign(n, 0.0);
  times_.names = jump_phase_names();
  times_.begin.assign(kNumJumpPhases, -1.0);
  times_.extend = kExtend;
  times_.rise = kRise;
  times_.fall = kFall;
  times_.land = kLand;

  // The legs: hip pitch and roll, and the chain from the hip down to the foot.
  const int hip_roll = l.hip_roll;
  for (int s = 0; s < 2; ++s) {
    LegGeometry& leg = legs_[static_cast<size_t>(s)];
    leg.hip_pitch = body.groups[static_cast<size_t>(hip_)].joints[static_cast<size_t>(s)];
    if (hip_roll >= 0 && body.groups[static_cast<size_t>(hip_roll)].joints.size() == 2) {
      leg.hip_roll = body.groups[static_cast<size_t>(hip_roll)].joints[static_cast<size_t>(s)];
    }
  }
}

void Jump3dController::set_parameters(const std::vector<double>& values) {
  if (values.size() != param_count_) throw std::logic_error("Jump3dController: parameter count");
  const bool asymmetric = config_.asymmetric;
  size_t k = 0;
  // In parameter_specs() order: one value for both sides, or the left's then the right's.
  auto next = [&](bool two) {
    Sides v;
    v[0] = values[k++];
    v[1] = two ? values[k++] : v[0];
    return v;
  };
  for (int p = 0; p < kNumJumpPhases; ++p) {
    const size_t ps = static_cast<size_t>(p);
    for (size_t g = 0; g < posed_.size(); ++g) pose_[ps][g] = next(split_[ps][g] != 0);
    for (size_t j = 0; j < 3; ++j) {
      kp_[ps][j] = next(asymmetric);
      kd_[ps][j] = next(asymmetric);
    }
  }
  start_duration_ = values[k++];
  crouch_duration_ = values[k++];
  land_duration_ = values[k++];
  lean_ = values[k++];
  extend_lean_ = values[k++];
  extend_speed_ = values[k++];
  land_offset_ = values[k++];
  landing_offset_ = next(asymmetric);
  landing_velocity_gain_ = next(asymmetric);
}

void Jump3dController::reset(const mjModel* m, const mjData* d) {
  com_velocity_ = SubtreeComVelocity(m, body_.root_body);
  StanceGains gains;
  gains.com_kp = config_.com_kp;
  gains.com_kd = config_.com_kd;
  gains.yaw_kp = config_.yaw_kp;
  gains.yaw_kd = config_.yaw_kd;
  stance_ = std::make_unique<StanceController>(body_, m, gains);
  gravity_ = -m->opt.gravity[2];
  const size_t n = body_.joints.size();
  for (size_t k = 0; k < n; ++k) qpos0_[k] = m->qpos0[body_.joints[k].qpos];
  const double* q0 = m->qpos0 + body_.root_qpos + 3;
  root0_inv_ = {q0[0], -q0[1], -q0[2], -q0[3]};
  mju_normalize4(root0_inv_.data());

  // Leg geometry at qpos0, in the root's frame.
  const int foot_group = foot_group_;
  double middle = 0;
  std::array<Vec3, 2> foot_point{};
  for (int s = 0; s < 2; ++s) {
    LegGeometry& leg = legs_[static_cast<size_t>(s)];
    const CharacterJoint& hip = body_.joints[static_cast<size_t>(leg.hip_pitch)];
    const int foot_joint = body_.groups[static_cast<size_t>(foot_group)].joints[static_cast<size_t>(s)];
    const CharacterJoint& foot = body_.joints[static_cast<size_t>(foot_joint)];
    leg.pitch0 = m->qpos0[hip.qpos];
    leg.pitch_axis = in_frame(root0_inv_, hip.axis0);
    if (leg.hip_roll >= 0) {
      const CharacterJoint& roll = body_.joints[static_cast<size_t>(leg.hip_roll)];
      leg.roll0 = m->qpos0[roll.qpos];
      leg.roll_axis = in_frame(root0_inv_, roll.axis0);
    }
    // The joints strictly between the hip's body and the foot's, top down (chain() runs
    // from the joint's body up to the root).
    const std::vector<int>& chain = body_.chain(foot_joint);
    leg.middle.clear();
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const CharacterJoint& j = body_.joints[static_cast<size_t>(*it)];
      if (j.body != hip.body && j.body != foot.body) leg.middle.push_back(*it);
    }
    leg.middle0.clear();
    leg.axes.clear();
    leg.segments.clear();
    Vec3 from = hip.anchor0;
    for (int k : leg.middle) {
      const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
      leg.middle0.push_back(m->qpos0[j.qpos]);
      leg.axes.push_back(in_frame(root0_inv_, j.axis0));
      leg.segments.push_back(in_frame(root0_inv_, sub(j.anchor0, from)));
      from = j.anchor0;
    }
    leg.segments.push_back(in_frame(root0_inv_, sub(foot.anchor0, from)));
    foot_point[static_cast<size_t>(s)] = in_frame(root0_inv_, foot.anchor0);
    middle += 0.5 * foot_point[static_cast<size_t>(s)][1];
  }
  for (int s = 0; s < 2; ++s) legs_[static_cast<size_t>(s)].lateral = foot_point[static_cast<size_t>(s)][1] - middle;

  std::fill(times_.begin.begin(), times_.begin.end(), -1.0);
  extend_timed_out_ = false;
  takeoff_com_z_ = 0;
  free_since_ = -1;
  for (size_t k = 0; k < n; ++k) target_[k] = d->qpos[body_.joints[k].qpos];
  stance_->reset(m, d);
  heading_ = stance_->heading();
  const int root = body_.root_body;
  for (int k = 0; k < 3; ++k) com_[static_cast<size_t>(k)] = d->subtree_com[3 * root + k];
  com_vel_ = {0, 0, 0};
  enter(kStart, m, d);
  phase_changed_ = false;
}

void Jump3dController::enter(int phase, const mjModel* m, const mjData* d) {
  const double t = d->time;
  const int previous = phase_;
  phase_ = phase;
  phase_begin_ = t;
  phase_changed_ = true;
  times_.begin[static_cast<size_t>(phase)] = t;
  const size_t n = body_.joints.size();
  const std::vector<Sides>& pose = pose_[static_cast<size_t>(phase)];

  if (phase == kExtend && config_.joint_space_extend) {
    // A push-off in joint space: every target at once, the hip, foot and chest values as
    // joint angles from the standing pose.
    for (size_t k = 0; k < n; ++k) {
      const int g = body_.joints[k].group;
      const int slot = pose_slot_[static_cast<size_t>(g)];
      const double value = slot >= 0 ? pose[static_cast<size_t>(slot)][static_cast<size_t>(side_[k])] : 0.0;
      if (slot < 0) target_[k] = qpos0_[k];
      else if (g == hip_ || g == foot_group_ || g == chest_) target_[k] = clamp_to_range(body_.joints[k], qpos0_[k] + value);
      else target_[k] = value;
    }
    phase_duration_ = 0;
    return;
  }
  if (is_stance(phase)) {
    if (phase == kLand) stance_->reset(m, d);  // the heading and footing it landed with
    // Start from where the body is (after reset or flight) or from the targets commanded
    // so far (from one stance phase to the next).
    const bool continuing = phase != kStart && phase != kLand && is_stance(previous);
    if (!continuing) {
      const StanceController::Pitches p = stance_->measured_pitches(d);
      from_.root = p.root;
      from_.torso = p.torso;
      from_.foot = {p.foot, p.foot};  // both feet from their mean
      for (size_t k = 0; k < n; ++k) from_.joints[k] = d->qpos[body_.joints[k].qpos];
    } else {
      from_ = goal_;
    }
    goal_.root = pose[static_cast<size_t>(pose_slot_[static_cast<size_t>(hip_)])][0];
    goal_.foot = pose[static_cast<size_t>(pose_slot_[static_cast<size_t>(foot_group_)])];
    goal_.torso = chest_ >= 0 ? pose[static_cast<size_t>(pose_slot_[static_cast<size_t>(chest_)])][0] : goal_.root;
    for (size_t k = 0; k < n; ++k) {
      const int g = body_.joints[k].group;
      const int slot = pose_slot_[static_cast<size_t>(g)];
      if (g == hip_ || g == foot_group_ || g == chest_) {
        goal_.joints[k] = from_.joints[k];  // tracked in the world; held if the leg is off the ground
      } else {
        goal_.joints[k] = slot >= 0 ? pose[static_cast<size_t>(slot)][static_cast<size_t>(side_[k])] : qpos0_[k];
      }
    }
    for (size_t k = 0; k < n; ++k) {
      const int gs = gain_slot_[static_cast<size_t>(body_.joints[k].group)];
      const JointGroup& g = body_.groups[static_cast<size_t>(body_.joints[k].group)];
      // The strength model scales every joint's PD gains (Character::strength).
      const double s = body_.strength;
      if (gs >= 0) {
        const size_t side = static_cast<size_t>(side_[k]);
        stance_->set_joint_gains(static_cast<int>(k), s * kp_[static_cast<size_t>(phase)][static_cast<size_t>(gs)][side],
                                 s * kd_[static_cast<size_t>(phase)][static_cast<size_t>(gs)][side]);
      } else {
        stance_->set_joint_gains(static_cast<int>(k), s * g.kp, s * g.kd);
      }
    }
    // The root's gains are the two hips' (twice the hip gain when they share it; x + x is
    // 2 x exactly).
    const auto& hip_kp = kp_[static_cast<size_t>(phase)][0];
    const auto& hip_kd = kd_[static_cast<size_t>(phase)][0];
    stance_->set_root_gains(hip_kp[0] + hip_kp[1], hip_kd[0] + hip_kd[1]);
    const double h = stance_->heading();
    const double offset = phase == kLand ? land_offset_ : phase == kExtend ? extend_lean_ : lean_;
    stance_->set_com_offset(offset * std::cos(h), offset * std::sin(h));
    // The push-off drives the COM towards a speed along the heading; the other stance
    // phases hold it still.
    const double speed = phase == kExtend ? extend_speed_ : 0.0;
    stance_->set_com_velocity(speed * std::cos(h), speed * std::sin(h));
    stance_->set_com_force(phase == kExtend ? StanceController::ComForce::kPush : StanceController::ComForce::kSupport);
    switch (phase) {
      case kStart: phase_duration_ = start_duration_; break;
      case kCrouch: phase_duration_ = crouch_duration_; break;
      case kLand: phase_duration_ = land_duration_; break;
      default: phase_duration_ = 0; break;  // extend: at once
    }
    return;
  }

  // Flight: joint targets, from the pose at take-off or the targets commanded so far.
  for (size_t k = 0; k < n; ++k) {
    flight_from_[k] = phase == kRise ? d->qpos[body_.joints[k].qpos] : target_[k];
    target_[k] = flight_from_[k];
  }
  if (phase == kRise) {
    takeoff_com_z_ = com_[2];
    phase_duration_ = std::max(com_vel_[2], 0.05) / gravity_;
  } else {
    phase_duration_ = std::sqrt(2 * std::max(com_[2] - takeoff_com_z_, 0.01) / gravity_);
  }
}

void Jump3dController::landing_hips(const mjData* d, std::vector<double>& targets) const {
  // Where the COM comes down on its ballistic path to the height it took off at (raised by
  // the landing surface's height): where the feet meet the ground.
  const double z = std::max(com_[2] - takeoff_com_z_ - config_.landing_height_m, 0.0);
  const double vz = com_vel_[2];
  const double t_cross = (vz + std::sqrt(vz * vz + 2 * gravity_ * z)) / gravity_;
  const double f[2] = {std::cos(heading_), std::sin(heading_)};
  const double lat[2] = {-f[1], f[0]};
  std::array<std::array<double, 2>, 2> goals{};
  for (int s = 0; s < 2; ++s) {
    const LegGeometry& leg = legs_[static_cast<size_t>(s)];
    for (int i = 0; i < 2; ++i) {
      goals[static_cast<size_t>(s)][static_cast<size_t>(i)] =
          com_[static_cast<size_t>(i)] + com_vel_[static_cast<size_t>(i)] * t_cross +
          landing_offset_[static_cast<size_t>(s)] * f[i] +
          landing_velocity_gain_[static_cast<size_t>(s)] * com_vel_[static_cast<size_t>(i)] + leg.lateral * lat[i];
    }
  }
  point_legs(d, goals, {true, true}, targets);
}

void Jump3dController::point_legs(const mjData* d, const std::array<std::array<double, 2>, 2>& goals,
                                  const std::array<bool, 2>& which, std::vector<double>& targets) const {
  const int root = body_.root_body;
  std::array<double, 4> root_inv{d->xquat[4 * root], -d->xquat[4 * root + 1], -d->xquat[4 * root + 2],
                                 -d->xquat[4 * root + 3]};
  for (int s = 0; s < 2; ++s) {
    if (!which[static_cast<size_t>(s)]) continue;
    const LegGeometry& leg = legs_[static_cast<size_t>(s)];
    const double* goal = goals[static_cast<size_t>(s)].data();
    // The leg (hip to foot joint) with the joints between at their targets, in the root's
    // frame with the hip at its reference angles: s0 + R1 (s1 + R2 (s2 + ...)).
    Vec3 v = leg.segments.back();
    for (size_t i = leg.middle.size(); i-- > 0;) {
      const double q = targets[static_cast<size_t>(leg.middle[i])];
      v = add(leg.segments[i], turn(leg.axes[i], q - leg.middle0[i], v));
    }
    const double length = std::sqrt(dot(v, v));
    if (length < 1e-6) continue;
    const CharacterJoint& hip = body_.joints[static_cast<size_t>(leg.hip_pitch)];
    const double* p = d->xanchor + 3 * hip.joint;
    const double dx = goal[0] - p[0], dy = goal[1] - p[1];
    const double reach = std::min(std::hypot(dx, dy), 0.9 * length);
    const double k = std::hypot(dx, dy) > 1e-9 ? reach / std::hypot(dx, dy) : 0;
    const Vec3 r_world{dx * k, dy * k, -std::sqrt(length * length - reach * reach)};
    Vec3 w;
    mju_rotVecQuat(w.data(), r_world.data(), root_inv.data());
    w = scale(w, 1 / length);
    const HipAngles a = hip_angles_for(scale(v, 1 / length), leg.pitch_axis, leg.roll_axis, leg.hip_roll >= 0, w);
    targets[static_cast<size_t>(leg.hip_pitch)] = clamp_to_range(hip, leg.pitch0 + a.pitch);
    if (leg.hip_roll >= 0) {
      const CharacterJoint& r = body_.joints[static_cast<size_t>(leg.hip_roll)];
      targets[static_cast<size_t>(leg.hip_roll)] = clamp_to_range(r, leg.roll0 + a.roll);
    }
  }
}

void Jump3dController::place_lifted_legs(const mjData* d, const ContactState& contacts) {
  // A leg off the ground while landing is placed again instead of holding its hip
  // angles of the touch-down, which the body's turn toward its landing pitch would
  // swing away: beside the foot still on the ground, moved along the heading toward
  // the COM's capture point by at most kSwingReach; with both feet off, at the
  // capture point (each foot at its standing sideways offset).
  const double height = std::max(com_[2] - config_.landing_height_m, 0.1);
  const double t_capture = std::sqrt(height / gravity_);
  const double f[2] = {std::cos(heading_), std::sin(heading_)};
  const double lat[2] = {-f[1], f[0]};
  double capture[2];
  for (int i = 0; i < 2; ++i) capture[i] = com_[static_cast<size_t>(i)] + t_capture * com_vel_[static_cast<size_t>(i)];
  const int standing = contacts.foot[0] ? 0 : contacts.foot[1] ? 1 : -1;
  std::array<std::array<double, 2>, 2> goals{};
  for (int side = 0; side < 2; ++side) {
    const double w = legs_[static_cast<size_t>(side)].lateral;
    for (int i = 0; i < 2; ++i) goals[static_cast<size_t>(side)][static_cast<size_t>(i)] = capture[i] + w * lat[i];
    if (standing < 0) continue;
    const int foot = body_.feet[static_cast<size_t>(standing)];
    const double* joint = d->xpos + 3 * foot;   // the stance foot's joint
    const double* centre = d->xipos + 3 * foot;  // and its sole's middle
    const double reach = std::clamp(f[0] * (capture[0] - centre[0]) + f[1] * (capture[1] - centre[1]),
                                    -kSwingReach, kSwingReach);
    const double dw = w - legs_[static_cast<size_t>(standing)].lateral;
    for (int i = 0; i < 2; ++i)
      goals[static_cast<size_t>(side)][static_cast<size_t>(i)] = joint[i] + reach * f[i] + dw * lat[i];
  }
  point_legs(d, goals, {!contacts.foot[0], !contacts.foot[1]}, target_);
}

void Jump3dController::turn_head_toward_landing(const mjData* d) {
  const int root = body_.root_body;
  // The head as a reaction mass: the root's backward pitch beyond the landing's target
  // (and its rate) swings the head back, which turns the body forward, and the other way.
  const double error = stance_->measured_pitches(d).root - pose_[kLand][static_cast<size_t>(pose_slot_[static_cast<size_t>(hip_)])][0];
  const double* w = d->cvel + 6 * root;
  const double rate = -(-std::sin(heading_) * w[0] + std::cos(heading_) * w[1]);  // backwards
  const double turn = config_.neck_attitude_kp * error + config_.neck_attitude_kd * rate;
  for (int k : body_.groups[static_cast<size_t>(neck_)].joints) {
    const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
    target_[static_cast<size_t>(k)] = clamp_to_range(j, qpos0_[static_cast<size_t>(k)] + turn);
  }
}

void Jump3dController::control(const mjModel* m, mjData* d, const ContactState& contacts, JointDrive& drive) {
  const double t = d->time;
  const int root = body_.root_body;
  for (int k = 0; k < 3; ++k) com_[static_cast<size_t>(k)] = d->subtree_com[3 * root + k];
  com_vel_ = com_velocity_(m, d);

  // Transitions: at most one per step.
  phase_changed_ = false;
  const double elapsed = t - phase_begin_;
  switch (phase_) {
    case kStart:
      if (elapsed >= start_duration_) enter(kCrouch, m, d);
      break;
    case kCrouch:
      if (elapsed >= crouch_duration_) enter(kExtend, m, d);
      break;
    case kExtend:
      if (contacts.any) free_since_ = -1;
      else if (free_since_ < 0) free_since_ = t;
      if (free_since_ >= 0 && t - free_since_ >= config_.airborne_time - 1e-9 && com_vel_[2] > 0) {
        enter(kRise, m, d);
      } else if (elapsed >= config_.extend_timeout) {
        extend_timed_out_ = true;
        enter(kLand, m, d);
      }
      break;
    case kRise:
      if (contacts.any) {
        times_.begin[kFall] = t;  // touched down while rising: a zero-length fall
        enter(kLand, m, d);
      } else if (com_vel_[2] <= 0) {
        enter(kFall, m, d);
      }
      break;
    case kFall:
      if (contacts.any) enter(kLand, m, d);
      break;
    default:
      break;
  }

  const double s = phase_duration_ > 0 ? std::clamp((t - phase_begin_) / phase_duration_, 0.0, 1.0) : 1.0;
  const size_t n = body_.joints.size();

  if (phase_ == kExtend && config_.joint_space_extend) {
    drive_toward_targets(d, drive, /*foot_with_ankle_gains=*/true);  // the targets enter() set
    if (config_.extend_root_kd > 0) damp_root_with_hips(d, drive);
    return;
  }
  if (is_stance(phase_)) {
    for (size_t k = 0; k < n; ++k) target_[k] = from_.joints[k] + s * (goal_.joints[k] - from_.joints[k]);
    if (phase_ == kLand && config_.land_swing_placement && !(contacts.foot[0] && contacts.foot[1]))
      place_lifted_legs(d, contacts);
    stance_->set_pitches(from_.root + s * (goal_.root - from_.root), from_.torso + s * (goal_.torso - from_.torso),
                         {from_.foot[0] + s * (goal_.foot[0] - from_.foot[0]),
                          from_.foot[1] + s * (goal_.foot[1] - from_.foot[1])});
    stance_->set_targets(target_);
    stance_->control(m, d, drive);
    return;
  }

  // Flight: PD toward the phase's joint targets.
  const std::vector<Sides>& pose = pose_[static_cast<size_t>(phase_)];
  for (size_t k = 0; k < n; ++k) {
    const int slot = pose_slot_[static_cast<size_t>(body_.joints[k].group)];
    const double goal = slot >= 0 ? pose[static_cast<size_t>(slot)][static_cast<size_t>(side_[k])] : qpos0_[k];
    target_[k] = flight_from_[k] + s * (goal - flight_from_[k]);
  }
  if (phase_ == kFall && config_.landing_control) {
    // Blend toward the landing placement while the root is within 60 degrees of upright.
    double up0[3];
    const double z[3] = {0, 0, 1};
    mju_rotVecQuat(up0, z, root0_inv_.data());
    double up[3];
    mju_mulMatVec(up, d->xmat + 9 * root, up0, 3, 3);
    const double w = std::clamp((up[2] - 0.5) / 0.5, 0.0, 1.0);
    if (w > 0) {
      std::array<double, 4> hips{};
      for (int side = 0; side < 2; ++side) {
        const LegGeometry& leg = legs_[static_cast<size_t>(side)];
        hips[static_cast<size_t>(2 * side)] = target_[static_cast<size_t>(leg.hip_pitch)];
        hips[static_cast<size_t>(2 * side + 1)] = leg.hip_roll >= 0 ? target_[static_cast<size_t>(leg.hip_roll)] : 0;
      }
      landing_hips(d, target_);
      for (int side = 0; side < 2; ++side) {
        const LegGeometry& leg = legs_[static_cast<size_t>(side)];
        double& pitch = target_[static_cast<size_t>(leg.hip_pitch)];
        pitch = (1 - w) * hips[static_cast<size_t>(2 * side)] + w * pitch;
        if (leg.hip_roll >= 0) {
          double& roll = target_[static_cast<size_t>(leg.hip_roll)];
          roll = (1 - w) * hips[static_cast<size_t>(2 * side + 1)] + w * roll;
        }
      }
    }
  }
  if (neck_ >= 0 && (config_.neck_attitude_kp > 0 || config_.neck_attitude_kd > 0)) turn_head_toward_landing(d);
  drive_toward_targets(d, drive, /*foot_with_ankle_gains=*/false);
}

void Jump3dController::damp_root_with_hips(const mjData* d, JointDrive& drive) const {
  // Each hip hinge turns the root the other way about its axis; the two legs' hinges
  // together give the root -extend_root_kd times its angular velocity about each axis.
  const double* w = d->cvel + 6 * body_.root_body;
  for (const LegGeometry& leg : legs_) {
    for (int k : {leg.hip_pitch, leg.hip_roll}) {
      if (k < 0) continue;
      const double* a = d->xaxis + 3 * body_.joints[static_cast<size_t>(k)].joint;
      const double rate = a[0] * w[0] + a[1] * w[1] + a[2] * w[2];
      drive.set(k, drive.u(k) + 0.5 * config_.extend_root_kd * body_.strength * rate, drive.kd(k));
    }
  }
}

void Jump3dController::drive_toward_targets(const mjData* d, JointDrive& drive, bool foot_with_ankle_gains) const {
  const auto& kp = kp_[static_cast<size_t>(phase_)];
  const auto& kd = kd_[static_cast<size_t>(phase_)];
  for (size_t k = 0; k < body_.joints.size(); ++k) {
    const CharacterJoint& j = body_.joints[k];
    const JointGroup& g = body_.groups[static_cast<size_t>(j.group)];
    const int gs = foot_with_ankle_gains && j.group == foot_group_ ? 2 : gain_slot_[static_cast<size_t>(j.group)];
    const size_t side = static_cast<size_t>(side_[k]);
    const double p = body_.strength * (gs >= 0 ? kp[static_cast<size_t>(gs)][side] : g.kp);
    const double v = body_.strength * (gs >= 0 ? kd[static_cast<size_t>(gs)][side] : g.kd);
    drive.set(static_cast<int>(k), p * (target_[k] - d->qpos[j.qpos]), v);
  }
}

}  // namespace diverse
