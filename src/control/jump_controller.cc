#include "control/jump_controller.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/error.h"
#include "core/toml_reader.h"

namespace diverse {
namespace {

constexpr const char* kPhaseNames[kNumJumpPhases] = {"start", "crouch", "extend",
                                                     "rise",  "fall",   "land"};
constexpr const char* kGainJoints[3] = {"hip", "knee", "ankle"};

bool is_stance(int phase) { return phase == kStart || phase == kCrouch || phase == kExtend || phase == kLand; }
bool has_balance(int phase) { return phase == kStart || phase == kCrouch || phase == kLand; }

// An angle in [-pi, pi]. Most are already there, and for them remainder(a, 2 pi) is a
// itself (a / 2 pi rounds to 0, ties to even), so the library call is skipped: the same
// bits, at a fraction of the cost.
double wrap(double a) { return std::fabs(a) <= M_PI ? a : std::remainder(a, 2 * M_PI); }

// World-pitch ranges (rad) of the links tracked in stance: pelvis, foot, chest.
constexpr double kPelvisRange[2] = {-1.4, 1.4};
constexpr double kFootRange[2] = {-1.0, 0.4};
constexpr double kChestRange[2] = {-1.4, 1.4};

// The groups a jump2d controller drives, by role.
struct Layout {
  int hip = -1, knee = -1, ankle = -1, chest = -1;
  std::vector<int> posed;  // parameterized groups, character order (not role neck)
};

Layout layout_of(const Character& body) {
  Layout l;
  l.hip = body.find_group(JointRole::kHip);
  l.knee = body.find_group(JointRole::kKnee);
  l.ankle = body.find_group(JointRole::kAnkle);
  // The topmost waist group: the one whose joint has the longest chain from the root.
  size_t depth = 0;
  for (size_t g = 0; g < body.groups.size(); ++g) {
    if (body.groups[g].role != JointRole::kWaist) continue;
    const size_t d = body.chain(body.groups[g].joints[0]).size();
    if (l.chest < 0 || d > depth) {
      l.chest = static_cast<int>(g);
      depth = d;
    }
  }
  for (size_t g = 0; g < body.groups.size(); ++g) {
    if (body.groups[g].role != JointRole::kNeck) l.posed.push_back(static_cast<int>(g));
  }
  return l;
}

// Parameter name of a pose entry: stance phases name the world-frame quantities.
std::string pose_name(int phase, const Character& body, const Layout& l, int group) {
  std::string name = body.groups[static_cast<size_t>(group)].name;
  if (is_stance(phase)) {
    if (group == l.hip) name = "pelvis";
    if (group == l.ankle) name = "foot";
    if (group == l.chest) name = "chest";
  }
  return std::string(kPhaseNames[phase]) + "." + name;
}

ParamSpec pose_spec(int phase, const Character& body, const Layout& l, int group) {
  const CharacterJoint& j = body.joints[static_cast<size_t>(body.groups[static_cast<size_t>(group)].joints[0])];
  double lo = j.lower, hi = j.upper;
  if (!std::isfinite(lo) || !std::isfinite(hi)) {
    lo = -M_PI;
    hi = M_PI;
  }
  if (is_stance(phase)) {
    const double* r = group == l.hip ? kPelvisRange : group == l.ankle ? kFootRange : group == l.chest ? kChestRange : nullptr;
    if (r != nullptr) {
      lo = r[0];
      hi = r[1];
    }
  }
  return {pose_name(phase, body, l, group), lo, hi, "rad"};
}

// With level_feet, the foot's world pitch in start, crouch and land is 0, not a parameter.
bool level_foot(int phase, const JumpControllerConfig& config) {
  return config.level_feet && (phase == kStart || phase == kCrouch || phase == kLand);
}

}  // namespace

void append_jump_gain_specs(int phase, std::vector<ParamSpec>& specs) {
  const std::string prefix = std::string(kPhaseNames[phase]) + ".";
  for (int j = 0; j < 3; ++j) {
    const double kp_hi = j == 2 ? 1500 : 2000;
    specs.push_back({prefix + "kp_" + kGainJoints[j], 50, kp_hi, "Nm/rad"});
    specs.push_back({prefix + "kd_" + kGainJoints[j], 2, 200, "Nm s/rad"});
  }
}

std::vector<std::string> jump_phase_names() { return {kPhaseNames, kPhaseNames + kNumJumpPhases}; }

const char* jump_phase_name(int phase) {
  return (phase >= 0 && phase < kNumJumpPhases) ? kPhaseNames[phase] : "?";
}

std::shared_ptr<const ControllerConfig> JumpControllerConfig::with_landing_height(double height) const {
  auto c = std::make_shared<JumpControllerConfig>(*this);
  c->landing_height_m = height;
  return c;
}

// ---------------------------------------------------------------------------------------
// The plug-in.

std::shared_ptr<const ControllerConfig> JumpControllerType::read_config(const TomlReader& r) const {
  r.only({"type", "landing_control", "landing_height", "extend_timeout", "tuck_time", "open_time", "open_rotation",
          "open_turn",
          "balance_kp",
          "balance_kd", "balance_max_force", "crouch_lean", "gravity_compensation", "stance_landing",
          "stand_after", "stand_duration", "level_feet", "landing_reach",
          "landing_at_touchdown"});
  auto c = std::make_shared<JumpControllerConfig>();
  c->landing_control = r.boolean("landing_control", c->landing_control);
  c->landing_height_m = r.number("landing_height", 0, 3, c->landing_height_m);
  c->extend_timeout = r.number("extend_timeout", 0.1, 3, c->extend_timeout);
  c->tuck_time = r.number("tuck_time", 0, 1, c->tuck_time);
  c->open_time = r.number("open_time", 0, 1, c->open_time);
  c->open_rotation = r.number("open_rotation", 0, 4 * M_PI, c->open_rotation);  // rad, like the task's rotation
  c->open_turn = r.number("open_turn", 0, 4 * M_PI, c->open_turn);  // rad
  c->balance_kp = r.number("balance_kp", 0, 10000, c->balance_kp);
  c->balance_kd = r.number("balance_kd", 0, 5000, c->balance_kd);
  c->balance_max_force = r.number("balance_max_force", 0, 5000, c->balance_max_force);
  c->crouch_lean = r.number("crouch_lean", 0, 1, c->crouch_lean);
  c->gravity_compensation = r.number("gravity_compensation", 0, 2, c->gravity_compensation);
  c->stance_landing = r.boolean("stance_landing", c->stance_landing);
  c->level_feet = r.boolean("level_feet", c->level_feet);
  c->landing_reach = r.number("landing_reach", 0, 1, c->landing_reach);
  c->landing_at_touchdown = r.boolean("landing_at_touchdown", c->landing_at_touchdown);
  c->stand_after = r.number("stand_after", -1, 5, c->stand_after);
  c->stand_duration = r.number("stand_duration", 0.05, 5, c->stand_duration);
  if (c->stand_after >= 0 && !c->stance_landing) r.fail("stand_after", "expected stance_landing = true with it");
  return c;
}

void JumpControllerType::check(const Character& body, const std::string& task_file) const {
  const std::string who = "the character " + body.spec->file;
  if (body.root != RootKind::kPlanar) {
    throw_field_error(task_file, "controller.type",
                      "expected a character with a planar root for \"jump2d\", but " + who + " has a free root");
  }
  for (JointRole role : {JointRole::kHip, JointRole::kKnee, JointRole::kAnkle}) {
    const int g = body.find_group(role);
    if (g < 0) {
      throw_field_error(task_file, "controller.type",
                        std::string("expected a joint group with role \"") + to_string(role) +
                            "\" for \"jump2d\", but " + who + " has none");
    }
    if (body.groups[static_cast<size_t>(g)].joints.size() != 2) {
      throw_field_error(task_file, "controller.type",
                        std::string("expected a left/right pair in the \"") + to_string(role) +
                            "\" group for \"jump2d\" (two legs), in " + who);
    }
  }
}

std::vector<ParamSpec> JumpControllerType::parameter_specs(const Character& body,
                                                           const ControllerConfig& config) const {
  const auto* c = dynamic_cast<const JumpControllerConfig*>(&config);
  if (c == nullptr) throw std::logic_error("jump2d: configuration of another controller");
  return JumpController::parameter_specs(body, *c);
}

std::unique_ptr<Controller> JumpControllerType::make(const Character& body, const ControllerConfig& config,
                                                     const std::vector<double>& values) const {
  const auto* c = dynamic_cast<const JumpControllerConfig*>(&config);
  if (c == nullptr) throw std::logic_error("jump2d: configuration of another controller");
  auto controller = std::make_unique<JumpController>(body, *c);
  controller->set_parameters(values);
  return controller;
}

// ---------------------------------------------------------------------------------------
// The controller.

std::vector<ParamSpec> JumpController::parameter_specs(const Character& body,
                                                       const JumpControllerConfig& config) {
  const Layout l = layout_of(body);
  std::vector<ParamSpec> specs;
  for (int p = 0; p < kNumJumpPhases; ++p) {
    for (int g : l.posed) {
      if (!(g == l.ankle && level_foot(p, config))) specs.push_back(pose_spec(p, body, l, g));
    }
    append_jump_gain_specs(p, specs);
  }
  specs.push_back({"start.duration", 0.05, 0.6, "s"});
  specs.push_back({"crouch.duration", 0.1, 1.0, "s"});
  specs.push_back({"land.duration", 0.05, 0.8, "s"});
  specs.push_back({"land.balance_offset", -0.1, 0.1, "m"});
  specs.push_back({"landing.offset", -0.4, 0.4, "m"});
  specs.push_back({"landing.velocity_gain", -0.4, 0.4, "s"});
  return specs;
}

JumpController::JumpController(const Character& body, const JumpControllerConfig& config)
    : body_(body), config_(config) {
  const Layout l = layout_of(body);
  hip_ = l.hip;
  knee_ = l.knee;
  ankle_ = l.ankle;
  chest_ = l.chest;
  posed_ = l.posed;
  pose_slot_.assign(body.groups.size(), -1);
  for (size_t k = 0; k < posed_.size(); ++k) pose_slot_[static_cast<size_t>(posed_[k])] = static_cast<int>(k);
  gain_slot_.assign(body.groups.size(), -1);
  gain_slot_[static_cast<size_t>(hip_)] = 0;
  gain_slot_[static_cast<size_t>(knee_)] = 1;
  gain_slot_[static_cast<size_t>(ankle_)] = 2;
  tracked_.assign(body.joints.size(), Tracked::kNone);
  side_.assign(body.joints.size(), 0);
  for (size_t i = 0; i < body.joints.size(); ++i) {
    const int g = body.joints[i].group;
    if (g == hip_) tracked_[i] = Tracked::kParent;
    if (g == ankle_ || g == chest_) tracked_[i] = Tracked::kChild;
    side_[i] = body.joints[i].side == Side::kRight ? 1 : 0;
  }
  auto distance = [&](int a, int b) {
    const auto& p = body.joints[static_cast<size_t>(a)].anchor0;
    const auto& q = body.joints[static_cast<size_t>(b)].anchor0;
    return std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
  };
  const int hip0 = body.groups[static_cast<size_t>(hip_)].joints[0];
  const int knee0 = body.groups[static_cast<size_t>(knee_)].joints[0];
  const int ankle0 = body.groups[static_cast<size_t>(ankle_)].joints[0];
  thigh_length_ = distance(hip0, knee0);
  shin_length_ = distance(knee0, ankle0);
  for (auto& p : pose_) p.assign(posed_.size(), 0.0);
  from_.assign(body.joints.size(), 0.0);
  target_.assign(body.joints.size(), 0.0);
  balance_.assign(body.joints.size(), 0.0);
  times_.names = jump_phase_names();
  times_.begin.assign(kNumJumpPhases, -1.0);
  times_.extend = kExtend;
  times_.rise = kRise;
  times_.fall = kFall;
  times_.land = kLand;
}

void JumpController::set_parameters(const std::vector<double>& values) {
  // Per phase a target per posed group (but the level feet) and kp, kd of hip, knee,
  // ankle; then six more.
  size_t count = kNumJumpPhases * (posed_.size() + 6) + 6;
  for (int p = 0; p < kNumJumpPhases; ++p) count -= level_foot(p, config_) ? 1 : 0;
  if (values.size() != count) throw std::logic_error("JumpController: parameter count");
  size_t k = 0;
  for (int p = 0; p < kNumJumpPhases; ++p) {
    pose_[p].assign(posed_.size(), 0.0);  // a level foot: world pitch 0
    for (size_t g = 0; g < posed_.size(); ++g) {
      if (!(posed_[g] == ankle_ && level_foot(p, config_))) pose_[p][g] = values[k++];
    }
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

void JumpController::reset(const mjModel* m, const mjData* d) {
  com_velocity_ = SubtreeComVelocity(m, body_.root_body);
  if (config_.open_turn > 0) centroidal_ = CentroidalPitchOf(m, body_.root_body);
  q_ = d->qpos;
  from_is_world_ = true;  // start is a stance phase
  for (size_t i = 0; i < body_.joints.size(); ++i) {
    target_[i] = d->qpos[body_.joints[i].qpos];
    from_[i] = to_world(static_cast<int>(i), q_, target_[i]);
  }
  gravity_ = -m->opt.gravity[2];
  std::fill(times_.begin.begin(), times_.begin.end(), -1.0);
  extend_timed_out_ = false;
  phase_ = kStart;
  phase_begin_ = d->time;
  phase_duration_ = start_duration_;
  times_.begin[kStart] = d->time;
  takeoff_com_z_ = 0;
  free_since_ = -1;
  if (config_.stance_landing) stance_ = std::make_unique<StanceController>(body_, m);
  // Standing: the COM's height above the floor, and how far ahead of the ankle each sole's
  // middle (the foot's centre of mass) lies.
  standing_com_z_ = d->subtree_com[3 * body_.root_body + 2];
  sole_ahead_ = 0;
  for (int f : body_.feet) sole_ahead_ += 0.5 * (d->xipos[3 * f] - d->xpos[3 * f]);
}

void JumpController::enter(int phase, double time) {
  phase_ = phase;
  phase_begin_ = time;
  phase_changed_ = true;
  times_.begin[static_cast<size_t>(phase)] = time;
  from_ = target_;
  from_is_world_ = is_stance(phase);
  if (from_is_world_) {
    // World-frame joints interpolate in world pitch: start from the pitch that the last
    // commanded joint target implies for the tracked link in the current pose.
    for (size_t i = 0; i < body_.joints.size(); ++i) from_[i] = to_world(static_cast<int>(i), q_, target_[i]);
  }
  switch (phase) {
    case kCrouch: phase_duration_ = crouch_duration_; break;
    case kExtend: phase_duration_ = 1e-9; break;
    case kRise:
      takeoff_com_z_ = com_[2];
      takeoff_pitch_ = q_[body_.root_pitch_qpos];
      phase_duration_ = std::max(com_vel_[2], 0.05) / gravity_;
      if (config_.tuck_time > 0) phase_duration_ = std::min(phase_duration_, config_.tuck_time);
      break;
    case kFall:
      if (config_.open_rotation > 0 || config_.open_turn > 0) {
        // Possibly past the peak: the time back to take-off height from here.
        const double down = std::max(-com_vel_[2], 0.0);
        const double above = std::max(com_[2] - takeoff_com_z_, 0.01);
        phase_duration_ = (std::sqrt(down * down + 2 * gravity_ * above) - down) / gravity_;
      } else {
        phase_duration_ = std::sqrt(2 * std::max(com_[2] - takeoff_com_z_, 0.01) / gravity_);
      }
      if (config_.open_time > 0) phase_duration_ = std::min(phase_duration_, config_.open_time);
      break;
    case kLand: phase_duration_ = land_duration_; break;
    default: phase_duration_ = start_duration_; break;
  }
}

// stance_landing, at touch-down: the world pitches to move from (as the stance controller
// measures them) and to (the land pose's pelvis, chest and foot values), and the gains.
void JumpController::enter_stance_landing(const mjData* d) {
  const StanceController::Pitches p = stance_->measured_pitches(d);
  land_from_ = {p.root, p.torso, p.foot};
  const auto& pose = pose_[kLand];
  const double root = pose[static_cast<size_t>(pose_slot_[static_cast<size_t>(hip_)])];
  const double torso = chest_ >= 0 ? pose[static_cast<size_t>(pose_slot_[static_cast<size_t>(chest_)])] : root;
  land_goal_ = {root, torso, pose[static_cast<size_t>(pose_slot_[static_cast<size_t>(ankle_)])]};
  // The land phase's gains for the knees and the feet's world tracking, the character's
  // for the rest; the root (which the stance hips hold) keeps the stance controller's own
  // gains, 2 M g h0 (the land phase's hip gains made the landing chatter).
  for (size_t i = 0; i < body_.joints.size(); ++i) {
    const JointGroup& g = body_.groups[static_cast<size_t>(body_.joints[i].group)];
    const int gs = gain_slot_[static_cast<size_t>(body_.joints[i].group)];
    // The strength model scales every joint's PD gains (Character::strength).
    const double kp = gs >= 0 ? kp_[kLand][static_cast<size_t>(gs)] : g.kp;
    const double kd = gs >= 0 ? kd_[kLand][static_cast<size_t>(gs)] : g.kd;
    stance_->set_joint_gains(static_cast<int>(i), body_.strength * kp, body_.strength * kd);
  }
  const double h = stance_->heading();
  stance_->set_com_offset(balance_offset_ * std::cos(h), balance_offset_ * std::sin(h));
  stance_->set_com_velocity(0, 0);
  stance_->set_com_force(StanceController::ComForce::kSupport);
}

// stance_landing, every step of the land phase: the pitches and the other joints' targets
// a fraction s of the way to the land pose, then stance control.
void JumpController::control_stance_landing(const mjModel* m, const mjData* d, JointDrive& drive, double s) {
  // stand_after: a fraction u of the way on from the land pose to standing (the tracked
  // links level, every other joint at the model's qpos0).
  double u = 0;
  if (config_.stand_after >= 0) {
    u = std::clamp((d->time - phase_begin_ - land_duration_ - config_.stand_after) / config_.stand_duration, 0.0, 1.0);
  }
  auto at = [&](int k) {
    const double pitch = land_from_[static_cast<size_t>(k)] + s * (land_goal_[static_cast<size_t>(k)] - land_from_[static_cast<size_t>(k)]);
    return (1 - u) * pitch;
  };
  stance_->set_pitches(at(0), at(1), at(2));
  if (u > 0) {
    for (size_t i = 0; i < target_.size(); ++i) target_[i] += u * (m->qpos0[body_.joints[i].qpos] - target_[i]);
  }
  stance_->set_targets(target_);
  stance_->control(m, d, drive);
}

// World pitch (rad) of joint j's parent link.
double JumpController::parent_pitch(int j, const double* q) const {
  return body_.child_pitch(q, j) - q[body_.joints[static_cast<size_t>(j)].qpos];
}

// Joint target (rad) that makes joint j's tracked link reach world pitch `world`, for
// the world-frame joints of stance phases; other joints pass through.
double JumpController::to_local(int j, const double* q, double world) const {
  const CharacterJoint& joint = body_.joints[static_cast<size_t>(j)];
  switch (tracked_[static_cast<size_t>(j)]) {
    case Tracked::kParent:  // the pelvis: turning the hip turns the parent the other way
      return q[joint.qpos] + wrap(parent_pitch(j, q) - world);
    case Tracked::kChild:  // the foot, the chest
      return wrap(world - parent_pitch(j, q));
    default:
      return world;
  }
}

// Inverse of to_local: the world pitch a joint target implies in the current pose.
double JumpController::to_world(int j, const double* q, double local) const {
  const CharacterJoint& joint = body_.joints[static_cast<size_t>(j)];
  switch (tracked_[static_cast<size_t>(j)]) {
    case Tracked::kParent: return parent_pitch(j, q) - (local - q[joint.qpos]);
    case Tracked::kChild: return local + parent_pitch(j, q);
    default: return local;
  }
}

double JumpController::landing_hip_goal(int j, const mjData* d) const {
  const CharacterJoint& hip = body_.joints[static_cast<size_t>(j)];
  const int side = side_[static_cast<size_t>(j)];
  // The paper's: where the COM crosses the landing surface on its ballistic path.
  // landing_at_touchdown: where the COM will be when it has come down to its standing
  // height above the surface (about when the feet touch), less the sole's middle's lead
  // over the ankle, so that with offset and gain 0 the COM comes down over the soles.
  const double above = config_.landing_at_touchdown ? standing_com_z_ : 0.0;
  const double z = std::max(com_[2] - config_.landing_height_m - above, 0.0);
  const double vz = com_vel_[2];
  const double t_cross = (vz + std::sqrt(vz * vz + 2 * gravity_ * z)) / gravity_;
  const double sole = config_.landing_at_touchdown ? sole_ahead_ : 0.0;
  const double x_target = com_[0] + com_vel_[0] * t_cross - sole + landing_offset_ +
                          landing_velocity_gain_ * com_vel_[0];
  const double dx = x_target - d->xanchor[3 * hip.joint];
  // Two-link leg: ankle x offset = l1 sin(th) + l2 sin(th + qk) = R sin(th + psi).
  const int knee = body_.groups[static_cast<size_t>(knee_)].joints[static_cast<size_t>(side)];
  const double qk = target_[static_cast<size_t>(knee)];
  const double a = thigh_length_ + shin_length_ * std::cos(qk);
  const double b = shin_length_ * std::sin(qk);
  const double thigh = std::asin(std::clamp(dx / std::hypot(a, b), -0.9, 0.9)) - std::atan2(b, a);
  return wrap(thigh - parent_pitch(j, d->qpos));
}

// open_turn, in the rise past the peak: would the body as a whole, opened now, have turned
// as far as asked in the air by touch-down (or is touch-down no more than open_time away)?
// `now` is the body's spin in this step.
bool JumpController::time_to_open(const CentroidalPitch& now) const {
  const double vz = com_vel_[2];
  const double above = std::max(com_[2] - takeoff_com_z_, 0.0);
  const double t_down = (vz + std::sqrt(vz * vz + 2 * gravity_ * above)) / gravity_;
  if (t_down <= config_.open_time || now.inertia <= 0 || takeoff_inertia_ <= 0) return true;
  // Opening over open_time, the inertia going from the tuck's to the open body's (the
  // mean of the two rates), then open until touch-down.
  const double opening = config_.open_time;
  const double turn = now.momentum * (0.5 * opening * (1 / now.inertia + 1 / takeoff_inertia_) +
                                      (t_down - opening) / takeoff_inertia_);
  return flight_turn_ + turn >= config_.open_turn;
}

void JumpController::control(const mjModel* m, mjData* d, const ContactState& contacts, JointDrive& drive) {
  const double t = d->time;
  const double* q = d->qpos;
  q_ = q;
  const int root = body_.root_body;
  for (int k = 0; k < 3; ++k) com_[static_cast<size_t>(k)] = d->subtree_com[3 * root + k];
  com_vel_ = com_velocity_(m, d);

  // Transitions: at most one per step.
  phase_changed_ = false;
  const double elapsed = t - phase_begin_;
  switch (phase_) {
    case kStart:
      if (elapsed >= start_duration_) enter(kCrouch, t);
      break;
    case kCrouch:
      if (elapsed >= crouch_duration_) enter(kExtend, t);
      break;
    case kExtend:
      // Airborne: no contact for airborne_time with the COM rising (soft contacts can
      // flicker for a step while the legs push).
      if (contacts.any) free_since_ = -1;
      else if (free_since_ < 0) free_since_ = t;
      if (free_since_ >= 0 && t - free_since_ >= config_.airborne_time - 1e-9 && com_vel_[2] > 0) {
        if (config_.open_turn > 0) {
          takeoff_inertia_ = centroidal_(m, d, com_.data(), com_vel_.data()).inertia;
          flight_turn_ = 0;
          spin_time_ = t;
        }
        enter(kRise, t);
      } else if (elapsed >= config_.extend_timeout) {
        extend_timed_out_ = true;
        enter(kLand, t);
      }
      break;
    case kRise:
      if (config_.open_turn > 0) {  // the body's turn since take-off: its mean rate, integrated
        spin_ = centroidal_(m, d, com_.data(), com_vel_.data());
        flight_turn_ += spin_.rate() * (t - spin_time_);
        spin_time_ = t;
      }
      if (contacts.any) {
        // Touched down while still rising (a low, flat jump): the peak and the landing
        // coincide, a zero-length fall, so every jump has both airborne phases.
        times_.begin[kFall] = t;
        enter(kLand, t);
      } else if (com_vel_[2] <= 0 &&
                 std::fabs(q[body_.root_pitch_qpos] - takeoff_pitch_) >= config_.open_rotation &&
                 (config_.open_turn <= 0 || time_to_open(spin_))) {
        enter(kFall, t);
      }
      break;
    case kFall:
      if (contacts.any) enter(kLand, t);
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
    const int group = body_.joints[i].group;
    if (landing && group == hip_) continue;  // needs this step's knee targets
    const int slot = pose_slot_[static_cast<size_t>(group)];
    const double goal = slot >= 0 ? pose_[static_cast<size_t>(phase_)][static_cast<size_t>(slot)] : 0.0;
    if (from_is_world_) {
      // Interpolate the world pitch along the shorter way round, then turn it into a
      // joint target for the current pose.
      const bool world = tracked_[i] != Tracked::kNone;
      const double step = world ? wrap(goal - from_[i]) : goal - from_[i];
      target_[i] = to_local(static_cast<int>(i), q, from_[i] + s * step);
    } else {
      target_[i] = from_[i] + s * (goal - from_[i]);
    }
  }
  if (landing) {
    const double pelvis = q[body_.root_pitch_qpos];
    const double w = std::clamp((std::cos(pelvis) - 0.5) / 0.5, 0.0, 1.0);
    const double pose_hip = pose_[kFall][static_cast<size_t>(pose_slot_[static_cast<size_t>(hip_)])];
    for (int i : body_.groups[static_cast<size_t>(hip_)].joints) {
      double goal = pose_hip;
      if (w > 0) goal = (1 - w) * goal + w * landing_hip_goal(i, d);
      // How far along from the peak's hip angle to the goal (landing_reach: reached early).
      const double along = config_.landing_reach > 0 ? std::min(1.0, (t - phase_begin_) / config_.landing_reach) : s;
      target_[static_cast<size_t>(i)] = from_[static_cast<size_t>(i)] + along * (goal - from_[static_cast<size_t>(i)]);
    }
  }

  if (stance_ && phase_ == kLand) {
    if (phase_changed_) {
      stance_->reset(m, d);  // the heading and footing it landed with
      enter_stance_landing(d);
    }
    control_stance_landing(m, d, drive, s);
    return;
  }

  // Balance: tau = J^T F on the stance legs.
  std::fill(balance_.begin(), balance_.end(), 0.0);
  if (has_balance(phase_) && contacts.any) {
    const int* feet = body_.feet.data();
    const double support = 0.5 * (d->xipos[3 * feet[0]] + d->xipos[3 * feet[1]]);
    double target = support + balance_offset_, speed = 0;
    if (phase_ == kCrouch && config_.crouch_lean > 0) {  // lead the COM along the lean
      const double duration = std::max(crouch_duration_, 1e-6);
      target += std::clamp((t - phase_begin_) / duration, 0.0, 1.0) * config_.crouch_lean;
      speed = config_.crouch_lean / duration;
    }
    const double fx = std::clamp(config_.balance_kp * (target - com_[0]) + config_.balance_kd * (speed - com_vel_[0]),
                                 -config_.balance_max_force, config_.balance_max_force);
    const double fz = config_.gravity_compensation * body_.total_mass * gravity_;
    for (int group : {ankle_, knee_, hip_}) {
      for (int i : body_.groups[static_cast<size_t>(group)].joints) {
        const double* p = d->xanchor + 3 * body_.joints[static_cast<size_t>(i)].joint;
        const double rx = com_[0] - p[0], rz = com_[2] - p[2];
        balance_[static_cast<size_t>(i)] = -0.5 * (rx * fz - rz * fx);
      }
    }
  }

  // PD torques. The drive takes u (all but the damping) and kd, and applies
  // u - kd qdot within the joint's limit. World-frame joints of stance phases damp the
  // tracked link's world pitch rate: -kd qdot (the drive's damping) plus kd times the rate
  // of the link on the other side of the joint, with the sign that makes the sum the
  // tracked link's rate.
  const bool stance = is_stance(phase_);
  const double* v = d->qvel;
  for (size_t i = 0; i < body_.joints.size(); ++i) {
    const CharacterJoint& j = body_.joints[i];
    const JointGroup& group = body_.groups[static_cast<size_t>(j.group)];
    const int gs = gain_slot_[static_cast<size_t>(j.group)];
    // The strength model scales every joint's PD gains (Character::strength).
    const double kp = body_.strength * (gs >= 0 ? kp_[static_cast<size_t>(phase_)][static_cast<size_t>(gs)] : group.kp);
    const double kd = body_.strength * (gs >= 0 ? kd_[static_cast<size_t>(phase_)][static_cast<size_t>(gs)] : group.kd);
    if (stance && tracked_[i] != Tracked::kNone && drive.damping() == Damping::kConstrained) {
      // The drive damps the tracked link's world pitch rate itself: root pitch rate plus
      // the joint rates down the chain to the child; the parent's is that less qdot.
      damped_.clear();
      const double sign = tracked_[i] == Tracked::kParent ? -1.0 : 1.0;
      damped_.push_back({body_.root_pitch_dof, sign});
      for (int k : body_.chain(static_cast<int>(i)))
        damped_.push_back({body_.joints[static_cast<size_t>(k)].dof, sign});
      if (tracked_[i] == Tracked::kParent) damped_.push_back({j.dof, 1.0});
      drive.set(static_cast<int>(i), kp * (target_[i] - q[j.qpos]) + balance_[i], kd, damped_);
      continue;
    }
    double world_damping = 0;
    if (stance && tracked_[i] != Tracked::kNone) {
      const double child_rate = body_.child_pitch_rate(v, static_cast<int>(i));
      if (tracked_[i] == Tracked::kParent) {  // parent rate = child rate - qdot
        world_damping = kd * child_rate;
      } else {  // child rate = qdot + parent rate
        world_damping = -kd * (child_rate - v[j.dof]);
      }
    }
    const double u = kp * (target_[i] - q[j.qpos]) + world_damping + balance_[i];
    drive.set(static_cast<int>(i), u, kd);
  }
}

}  // namespace diverse
