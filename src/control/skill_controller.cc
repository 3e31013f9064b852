#include "control/skill_controller.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "control/module_aim_legs.h"
#include "control/module_balance.h"
#include "control/module_foot_placement.h"
#include "control/module_gravity_compensation.h"
#include "control/module_root_damping.h"
#include "control/module_linear_feedback.h"
#include "control/module_simbicon.h"
#include "control/module_spotting.h"
#include "control/module_stance.h"
#include "control/module_stance3d.h"
#include "control/module_stance_hip.h"
#include "control/module_stance_support.h"
#include "core/error.h"
#include "core/toml_reader.h"
#include "physics/model.h"

namespace diverse {

namespace {
double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
}  // namespace

double skill_wrap(double a) { return std::fabs(a) <= M_PI ? a : std::remainder(a, 2 * M_PI); }

double skill_parent_pitch(const Character& body, int j, const double* q) {
  return body.child_pitch(q, j) - q[body.joints[static_cast<size_t>(j)].qpos];
}

// ---------------------------------------------------------------------------------------
// The configuration and the plug-in.

std::shared_ptr<const ControllerConfig> SkillConfig::with_landing_height(double height) const {
  auto c = std::make_shared<SkillConfig>();
  c->skill = skill;
  c->landing_height_m = height;
  return c;
}

std::shared_ptr<const SkillBinding> SkillConfig::binding(const Character& body) const {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [spec, b] : bindings_)
    if (spec == body.spec.get()) return b;
  // A skill that names bodies is checked against the character's own model.
  bool bodies = false;
  for (const SkillPhase& p : skill->phases)
    for (const SkillTransition& tr : p.next)
      for (const SkillCondition& c : tr.on) bodies = bodies || !c.body.empty();
  mjModel* m = nullptr;
  if (bodies) {
    char error[1000] = "";
    m = mj_loadXML(body.spec->model.c_str(), nullptr, error, sizeof(error));
    if (m == nullptr) throw UserError(body.spec->model + ": expected a model MuJoCo loads (" + error + ")");
  }
  std::shared_ptr<const SkillBinding> b;
  try {
    b = std::make_shared<const SkillBinding>(bind_skill(*skill, body, m));
  } catch (...) {
    if (m != nullptr) mj_deleteModel(m);
    throw;
  }
  if (m != nullptr) mj_deleteModel(m);
  bindings_.emplace_back(body.spec.get(), b);
  return b;
}

std::shared_ptr<const ControllerConfig> SkillControllerType::read_config(const TomlReader& r) const {
  const std::string relative = r.string("skill");
  std::filesystem::path path(relative);
  if (path.is_relative()) path = std::filesystem::path(r.file()).parent_path() / path;
  const std::string file = path.lexically_normal().string();
  if (!std::filesystem::is_regular_file(file)) {
    r.fail("skill", "expected an existing skill file (relative to the task file), but " + file + " does not exist");
  }
  auto skill = std::make_shared<SkillFile>(load_skill_file(file));
  override_skill_settings(*skill, r, {"type", "skill", "landing_height"});
  auto c = std::make_shared<SkillConfig>();
  c->skill = skill;
  c->landing_height_m = r.number("landing_height", 0, 3, 0);
  return c;
}

const char* SkillControllerType::skill(const ControllerConfig& config) const {
  const auto* c = dynamic_cast<const SkillConfig*>(&config);
  return c != nullptr && c->skill->walk ? "walk" : "jump";
}

void SkillControllerType::check(const Character& body, const std::string& task_file) const {
  (void)body;
  (void)task_file;  // the skill is checked with the task's configuration, below
}

void SkillControllerType::check(const Character& body, const ControllerConfig& config, const std::string& task_file) const {
  (void)task_file;  // bind_skill's errors name the skill file's line
  const auto* c = dynamic_cast<const SkillConfig*>(&config);
  if (c == nullptr) throw std::logic_error("skill: configuration of another controller");
  (void)c->binding(body);
}

std::vector<ParamSpec> SkillControllerType::parameter_specs(const Character& body, const ControllerConfig& config) const {
  const auto* c = dynamic_cast<const SkillConfig*>(&config);
  if (c == nullptr) throw std::logic_error("skill: configuration of another controller");
  return c->binding(body)->params;
}

std::unique_ptr<Controller> SkillControllerType::make(const Character& body, const ControllerConfig& config,
                                                      const std::vector<double>& values) const {
  const auto* c = dynamic_cast<const SkillConfig*>(&config);
  if (c == nullptr) throw std::logic_error("skill: configuration of another controller");
  return std::make_unique<SkillController>(body, *c, c->binding(body), values);
}

// ---------------------------------------------------------------------------------------
// The engine.

SkillController::SkillController(const Character& body, const SkillConfig& config,
                                 std::shared_ptr<const SkillBinding> binding, const std::vector<double>& values)
    : body_(body), skill_(config.skill), binding_(std::move(binding)), values_(values) {
  if (values_.size() != binding_->params.size()) throw std::logic_error("SkillController: parameter count");
  for (size_t k = 0; k < skill_->modules.size(); ++k) {
    const ModuleSettings settings(skill_->modules[k], binding_->module_params[k], values_);
    modules_.push_back(make_skill_module(skill_->modules[k], settings, body));
  }
  takeoff_ = skill_->phase_index(skill_->takeoff);
  state_.body = &body_;
  state_.landing_height = config.landing_height_m;
  const size_t n = body.joints.size();
  state_.target.assign(n, 0.0);
  state_.from.assign(n, 0.0);
  state_.goal.assign(n, 0.0);
  state_.kp.assign(n, 0.0);
  state_.kd.assign(n, 0.0);
  state_.feedforward.assign(n, 0.0);
  state_.hold.assign(n, 0.0);
  qpos0_.assign(n, 0.0);
  for (const SkillPhase& p : skill_->phases) times_.names.push_back(p.name);
  // Per phase, found once: whether it waits for a lift-off, and which joints' targets its
  // modules write.
  for (size_t p = 0; p < skill_->phases.size(); ++p) {
    bool liftoff = false;
    for (const SkillTransition& tr : skill_->phases[p].next)
      for (const SkillCondition& c : tr.on) liftoff = liftoff || c.type == SkillCondition::Type::kLiftoff;
    liftoff_.push_back(liftoff ? 1 : 0);
    std::vector<char> owned(n, 0);
    for (size_t i = 0; i < n; ++i)
      for (int k : binding_->phases[p].modules) owned[i] = owned[i] || modules_[static_cast<size_t>(k)]->owns_target(static_cast<int>(i));
    owned_.push_back(owned);
  }
  times_.begin.assign(skill_->phases.size(), -1.0);
  times_.extend = skill_->phase_index(skill_->push);
  times_.rise = takeoff_;
  times_.fall = skill_->phase_index(skill_->peak);
  times_.land = skill_->phase_index(skill_->landing);
  state_.u.assign(n, 0.0);
  state_.damping.assign(n, 0.0);
  preset_.assign(n, 0);
  for (const SkillPhaseBinding& pb : binding_->phases) {
    heading_frame_ = heading_frame_ || pb.root;
    for (const SkillJointTarget& t : pb.targets) heading_frame_ = heading_frame_ || t.world == SkillTarget::World::kHeading;
  }
}

void SkillController::prepare(const mjModel* m) {
  if (prepared_ || !heading_frame_) return;
  prepared_ = true;
  standing_ = standing_frames(m, body_.root_body);
  state_.standing = &standing_;
  links_.assign(static_cast<size_t>(m->nbody), HeadingLink{});
  for (const CharacterJoint& j : body_.joints) {
    HeadingLink& link = links_[static_cast<size_t>(j.body)];
    if (link.body < 0) link = heading_link(body_, m, standing_, j.body);
  }
  link_done_.assign(static_cast<size_t>(m->nbody), 0);
  link_error_.assign(static_cast<size_t>(m->nbody), {0, 0, 0});
}

void SkillController::link_target(int b, double* quat) const {
  const HeadingLink& link = links_[static_cast<size_t>(b)];
  double angles[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  for (size_t i = 0; i < link.joints.size() && i < 8; ++i) angles[i] = state_.target[static_cast<size_t>(link.joints[i])];
  heading_link_target(link, state_.heading, angles, quat);
}

bool SkillController::start_state(const mjModel* m, mjData* d) {
  if (!skill_->start_pose) return false;
  prepare(m);
  const SkillPhaseBinding& pb = binding_->phases[0];
  load_goals(pb);
  state_.heading = 0;
  const int stance = pb.swing >= 0 ? 1 - pb.swing : -1;
  mju_copy(d->qpos, m->qpos0, m->nq);
  mju_zero(d->qvel, m->nv);
  if (pb.root) heading_root_target(standing_, 0, state_.root_pitch, state_.root_roll, d->qpos + body_.root_qpos + 3);
  const size_t n = body_.joints.size();
  for (size_t i = 0; i < n; ++i) {
    state_.target[i] = state_.goal[i];
    if (pb.targets[i].world == SkillTarget::World::kJoint) d->qpos[body_.joints[i].qpos] = state_.goal[i];
  }
  // The links at their targets (the stance foot at its standing orientation), by
  // fixed-point iteration on the hinge angles, each turned by the error's component along
  // its axis.
  std::vector<std::pair<const HeadingLink*, std::vector<double>>> goals;
  for (const HeadingLink& link : links_) {
    if (link.body < 0) continue;
    const bool stance_foot = stance >= 0 && link.body == body_.feet[static_cast<size_t>(stance)];
    bool tracked = false;
    for (int k : link.joints) tracked = tracked || pb.targets[static_cast<size_t>(k)].world == SkillTarget::World::kHeading;
    if (!tracked && !stance_foot) continue;
    std::vector<double> angles(link.joints.size(), 0.0);
    if (!stance_foot) {
      for (size_t i = 0; i < link.joints.size(); ++i) angles[i] = state_.goal[static_cast<size_t>(link.joints[i])];
    }
    goals.emplace_back(&link, angles);
  }
  for (int it = 0; it < 50; ++it) {
    mj_kinematics(m, d);
    double worst = 0;
    for (const auto& [link, angles] : goals) {
      double target[4], e[3];
      heading_link_target(*link, 0, angles.data(), target);
      rotation_error(target, d->xquat + 4 * link->body, e);
      worst = std::max(worst, mju_norm3(e));
      for (int k : link->joints) {
        const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
        double& q = d->qpos[j.qpos];
        q += dot3(d->xaxis + 3 * j.joint, e);
        if (std::isfinite(j.lower)) q = std::clamp(q, j.lower, j.upper);
      }
    }
    if (worst < 1e-10) break;
  }
  // The stance sole (or, without a swing leg, both) on the floor, the root above the origin.
  mj_kinematics(m, d);
  double lowest = INFINITY;
  for (int g = 0; g < m->ngeom; ++g) {
    int side = -1;
    if (m->geom_bodyid[g] == 0 || !body_.is_foot_geom(m, g, &side) || (stance >= 0 && side != stance)) continue;
    double lo = 0, hi = 0;
    geom_z_extent(m, d, g, &lo, &hi);
    lowest = std::min(lowest, lo);
  }
  if (std::isfinite(lowest)) d->qpos[body_.root_qpos + 2] -= lowest;
  d->qpos[body_.root_qpos] = 0;
  d->qpos[body_.root_qpos + 1] = 0;
  mj_kinematics(m, d);
  return true;
}

SkillTarget::World SkillController::world(size_t j) const {
  return binding_->phases[static_cast<size_t>(state_.phase)].targets[j].world;
}

// Joint target (rad) that makes joint j's tracked link reach world pitch `world_pitch`.
double SkillController::to_local(size_t j, const double* q, double world_pitch) const {
  const int k = static_cast<int>(j);
  switch (world(j)) {
    case SkillTarget::World::kParent:  // turning the joint turns the parent the other way
      return q[body_.joints[j].qpos] + skill_wrap(skill_parent_pitch(body_, k, q) - world_pitch);
    case SkillTarget::World::kChild:
      return skill_wrap(world_pitch - skill_parent_pitch(body_, k, q));
    default:
      return world_pitch;
  }
}

// Inverse of to_local: the world pitch a joint target implies in the current pose.
double SkillController::to_world(size_t j, const double* q, double local) const {
  const int k = static_cast<int>(j);
  switch (world(j)) {
    case SkillTarget::World::kParent: return skill_parent_pitch(body_, k, q) - (local - q[body_.joints[j].qpos]);
    case SkillTarget::World::kChild: return local + skill_parent_pitch(body_, k, q);
    default: return local;
  }
}

// A phase's duration (s) as it begins, from its value or predicted from the flight.
double SkillController::duration_of(int phase) const {
  const SkillPhase& p = skill_->phases[static_cast<size_t>(phase)];
  const SkillDuration& d = p.duration;
  const double g = state_.gravity;
  double t = 1e-9;
  if (d.kind == SkillDuration::Kind::kValue) {
    const int param = binding_->phases[static_cast<size_t>(phase)].duration_param;
    t = param >= 0 ? values_[static_cast<size_t>(param)] : d.value.number;
  } else if (d.kind == SkillDuration::Kind::kPredict) {
    const double z = state_.com[2], vz = state_.com_vel[2];
    if (d.predict == "rise") {  // to the peak
      t = std::max(vz, 0.05) / g;
    } else if (d.predict == "fall") {  // from the peak back to take-off height
      t = std::sqrt(2 * std::max(z - state_.takeoff_com_z, 0.01) / g);
    } else {  // from here, possibly past the peak, back to take-off height
      const double down = std::max(-vz, 0.0);
      const double above = std::max(z - state_.takeoff_com_z, 0.01);
      t = (std::sqrt(down * down + 2 * g * above) - down) / g;
    }
    if (d.at_most > 0) t = std::min(t, d.at_most);
  }
  return t;
}

void SkillController::reset(const mjModel* m, const mjData* d) {
  prepare(m);
  com_velocity_ = SubtreeComVelocity(m, body_.root_body);
  state_.gravity = -m->opt.gravity[2];
  state_.time = d->time;
  state_.qpos = d->qpos;
  for (int k = 0; k < 3; ++k) state_.com[static_cast<size_t>(k)] = d->subtree_com[3 * body_.root_body + k];
  state_.takeoff_com_z = 0;
  std::fill(times_.begin.begin(), times_.begin.end(), -1.0);
  gave_up_ = false;
  free_since_ = -1;
  takeoff_pitch_ = 0;
  for (size_t i = 0; i < body_.joints.size(); ++i) qpos0_[i] = m->qpos0[body_.joints[i].qpos];
  for (auto& module : modules_) module->reset(m, d, state_);
  // Resolve named bodies once.
  bodies_.clear();
  for (const SkillPhase& p : skill_->phases)
    for (const SkillTransition& tr : p.next)
      for (const SkillCondition& c : tr.on)
        if (!c.body.empty()) bodies_.emplace_back(&c, mj_name2id(m, mjOBJ_BODY, c.body.c_str()));
  // The first phase starts from the pose in d.
  state_.phase = 0;
  for (size_t i = 0; i < body_.joints.size(); ++i) {
    state_.target[i] = d->qpos[body_.joints[i].qpos];
    state_.hold[i] = state_.target[i];
    state_.from[i] = to_world(i, d->qpos, state_.target[i]);
  }
  state_.from_pose = true;
  const SkillPhaseBinding& pb = binding_->phases[0];
  state_.targets = &pb.targets;
  load_goals(pb);
  state_.phase_begin = d->time;
  state_.phase_duration = duration_of(0);
  state_.phase_changed = false;
  times_.begin[0] = d->time;
  for (int k : pb.modules) modules_[static_cast<size_t>(k)]->enter(m, d, state_);
}

// A phase's goal targets and gains: its numbers, or the motion's values of its parameters.
void SkillController::load_goals(const SkillPhaseBinding& pb) {
  auto value = [&](const SkillJointTarget& t) {
    const double v = t.param >= 0 ? values_[static_cast<size_t>(t.param)] : t.value->number;
    return t.sign == 1 ? v : t.sign * v;
  };
  state_.swing = pb.swing;
  state_.root = pb.root;
  if (pb.root) {
    state_.root_pitch = value(pb.root_pitch);
    state_.root_roll = value(pb.root_roll);
  }
  for (size_t i = 0; i < body_.joints.size(); ++i) {
    const SkillJointTarget& t = pb.targets[i];
    state_.goal[i] = value(t);
    if (t.value->kind == SkillValue::Kind::kStanding) state_.goal[i] = qpos0_[i];
    if (t.from_standing) {
      const CharacterJoint& j = body_.joints[i];
      state_.goal[i] += qpos0_[i];
      if (std::isfinite(j.lower) && std::isfinite(j.upper)) state_.goal[i] = std::clamp(state_.goal[i], j.lower, j.upper);
    }
    const SkillJointGain& g = pb.gains[i];
    state_.kp[i] = g.kp_param >= 0 ? values_[static_cast<size_t>(g.kp_param)] : g.kp;
    state_.kd[i] = g.kd_param >= 0 ? values_[static_cast<size_t>(g.kd_param)] : g.kd;
  }
}

void SkillController::enter(int phase, const mjModel* m, const mjData* d) {
  const double t = state_.time;
  const double* q = state_.qpos;
  state_.phase = phase;
  state_.phase_begin = t;
  state_.phase_changed = true;
  times_.begin[static_cast<size_t>(phase)] = t;
  // The phase's targets start from those last commanded (world-frame ones from the pitch
  // the last joint target implies for the tracked link in the current pose), from the
  // previous phase's goals, from the pose now, or at its own goals.
  const SkillPhase::From from = skill_->phases[static_cast<size_t>(phase)].from;
  state_.from_pose = from == SkillPhase::From::kPose;
  const size_t n = body_.joints.size();
  if (from == SkillPhase::From::kGoals) {
    state_.from = state_.goal;
  } else if (from == SkillPhase::From::kPose) {
    for (size_t i = 0; i < n; ++i) {
      state_.hold[i] = q[body_.joints[i].qpos];
      state_.from[i] = to_world(i, q, state_.hold[i]);
    }
  } else {
    for (size_t i = 0; i < n; ++i) state_.from[i] = to_world(i, q, state_.target[i]);
  }
  const SkillPhaseBinding& pb = binding_->phases[static_cast<size_t>(phase)];
  state_.targets = &pb.targets;
  load_goals(pb);
  if (from == SkillPhase::From::kNone) state_.from = state_.goal;
  if (phase == takeoff_) {
    state_.takeoff_com_z = state_.com[2];
    takeoff_pitch_ = q[body_.root_pitch_qpos];
  }
  free_since_ = -1;
  state_.phase_duration = duration_of(phase);
  for (int k : pb.modules) modules_[static_cast<size_t>(k)]->enter(m, d, state_);
}

bool SkillController::holds(const SkillCondition& c, const mjModel* m, const mjData* d) const {
  using T = SkillCondition::Type;
  const double elapsed = state_.time - state_.phase_begin;
  switch (c.type) {
    case T::kDuration: return elapsed >= state_.phase_duration;
    case T::kTime: return elapsed >= c.after;
    case T::kContact: return contacts_.any;
    case T::kLiftoff:
      // Airborne: no contact for a while with the COM rising (soft contacts can flicker for
      // a step while the legs push).
      return free_since_ >= 0 && state_.time - free_since_ >= c.airborne - 1e-9 && state_.com_vel[2] > 0;
    case T::kPeak: return state_.com_vel[2] <= 0;
    case T::kTurned: return std::fabs(state_.qpos[body_.root_pitch_qpos] - takeoff_pitch_) >= c.angle;
    case T::kSpotted:
      for (int mod : binding_->phases[static_cast<size_t>(state_.phase)].modules) {
        if (skill_->modules[static_cast<size_t>(mod)].kind == "spotting" && modules_[static_cast<size_t>(mod)]->spotted(state_)) return true;
      }
      return false;
    case T::kContactMade:
    case T::kContactLost: {
      bool touching = false;
      if (!c.foot.empty()) {
        // A foot (or a body below it) by side, or by its role in the phase.
        const int swing = state_.swing;
        const int side = c.foot == "left" ? 0 : c.foot == "right" ? 1 : c.foot == "swing" ? swing : 1 - swing;
        touching = contacts_.foot[static_cast<size_t>(side)];
      } else {
        int id = -1;
        for (const auto& [condition, body] : bodies_)
          if (condition == &c) id = body;
        for (int i = 0; i < d->ncon && !touching; ++i) {
          const mjContact& con = d->contact[i];
          if (con.exclude != 0) continue;
          touching = m->geom_bodyid[con.geom1] == id || m->geom_bodyid[con.geom2] == id;
        }
      }
      return c.type == T::kContactMade ? touching : !touching;
    }
    case T::kFeature: break;
  }
  // A feature crossing a threshold.
  const double v = skill_feature(c.which, body_, m, d, state_.com, state_.com_vel);
  return c.above ? v >= c.threshold : v <= c.threshold;
}

void SkillController::control(const mjModel* m, mjData* d, const ContactState& contacts, JointDrive& drive) {
  const double t = d->time;
  const double* q = d->qpos;
  state_.time = t;
  state_.qpos = q;
  state_.contacts = &contacts;
  contacts_ = contacts;
  const int root = body_.root_body;
  for (int k = 0; k < 3; ++k) state_.com[static_cast<size_t>(k)] = d->subtree_com[3 * root + k];
  state_.com_vel = com_velocity_(m, d);

  // 1. The phase's modules update what they track.
  const size_t phase0 = static_cast<size_t>(state_.phase);
  for (int k : binding_->phases[phase0].modules) modules_[static_cast<size_t>(k)]->update(m, d, state_);

  // 2. Transitions: at most one per step, the first whose conditions all hold.
  state_.phase_changed = false;
  const SkillPhase& phase = skill_->phases[phase0];
  if (liftoff_[phase0]) {
    if (contacts.any) free_since_ = -1;
    else if (free_since_ < 0) free_since_ = t;
  }
  for (const SkillTransition& tr : phase.next) {
    bool all = true;
    for (const SkillCondition& c : tr.on) {
      if (!holds(c, m, d)) {
        all = false;
        break;
      }
    }
    if (!all) continue;
    if (tr.gave_up) gave_up_ = true;
    for (const std::string& passed : tr.passes) times_.begin[static_cast<size_t>(skill_->phase_index(passed))] = t;
    enter(skill_->phase_index(tr.to), m, d);  // once per phase: the names are looked up then
    break;
  }

  // 3. Targets: linear from the phase's starting targets to its goal.
  const size_t p = static_cast<size_t>(state_.phase);
  const SkillPhase& now = skill_->phases[p];
  const SkillPhaseBinding& pb = binding_->phases[p];
  const bool at_once = !now.interpolate || now.duration.kind == SkillDuration::Kind::kNone;
  const double s = at_once ? 1.0 : std::clamp((t - state_.phase_begin) / std::max(state_.phase_duration, 1e-6), 0.0, 1.0);
  state_.progress = s;
  if (heading_frame_) state_.heading = root_heading(d, root, standing_);
  state_.double_support = pb.swing >= 0 && !pb.swing_lands && contacts.foot[static_cast<size_t>(pb.swing)];
  const std::vector<char>& owned = owned_[p];
  for (size_t i = 0; i < body_.joints.size(); ++i) {
    if (owned[i]) continue;
    const SkillJointTarget& jt = pb.targets[i];
    const bool tracked = jt.world == SkillTarget::World::kParent || jt.world == SkillTarget::World::kChild;
    if (jt.value->kind == SkillValue::Kind::kCurve) {
      const auto& knots = jt.value->curve;
      size_t k = 1;
      while (k + 1 < knots.size() && knots[k][0] < s) ++k;
      const double u = (s - knots[k - 1][0]) / (knots[k][0] - knots[k - 1][0]);
      const double value = knots[k - 1][1] + u * (knots[k][1] - knots[k - 1][1]);
      state_.target[i] = tracked ? to_local(i, q, value) : value;
      continue;
    }
    const double goal = state_.goal[i];
    if (jt.world == SkillTarget::World::kHeading) {  // at once: angles from standing
      state_.target[i] = goal;
      continue;
    }
    // World pitches along the shorter way round, then a joint target for the current pose.
    const double step = tracked ? skill_wrap(goal - state_.from[i]) : goal - state_.from[i];
    state_.target[i] = tracked ? to_local(i, q, state_.from[i] + s * step) : state_.from[i] + s * step;
  }
  for (int k : pb.modules) modules_[static_cast<size_t>(k)]->set_targets(m, d, state_);

  // 4. Torques: a module that drives the phase, or PD plus the modules' feedforward.
  for (int k : pb.modules) {
    if (modules_[static_cast<size_t>(k)]->drives()) {
      modules_[static_cast<size_t>(k)]->drive(m, d, state_, drive);
      return;
    }
  }
  std::fill(state_.feedforward.begin(), state_.feedforward.end(), 0.0);
  for (int k : pb.modules) modules_[static_cast<size_t>(k)]->add_torques(m, d, state_);
  // The drive takes u (all but the damping) and kd, and applies u - kd qdot within the
  // joint's limit. World-frame joints damp the tracked link's world pitch rate: -kd qdot
  // (the drive's damping) plus kd times the rate of the link on the other side of the
  // joint, with the sign that makes the sum the tracked link's rate.
  const double* v = d->qvel;
  if (heading_frame_) std::fill(link_done_.begin(), link_done_.end(), 0);
  for (size_t i = 0; i < body_.joints.size(); ++i) {
    const CharacterJoint& j = body_.joints[i];
    // The strength model scales every joint's PD gains (Character::strength).
    const double kp = body_.strength * state_.kp[i];
    const double kd = body_.strength * state_.kd[i];
    SkillTarget::World w = pb.targets[i].world;
    preset_[i] = 0;
    if (w == SkillTarget::World::kHeading) {
      // The link below the joint tracks its heading-frame orientation: the rotation error e
      // (world) projected on the hinge's axis a, tau = kp a . e - kd a . w_link, the
      // derivative part split into the joint's own rate (the drive's damping) and
      // a . w_parent.
      const size_t b = static_cast<size_t>(j.body);
      if (!link_done_[b]) {
        double target[4];
        link_target(j.body, target);
        rotation_error(target, d->xquat + 4 * j.body, link_error_[b].data());
        link_done_[b] = 1;
      }
      const double* a = d->xaxis + 3 * j.joint;
      const double* w_parent = d->cvel + 6 * m->body_parentid[j.body];
      state_.u[i] = kp * dot3(a, link_error_[b].data()) - kd * dot3(a, w_parent) + state_.feedforward[i];
      state_.damping[i] = kd;
      continue;
    }
    // A stance3d module's world pitches are PD joint targets here (their joints hold).
    if (w != SkillTarget::World::kParent && w != SkillTarget::World::kChild) w = SkillTarget::World::kJoint;
    if (w != SkillTarget::World::kJoint && drive.damping() == Damping::kConstrained) {
      // The drive damps the tracked link's world pitch rate itself: root pitch rate plus
      // the joint rates down the chain to the child; the parent's is that less qdot.
      damped_.clear();
      const double sign = w == SkillTarget::World::kParent ? -1.0 : 1.0;
      damped_.push_back({body_.root_pitch_dof, sign});
      for (int k : body_.chain(static_cast<int>(i))) damped_.push_back({body_.joints[static_cast<size_t>(k)].dof, sign});
      if (w == SkillTarget::World::kParent) damped_.push_back({j.dof, 1.0});
      drive.set(static_cast<int>(i), kp * (state_.target[i] - q[j.qpos]) + state_.feedforward[i], kd, damped_);
      preset_[i] = 1;
      continue;
    }
    double world_damping = 0;
    if (w != SkillTarget::World::kJoint) {
      const double child_rate = body_.child_pitch_rate(v, static_cast<int>(i));
      if (w == SkillTarget::World::kParent) {  // parent rate = child rate - qdot
        world_damping = kd * child_rate;
      } else {  // child rate = qdot + parent rate
        world_damping = -kd * (child_rate - v[j.dof]);
      }
    }
    state_.u[i] = kp * (state_.target[i] - q[j.qpos]) + world_damping + state_.feedforward[i];
    state_.damping[i] = kd;
  }
  for (int k : pb.modules) modules_[static_cast<size_t>(k)]->adjust_torques(m, d, state_);
  for (size_t i = 0; i < body_.joints.size(); ++i) {
    if (!preset_[i]) drive.set(static_cast<int>(i), state_.u[i], state_.damping[i]);
  }
}

// ---------------------------------------------------------------------------------------
// Module settings.

ModuleSettings::ModuleSettings(const SkillModuleSpec& spec, const std::map<std::string, int>& params,
                               const std::vector<double>& values) {
  for (const auto& [name, value] : spec.settings) {
    const auto it = params.find(name);
    values_[name] = it != params.end() && it->second >= 0 ? values[static_cast<size_t>(it->second)] : value.number;
  }
}

double ModuleSettings::get(const std::string& name, double fallback) const {
  const auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second;
}

}  // namespace diverse

namespace diverse {

std::unique_ptr<SkillModule> make_skill_module(const SkillModuleSpec& spec, const ModuleSettings& settings,
                                               const Character& body) {
  if (spec.kind == "balance") return std::make_unique<BalanceModule>(settings, body);
  if (spec.kind == "foot_placement") return std::make_unique<FootPlacementModule>(settings, body);
  if (spec.kind == "spotting") return std::make_unique<SpottingModule>(settings);
  if (spec.kind == "stance") return std::make_unique<StanceModule>(settings, body);
  if (spec.kind == "simbicon") return std::make_unique<SimbiconModule>(spec, settings, body);
  if (spec.kind == "gravity_compensation") return std::make_unique<GravityCompensationModule>(body);
  if (spec.kind == "stance_support") return std::make_unique<StanceSupportModule>(settings, body);
  if (spec.kind == "stance_hip") return std::make_unique<StanceHipModule>(settings, body);
  if (spec.kind == "stance3d") return std::make_unique<Stance3dModule>(settings, body);
  if (spec.kind == "aim_legs") return std::make_unique<AimLegsModule>(settings, body);
  if (spec.kind == "root_damping") return std::make_unique<RootDampingModule>(settings, body);
  if (spec.kind == "linear_feedback") return std::make_unique<LinearFeedbackModule>(spec, settings, body);
  throw std::logic_error("skill: no module of kind " + spec.kind);
}

}  // namespace diverse
