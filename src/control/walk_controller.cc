#include "control/walk_controller.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/error.h"
#include "core/toml_reader.h"
#include "physics/model.h"

namespace diverse {
namespace {

constexpr const char* kStateNames[kNumWalkStates] = {"left_lift", "left_strike", "right_lift",
                                                     "right_strike"};
constexpr const char* kBlock[2] = {"lift", "strike"};  // parameter prefixes of the two states

// Ranges (rad) of the heading-frame targets, intersected with the joints' own.
constexpr double kPelvisRange = 0.4;
constexpr double kTorsoRange = 0.6;
constexpr double kLinkRange = 1.2;  // femur and foot, about their standing orientation

double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Rotation vector (world) of the rotation that takes orientation q to `target`.
void rotation_error(const double* target, const double* q, double* e) {
  double inv[4], dq[4];
  mju_negQuat(inv, q);
  mju_mulQuat(dq, target, inv);
  if (dq[0] < 0) {
    for (double& c : dq) c = -c;
  }
  mju_quat2Vel(e, dq, 1.0);
}

// Gravity compensation of one hinge: a . ((c_sub - p) x m_sub g z).
double gravity_torque(const mjModel* m, const mjData* d, const CharacterJoint& j, double gravity) {
  const double* a = d->xaxis + 3 * j.joint;
  const double* p = d->xanchor + 3 * j.joint;
  const double* c = d->subtree_com + 3 * j.body;
  const double r[3] = {c[0] - p[0], c[1] - p[1], c[2] - p[2]};
  const double f[3] = {0, 0, m->body_subtreemass[j.body] * gravity};
  double rf[3];
  mju_cross(rf, r, f);
  return dot3(a, rf);
}

// Heading (rad) of orientation q: its forward (x) axis turned onto the ground plane.
double heading_of(const double* q) {
  double R[9];
  mju_quat2Mat(R, q);
  return std::atan2(R[3], R[0]);
}

bool is_lift(int state) { return state == kLeftLift || state == kRightLift; }

// The structure a walk3d controller needs, found from the character alone.
struct Layout {
  std::vector<int> leg_of;   // per joint: 0, 1 (in the chain from the root to a foot) or -1
  std::vector<char> hip;     // per joint: a leg joint whose body's parent is the root body
  std::vector<char> foot;    // per joint: a leg joint on the foot body (or below it)
  int torso_body = -1;       // the deepest waist hinge's body, or -1
};

Layout layout_of(const Character& body) {
  Layout l;
  const size_t n = body.joints.size();
  l.leg_of.assign(n, -1);
  l.hip.assign(n, 0);
  l.foot.assign(n, 0);
  for (size_t k = 0; k < n; ++k) {
    const CharacterJoint& j = body.joints[k];
    const int s = body.foot_of_body_[static_cast<size_t>(j.body)];
    if (s < 0) continue;
    // The foot's own hinges (and any below it) and everything on the path to the root.
    l.foot[k] = 1;
    for (int c : body.chain(static_cast<int>(k))) l.leg_of[static_cast<size_t>(c)] = s;
  }
  size_t depth = 0;
  for (size_t k = 0; k < n; ++k) {
    const CharacterJoint& j = body.joints[k];
    if (l.leg_of[k] >= 0) {
      // A hip: every joint between it and the root is on its own body.
      bool hip = true;
      for (int c : body.chain(static_cast<int>(k))) hip = hip && body.joints[static_cast<size_t>(c)].body == j.body;
      l.hip[k] = hip;
    }
    const JointGroup& g = body.groups[static_cast<size_t>(j.group)];
    if (g.role == JointRole::kWaist && j.side == Side::kCenter) {
      const size_t dd = body.chain(static_cast<int>(k)).size();
      if (l.torso_body < 0 || dd > depth) {
        l.torso_body = j.body;
        depth = dd;
      }
    }
  }
  return l;
}

// One state's targets, as named parameters: name suffix, range, and which joints use it.
struct Entry {
  std::string name;
  double lo = 0, hi = 0;
};

double rel_lo(const CharacterJoint& j, double qpos0, double limit) {
  return std::max(std::isfinite(j.lower) ? j.lower - qpos0 : -limit, -limit);
}
double rel_hi(const CharacterJoint& j, double qpos0, double limit) {
  return std::min(std::isfinite(j.upper) ? j.upper - qpos0 : limit, limit);
}

// The standing angle of each joint (qpos0).
std::vector<double> standing_angles(const Character& body) {
  std::vector<double> q;
  for (const CharacterJoint& j : body.joints) q.push_back(j.standing);
  return q;
}

// The per-state entries and, per swing leg and joint, what the joint does and which entry
// it reads. Entry 0 and 1 are the pelvis's pitch and roll.
struct Plan {
  std::vector<Entry> entries;
  std::array<std::vector<int>, 2> kind;   // per swing leg, per joint: 0 stance hip, 1 swing hip,
                                          // 2 swing foot, 3 torso, 4 joint, 5 hold
  std::array<std::vector<int>, 2> param;  // per swing leg, per joint: entry or -1
};

Plan plan_of(const Character& body, const Layout& l) {
  Plan p;
  const std::vector<double> q0 = standing_angles(body);
  p.entries.push_back({"pelvis.pitch", -kPelvisRange, kPelvisRange});
  p.entries.push_back({"pelvis.roll", -kPelvisRange, kPelvisRange});
  const size_t n = body.joints.size();
  for (int s = 0; s < 2; ++s) {
    p.kind[static_cast<size_t>(s)].assign(n, 4);
    p.param[static_cast<size_t>(s)].assign(n, -1);
  }
  auto add = [&](const std::string& name, double lo, double hi) {
    p.entries.push_back({name, lo, hi});
    return static_cast<int>(p.entries.size()) - 1;
  };
  for (const JointGroup& g : body.groups) {
    const int first = g.joints[0];
    const CharacterJoint& j = body.joints[static_cast<size_t>(first)];
    const double q = q0[static_cast<size_t>(first)];
    if (g.role == JointRole::kNeck) {
      for (int k : g.joints)
        for (int s = 0; s < 2; ++s) p.kind[static_cast<size_t>(s)][static_cast<size_t>(k)] = 5;
      continue;
    }
    if (l.leg_of[static_cast<size_t>(first)] >= 0) {
      const bool hip = l.hip[static_cast<size_t>(first)];
      const bool foot = l.foot[static_cast<size_t>(first)];
      int swing = -1, stance = -1;
      if (hip || foot) {
        swing = add("swing." + g.name, rel_lo(j, q, kLinkRange), rel_hi(j, q, kLinkRange));
      } else {
        swing = add("swing." + g.name, j.lower, j.upper);
      }
      if (!hip) stance = add("stance." + g.name, j.lower, j.upper);
      for (int k : g.joints) {
        const int leg = l.leg_of[static_cast<size_t>(k)];
        for (int s = 0; s < 2; ++s) {
          int& kind = p.kind[static_cast<size_t>(s)][static_cast<size_t>(k)];
          int& param = p.param[static_cast<size_t>(s)][static_cast<size_t>(k)];
          if (leg == s) {
            kind = hip ? 1 : foot ? 2 : 4;
            param = swing;
          } else {
            kind = hip ? 0 : 4;
            param = hip ? -1 : stance;
          }
        }
      }
      continue;
    }
    if (g.role == JointRole::kWaist && j.body == l.torso_body) {
      const int e = add("torso." + g.name, rel_lo(j, q, kTorsoRange), rel_hi(j, q, kTorsoRange));
      for (int k : g.joints)
        for (int s = 0; s < 2; ++s) {
          p.kind[static_cast<size_t>(s)][static_cast<size_t>(k)] = 3;
          p.param[static_cast<size_t>(s)][static_cast<size_t>(k)] = e;
        }
      continue;
    }
    if (g.joints.size() == 2) {
      const int sw = add("swing_side." + g.name, j.lower, j.upper);
      const int st = add("stance_side." + g.name, j.lower, j.upper);
      for (size_t i = 0; i < 2; ++i)
        for (int s = 0; s < 2; ++s)
          p.param[static_cast<size_t>(s)][static_cast<size_t>(g.joints[i])] =
              static_cast<int>(i) == s ? sw : st;
      continue;
    }
    const int e = add(g.name, j.lower, j.upper);
    for (int s = 0; s < 2; ++s) p.param[static_cast<size_t>(s)][static_cast<size_t>(first)] = e;
  }
  return p;
}

}  // namespace

const char* walk_state_name(int state) {
  return state >= 0 && state < kNumWalkStates ? kStateNames[state] : "?";
}

std::shared_ptr<const ControllerConfig> WalkControllerConfig::with_landing_height(double) const {
  return std::make_shared<WalkControllerConfig>(*this);
}

std::shared_ptr<const ControllerConfig> WalkControllerType::read_config(const TomlReader& r) const {
  r.only({"type", "root_kp", "root_kd", "strike_timeout", "gravity_compensation", "stance_support"});
  auto c = std::make_shared<WalkControllerConfig>();
  c->root_kp = r.number("root_kp", 0, 20000, c->root_kp);
  c->root_kd = r.number("root_kd", 0, 5000, c->root_kd);
  c->strike_timeout = r.number("strike_timeout", 0.1, 10, c->strike_timeout);
  c->gravity_compensation = r.boolean("gravity_compensation", c->gravity_compensation);
  c->stance_support = r.number("stance_support", 0, 1.5, c->stance_support);
  return c;
}

void WalkControllerType::check(const Character& body, const std::string& task_file) const {
  const std::string who = "the character " + body.spec->file;
  if (body.root != RootKind::kFree) {
    throw_field_error(task_file, "controller.type",
                      "expected a character with a free root for \"walk3d\", but " + who + " has a planar root");
  }
  const int hip = body.find_group(JointRole::kHip);
  if (hip < 0 || body.groups[static_cast<size_t>(hip)].joints.size() != 2) {
    throw_field_error(task_file, "controller.type",
                      "expected a left/right pair in a \"hip\" group for \"walk3d\" (two legs), in " + who);
  }
}

std::vector<ParamSpec> WalkControllerType::parameter_specs(const Character& body,
                                                           const ControllerConfig&) const {
  return WalkController::parameter_specs(body);
}

std::unique_ptr<Controller> WalkControllerType::make(const Character& body, const ControllerConfig& config,
                                                     const std::vector<double>& values) const {
  const auto* c = dynamic_cast<const WalkControllerConfig*>(&config);
  if (c == nullptr) throw std::logic_error("walk3d: wrong config type");
  auto controller = std::make_unique<WalkController>(body, *c);
  controller->set_parameters(values);
  return controller;
}

std::vector<ParamSpec> WalkController::parameter_specs(const Character& body) {
  const Plan p = plan_of(body, layout_of(body));
  std::vector<ParamSpec> specs;
  for (int b = 0; b < 2; ++b) {
    for (const Entry& e : p.entries) specs.push_back({std::string(kBlock[b]) + "." + e.name, e.lo, e.hi, "rad"});
  }
  specs.push_back({"lift.duration", 0.1, 0.7, "s"});
  specs.push_back({"sagittal.cd", 0, 1.5, "rad/m"});
  specs.push_back({"sagittal.cv", 0, 1.0, "rad s/m"});
  specs.push_back({"coronal.cd", 0, 1.5, "rad/m"});
  specs.push_back({"coronal.cv", 0, 1.0, "rad s/m"});
  return specs;
}

WalkController::WalkController(const Character& body, const WalkControllerConfig& config)
    : body_(body), config_(config) {
  if (body.root != RootKind::kFree) throw std::invalid_argument("WalkController: expected a free root");
  const Layout l = layout_of(body);
  const Plan p = plan_of(body, l);
  per_state_ = static_cast<int>(p.entries.size());
  pelvis_pitch_ = 0;
  pelvis_roll_ = 1;
  leg_of_ = l.leg_of;
  qpos0_ = standing_angles(body);
  const int n = body.dof();
  static constexpr Kind kKinds[6] = {Kind::kStanceHip, Kind::kSwingHip, Kind::kSwingFoot,
                                     Kind::kTorso,     Kind::kJoint,    Kind::kHold};
  for (int s = 0; s < 2; ++s) {
    slots_[static_cast<size_t>(s)].resize(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k) {
      Slot& slot = slots_[static_cast<size_t>(s)][static_cast<size_t>(k)];
      slot.kind = kKinds[p.kind[static_cast<size_t>(s)][static_cast<size_t>(k)]];
      slot.param = p.param[static_cast<size_t>(s)][static_cast<size_t>(k)];
    }
  }
  for (int k = 0; k < n; ++k) {
    bool on_root_child = true;
    for (int c : body.chain(k)) on_root_child = on_root_child && body.joints[static_cast<size_t>(c)].body == body.joints[static_cast<size_t>(k)].body;
    if (on_root_child) root_children_.push_back(k);
  }
  for (int s = 0; s < 2; ++s) {
    for (int k = 0; k < n; ++k)
      if (l.hip[static_cast<size_t>(k)] && l.leg_of[static_cast<size_t>(k)] == s) femur_[static_cast<size_t>(s)].body = body.joints[static_cast<size_t>(k)].body;
    foot_[static_cast<size_t>(s)].body = body.feet[static_cast<size_t>(s)];
  }
  torso_.body = l.torso_body;
  for (int k = 0; k < n; ++k) {
    const int leg = l.leg_of[static_cast<size_t>(k)];
    if (leg >= 0 && !l.hip[static_cast<size_t>(k)] && !l.foot[static_cast<size_t>(k)]) middle_[static_cast<size_t>(leg)].push_back(k);
  }
  times_.names.assign(kStateNames, kStateNames + kNumWalkStates);
  times_.begin.assign(kNumWalkStates, -1.0);
  u_.assign(static_cast<size_t>(n), 0.0);
  kd_.assign(static_cast<size_t>(n), 0.0);
  for (auto& t : targets_) t.assign(static_cast<size_t>(per_state_), 0.0);
}

void WalkController::prepare(const mjModel* m) {
  if (prepared_) return;
  prepared_ = true;
  // The standing pose by forward kinematics at qpos0, where every hinge adds no rotation
  // (MuJoCo turns a hinge by qpos - qpos0) and the free root sits at its body frame.
  const int nb = m->nbody;
  std::vector<std::array<double, 4>> quat(static_cast<size_t>(nb), {1, 0, 0, 0});
  std::vector<std::array<double, 3>> pos(static_cast<size_t>(nb), {0, 0, 0});
  double com[3] = {0, 0, 0};
  for (int b = 1; b < nb; ++b) {
    const int parent = m->body_parentid[b];
    double R[9], off[3];
    mju_quat2Mat(R, quat[static_cast<size_t>(parent)].data());
    mju_mulMatVec(off, R, m->body_pos + 3 * b, 3, 3);
    for (int i = 0; i < 3; ++i) pos[static_cast<size_t>(b)][static_cast<size_t>(i)] = pos[static_cast<size_t>(parent)][static_cast<size_t>(i)] + off[i];
    mju_mulQuat(quat[static_cast<size_t>(b)].data(), quat[static_cast<size_t>(parent)].data(), m->body_quat + 4 * b);
    if (m->body_rootid[b] != body_.root_body) continue;
    double Rb[9], ci[3];
    mju_quat2Mat(Rb, quat[static_cast<size_t>(b)].data());
    mju_mulMatVec(ci, Rb, m->body_ipos + 3 * b, 3, 3);
    for (int i = 0; i < 3; ++i) com[i] += m->body_mass[b] * (pos[static_cast<size_t>(b)][static_cast<size_t>(i)] + ci[i]);
  }
  auto track = [&](Tracked& t) {
    if (t.body < 0) return;
    t.joints.clear();
    t.axes.clear();
    double R[9];
    mju_quat2Mat(R, quat[static_cast<size_t>(t.body)].data());
    for (int k = 0; k < body_.dof(); ++k) {
      const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
      if (j.body != t.body) continue;
      t.joints.push_back(k);
      std::array<double, 3> a{};
      mju_mulMatVec(a.data(), R, m->jnt_axis + 3 * j.joint, 3, 3);
      t.axes.push_back(a);
    }
    t.standing = quat[static_cast<size_t>(t.body)];
  };
  for (int s = 0; s < 2; ++s) {
    track(femur_[static_cast<size_t>(s)]);
    track(foot_[static_cast<size_t>(s)]);
  }
  track(torso_);
  const int root = body_.root_body;
  root_standing_ = quat[static_cast<size_t>(root)];
  root_standing_heading_ = heading_of(root_standing_.data());
  mass_ = m->body_subtreemass[root];
  gravity_ = -m->opt.gravity[2];
  const double standing_height = com[2] / mass_;
  root_kp_ = config_.root_kp > 0 ? config_.root_kp : 2 * mass_ * gravity_ * standing_height;
  root_kd_ = config_.root_kd > 0 ? config_.root_kd : root_kp_ / 5;
}

void WalkController::set_parameters(const std::vector<double>& values) {
  const size_t expected = 2 * static_cast<size_t>(per_state_) + 5;
  if (values.size() != expected) {
    throw std::invalid_argument("WalkController::set_parameters: expected " + std::to_string(expected) +
                                " values, got " + std::to_string(values.size()));
  }
  size_t i = 0;
  for (auto& t : targets_)
    for (double& v : t) v = values[i++];
  lift_duration_ = values[i++];
  cd_sag_ = values[i++];
  cv_sag_ = values[i++];
  cd_cor_ = values[i++];
  cv_cor_ = values[i++];
}

void WalkController::link_target(const Tracked& link, const double* angles, double* quat) const {
  const double h = heading_;
  double q[4] = {std::cos(h / 2), 0, 0, std::sin(h / 2)};
  for (size_t i = 0; i < link.joints.size(); ++i) {
    double r[4], next[4];
    mju_axisAngle2Quat(r, link.axes[i].data(), angles[i]);
    mju_mulQuat(next, q, r);
    mju_copy4(q, next);
  }
  mju_mulQuat(quat, q, link.standing.data());
}

void WalkController::root_target(int state, double* quat) const {
  const std::vector<double>& t = targets_[is_lift(state) ? 0 : 1];
  const double mirror = swing_leg(state) == 0 ? 1.0 : -1.0;
  const double pitch_axis[3] = {0, -1, 0}, roll_axis[3] = {1, 0, 0};
  double yaw[4] = {std::cos(heading_ / 2), 0, 0, std::sin(heading_ / 2)};
  double p[4], r[4], a[4], b[4];
  mju_axisAngle2Quat(p, pitch_axis, t[static_cast<size_t>(pelvis_pitch_)]);
  mju_axisAngle2Quat(r, roll_axis, mirror * t[static_cast<size_t>(pelvis_roll_)]);
  mju_mulQuat(a, yaw, p);
  mju_mulQuat(b, a, r);
  // The standing orientation without its heading (the heading frame replaces it).
  double unturn[4] = {std::cos(-root_standing_heading_ / 2), 0, 0, std::sin(-root_standing_heading_ / 2)};
  double level[4];
  mju_mulQuat(level, unturn, root_standing_.data());
  mju_mulQuat(quat, b, level);
}

void WalkController::tracked_angles(const Tracked& link, int state, int swing, double* angles) const {
  const std::vector<double>& t = targets_[is_lift(state) ? 0 : 1];
  const double mirror = swing == 0 ? 1.0 : -1.0;
  for (size_t i = 0; i < link.joints.size(); ++i) {
    const int k = link.joints[i];
    const Slot& slot = slots_[static_cast<size_t>(swing)][static_cast<size_t>(k)];
    double v = slot.param >= 0 ? t[static_cast<size_t>(slot.param)] : 0.0;
    const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
    const JointPlane plane = body_.groups[static_cast<size_t>(j.group)].plane;
    if (slot.kind == Kind::kTorso && plane == JointPlane::kCoronal) v *= mirror;
    if (slot.kind == Kind::kSwingHip) v += plane == JointPlane::kCoronal ? femur_target_[1] : femur_target_[0];
    angles[i] = v;
  }
}

bool WalkController::start_state(const mjModel* m, mjData* d) {
  prepare(m);
  const int swing = swing_leg(kLeftLift), stance = 1 - swing;
  const std::vector<double>& t = targets_[0];
  heading_ = 0;
  femur_target_ = {0, 0};
  mju_copy(d->qpos, m->qpos0, m->nq);
  mju_zero(d->qvel, m->nv);
  double* root_q = d->qpos + body_.root_qpos + 3;
  root_target(kLeftLift, root_q);
  const int n = body_.dof();
  for (int k = 0; k < n; ++k) {
    const Slot& slot = slots_[static_cast<size_t>(swing)][static_cast<size_t>(k)];
    const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
    if (slot.kind == Kind::kJoint) d->qpos[j.qpos] = t[static_cast<size_t>(slot.param)];
  }
  // The tracked links: the swing femur, foot and the torso at their targets, the stance
  // femur and foot at their standing orientations (zero angles), by fixed-point iteration
  // on the hinge angles (each turned by the error's component along its axis).
  struct Goal {
    const Tracked* link;
    std::vector<double> angles;
  };
  std::vector<Goal> goals;
  auto goal = [&](const Tracked& link, bool targeted) {
    if (link.body < 0) return;
    Goal g{&link, std::vector<double>(link.joints.size(), 0.0)};
    if (targeted) tracked_angles(link, kLeftLift, swing, g.angles.data());
    goals.push_back(std::move(g));
  };
  goal(femur_[static_cast<size_t>(swing)], true);
  goal(foot_[static_cast<size_t>(swing)], true);
  goal(torso_, true);
  goal(femur_[static_cast<size_t>(stance)], false);
  goal(foot_[static_cast<size_t>(stance)], false);
  for (int it = 0; it < 50; ++it) {
    mj_kinematics(m, d);
    double worst = 0;
    for (const Goal& g : goals) {
      double target[4], e[3];
      link_target(*g.link, g.angles.data(), target);
      rotation_error(target, d->xquat + 4 * g.link->body, e);
      worst = std::max(worst, mju_norm3(e));
      for (int k : g.link->joints) {
        const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
        double& q = d->qpos[j.qpos];
        q += dot3(d->xaxis + 3 * j.joint, e);
        if (std::isfinite(j.lower)) q = std::clamp(q, j.lower, j.upper);
      }
    }
    if (worst < 1e-10) break;
  }
  // The stance sole on the floor, the root above the origin.
  mj_kinematics(m, d);
  double lowest = INFINITY;
  for (int g = 0; g < m->ngeom; ++g) {
    int side = -1;
    if (m->geom_bodyid[g] == 0 || !body_.is_foot_geom(m, g, &side) || side != stance) continue;
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

void WalkController::measure(const mjModel* m, const mjData* d) {
  const int root = body_.root_body;
  const double* c = d->subtree_com + 3 * root;
  com_ = {c[0], c[1], c[2]};
  double p[3] = {0, 0, 0};
  for (int b : body_.links) {
    const double* v = d->cvel + 6 * b;
    const double* o = d->subtree_com + 3 * m->body_rootid[b];
    const double r[3] = {d->xipos[3 * b] - o[0], d->xipos[3 * b + 1] - o[1], d->xipos[3 * b + 2] - o[2]};
    double w_r[3];
    mju_cross(w_r, v, r);
    for (int i = 0; i < 3; ++i) p[i] += m->body_mass[b] * (v[3 + i] + w_r[i]);
  }
  for (int i = 0; i < 3; ++i) com_vel_[static_cast<size_t>(i)] = p[i] / mass_;
}

void WalkController::enter(int state, double time) {
  state_ = state;
  state_begin_ = time;
  changed_ = true;
  times_.begin[static_cast<size_t>(state)] = time;
}

void WalkController::reset(const mjModel* m, const mjData* d) {
  prepare(m);
  measure(m, d);
  state_ = kLeftLift;
  strikes_ = 0;
  times_.begin.assign(kNumWalkStates, -1.0);
  enter(kLeftLift, d->time);
}

void WalkController::control(const mjModel* m, mjData* d, const ContactState& contacts, JointDrive& drive) {
  changed_ = false;
  measure(m, d);
  const double time = d->time;
  const int root = body_.root_body;
  if (is_lift(state_)) {
    if (time - state_begin_ >= lift_duration_) enter(state_ + 1, time);
  } else {
    const bool down = contacts.foot[static_cast<size_t>(swing_leg(state_))];
    if (down || time - state_begin_ >= config_.strike_timeout) {
      if (down) ++strikes_;
      enter((state_ + 1) % kNumWalkStates, time);
    }
  }
  const int swing = swing_leg(state_), stance = 1 - swing;
  const std::vector<double>& t = targets_[is_lift(state_) ? 0 : 1];
  const std::vector<Slot>& slots = slots_[static_cast<size_t>(swing)];
  const bool double_support = is_lift(state_) && contacts.foot[static_cast<size_t>(swing)];

  // Heading frame and balance feedback.
  {
    double q[4], unturn[4];
    mju_negQuat(unturn, root_standing_.data());
    mju_mulQuat(q, d->xquat + 4 * root, unturn);
    heading_ = heading_of(q) + 0.0;
  }
  const double ch = std::cos(heading_), sh = std::sin(heading_);
  const double* ankle = d->xpos + 3 * body_.feet[static_cast<size_t>(stance)];
  const double dx = com_[0] - ankle[0], dy = com_[1] - ankle[1];
  const double toward_swing = swing == 0 ? 1.0 : -1.0;  // heading-frame y points left
  const double d_sag = ch * dx + sh * dy;
  const double d_cor = toward_swing * (-sh * dx + ch * dy);
  const double v_sag = ch * com_vel_[0] + sh * com_vel_[1];
  const double v_cor = toward_swing * (-sh * com_vel_[0] + ch * com_vel_[1]);
  femur_target_ = {cd_sag_ * d_sag + cv_sag_ * v_sag, cd_cor_ * d_cor + cv_cor_ * v_cor};

  // Every joint but the stance hip.
  const int n = body_.dof();
  auto track = [&](const Tracked& link) {
    double angles[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    tracked_angles(link, state_, swing, angles);
    double target[4], e[3];
    link_target(link, angles, target);
    rotation_error(target, d->xquat + 4 * link.body, e);
    const double* w_parent = d->cvel + 6 * m->body_parentid[link.body];
    for (int k : link.joints) {
      const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
      const JointGroup& g = body_.groups[static_cast<size_t>(j.group)];
      const double* a = d->xaxis + 3 * j.joint;
      const double kp = body_.strength * g.kp, kd = body_.strength * g.kd;
      u_[static_cast<size_t>(k)] = kp * dot3(a, e) - kd * dot3(a, w_parent);
      kd_[static_cast<size_t>(k)] = kd;
    }
  };
  for (int k = 0; k < n; ++k) {
    const Slot& slot = slots[static_cast<size_t>(k)];
    const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
    const JointGroup& g = body_.groups[static_cast<size_t>(j.group)];
    if (slot.kind == Kind::kJoint || slot.kind == Kind::kHold) {
      const double target = slot.kind == Kind::kHold ? qpos0_[static_cast<size_t>(k)] : t[static_cast<size_t>(slot.param)];
      u_[static_cast<size_t>(k)] = body_.strength * g.kp * (target - d->qpos[j.qpos]);
      kd_[static_cast<size_t>(k)] = body_.strength * g.kd;
    }
  }
  track(femur_[static_cast<size_t>(swing)]);
  track(foot_[static_cast<size_t>(swing)]);
  if (torso_.body >= 0) track(torso_);
  if (config_.gravity_compensation) {
    for (int k = 0; k < n; ++k) {
      const int leg = leg_of_[static_cast<size_t>(k)];
      if (leg == stance || (double_support && leg == swing)) continue;
      u_[static_cast<size_t>(k)] += gravity_torque(m, d, body_.joints[static_cast<size_t>(k)], gravity_);
    }
  }

  // Weight support on the stance leg's knee and the joints between it and the foot
  // (Jacobian transpose of an upward force M g on the COM, the foot as the base:
  // tau_j = -a_j . ((c - p_j) x F)).
  if (config_.stance_support > 0) {
    const double F[3] = {0, 0, config_.stance_support * mass_ * gravity_};
    for (int k : middle_[static_cast<size_t>(stance)]) {
      const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
      const double* a = d->xaxis + 3 * j.joint;
      const double* p = d->xanchor + 3 * j.joint;
      const double r[3] = {com_[0] - p[0], com_[1] - p[1], com_[2] - p[2]};
      double rf[3];
      mju_cross(rf, r, F);
      u_[static_cast<size_t>(k)] -= dot3(a, rf);
    }
  }

  // The stance hip: the root's PD torque plus what the other hinges on the root take away.
  // While the swing foot still touches the ground (double support, early in a lift
  // state) both hips share that torque equally and the swing femur is not tracked.
  auto is_stance_hip = [&](int k) {
    const Kind kind = slots[static_cast<size_t>(k)].kind;
    return kind == Kind::kStanceHip || (double_support && kind == Kind::kSwingHip);
  };
  {
    double target[4], e[3];
    root_target(state_, target);
    rotation_error(target, d->xquat + 4 * root, e);
    double base[3], swing_part[3] = {0, 0, 0};
    for (int i = 0; i < 3; ++i) base[i] = root_kp_ * e[i];
    for (int k : root_children_) {
      if (is_stance_hip(k)) continue;
      const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
      const double tau = std::clamp(u_[static_cast<size_t>(k)] - kd_[static_cast<size_t>(k)] * d->qvel[j.dof],
                                    -j.torque_limit, j.torque_limit);
      const double* a = d->xaxis + 3 * j.joint;
      double* sum = slots[static_cast<size_t>(k)].kind == Kind::kSwingHip ? swing_part : base;
      for (int i = 0; i < 3; ++i) sum[i] += tau * a[i];
    }
    // The root comes first: if the stance hip cannot take the swing hip's reaction on top
    // of the root's torque, the swing hip's torque is scaled down by the largest factor
    // that keeps every stance-hip hinge within its limit (the damping estimated at the
    // current joint rate).
    const double share = double_support ? 0.5 : 1.0;
    double scale = 1;
    for (int k : root_children_) {
      if (!is_stance_hip(k)) continue;
      const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
      const double* a = d->xaxis + 3 * j.joint;
      const double* w_child = d->cvel + 6 * j.body;
      const double fixed = share * (-dot3(a, base) + root_kd_ * dot3(a, w_child) - root_kd_ * d->qvel[j.dof]);
      const double varying = -share * dot3(a, swing_part);
      const double L = j.torque_limit;
      if (std::fabs(fixed + varying) <= L) continue;
      if (std::fabs(fixed) >= L) {
        scale = 0;
      } else {
        // |fixed + s varying| = L at s = (sign(varying) L - fixed) / varying.
        const double bound = ((varying > 0 ? L : -L) - fixed) / varying;
        scale = std::min(scale, std::clamp(bound, 0.0, 1.0));
      }
    }
    for (int k : root_children_) {
      if (slots[static_cast<size_t>(k)].kind != Kind::kSwingHip || is_stance_hip(k)) continue;
      u_[static_cast<size_t>(k)] *= scale;
      kd_[static_cast<size_t>(k)] *= scale;
    }
    for (int k : root_children_) {
      if (!is_stance_hip(k)) continue;
      const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
      const double* a = d->xaxis + 3 * j.joint;
      const double* w_child = d->cvel + 6 * j.body;
      double torque[3];
      for (int i = 0; i < 3; ++i) torque[i] = base[i] + scale * swing_part[i];
      // Root damping -root_kd w_root, by a . w_root = a . w_thigh - qdot: its -qdot part
      // is the hip's own damping, implicit in the drive.
      u_[static_cast<size_t>(k)] = share * (-dot3(a, torque) + root_kd_ * dot3(a, w_child));
      kd_[static_cast<size_t>(k)] = share * root_kd_;
    }
  }
  for (int k = 0; k < n; ++k) drive.set(k, u_[static_cast<size_t>(k)], kd_[static_cast<size_t>(k)]);
}

}  // namespace diverse
