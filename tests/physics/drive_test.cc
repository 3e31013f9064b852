// Joint drives (physics/drive.h): the net torque, motor plus the implicit damper on the
// end-of-step velocity, stays within each joint's limit at every step through impacts,
// where applying the damping the old way (ctrl = clamp(tau) + kd qdot_t, dof_damping = kd)
// exceeds it; a rollout with integrations redone replays bit for bit in plain MuJoCo; far
// from the limits the drive is plain implicit PD; and check_net_torque() gives the
// closed-form answer on a sliding block.
#include "physics/drive.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "physics/model.h"
#include "physics/rollout.h"

namespace diverse {
namespace {

const std::string kHuman = std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/human2d.xml";

// A horizontal arm held by a stiff, heavily damped PD; a 5 kg box falls on its tip.
// The impact changes the arm's velocity within one step, which an implicit damper of
// kd = 200 Nm s/rad turns into a torque far beyond the motor's 20 Nm.
constexpr const char* kArmHitByBox = R"(
<mujoco>
  <option timestep="0.002" integrator="Euler"/>
  <worldbody>
    <geom type="plane" size="5 5 0.1"/>
    <body pos="0 0 1">
      <joint name="shoulder" type="hinge" axis="0 -1 0" range="-1.2 1.2" limited="true"/>
      <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.03" mass="1"/>
    </body>
    <body pos="0.45 0 1.8">
      <freejoint/>
      <geom type="box" size="0.05 0.05 0.05" mass="5"/>
    </body>
  </worldbody>
  <actuator>
    <motor joint="shoulder" forcelimited="true" forcerange="-20 20"/>
  </actuator>
</mujoco>)";

// A two-link arm swung by its shoulder and elbow into a heavy box standing in its way.
constexpr const char* kTwoLinkArm = R"(
<mujoco>
  <option timestep="0.002" integrator="Euler"/>
  <worldbody>
    <geom type="plane" size="5 5 0.1"/>
    <geom type="box" pos="0.55 0 0.6" size="0.1 0.1 0.6" solref="0.004 1"/>
    <body pos="0 0 1.2">
      <joint name="shoulder" type="hinge" axis="0 -1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.04" mass="2"/>
      <body pos="0 0 -0.4">
        <joint name="elbow" type="hinge" axis="0 -1 0" range="-2.5 2.5" limited="true"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.035" mass="1.5"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor joint="shoulder" forcelimited="true" forcerange="-80 80"/>
    <motor joint="elbow" forcelimited="true" forcerange="-40 40"/>
  </actuator>
</mujoco>)";

// The qpos address of each driven joint.
std::vector<int> qpos_of(const mjModel* m, const std::vector<DrivenJoint>& joints) {
  std::vector<int> out;
  for (const DrivenJoint& j : joints) out.push_back(m->jnt_qposadr[m->dof_jntid[j.dof]]);
  return out;
}

// PD toward fixed targets: u = kp (target - q), damping kd.
struct Pd {
  std::vector<double> target, kp, kd;
};

// The drive's way: the hooks set requests, the drive applies them.
class DrivenPd : public StepHooks {
 public:
  DrivenPd(const mjModel* m, JointDrive* drive, Pd pd)
      : drive_(drive), qpos_(qpos_of(m, drive->joints())), pd_(std::move(pd)) {}
  void control(mjModel*, mjData* d) override {
    for (int k = 0; k < drive_->size(); ++k) {
      const size_t i = static_cast<size_t>(k);
      drive_->set(k, pd_.kp[i] * (pd_.target[i] - d->qpos[qpos_[i]]), pd_.kd[i]);
    }
  }
  bool observe(const mjModel*, const mjData*) override { return false; }

 private:
  JointDrive* drive_;
  std::vector<int> qpos_;
  Pd pd_;
};

// The old way: the clamped PD torque with the damping added back to the motor, the
// damping itself implicit in dof_damping (so the motor and damper need not cancel).
// `clamp` false gives plain implicit PD: ctrl = u, dof_damping = kd.
class OldPd : public StepHooks {
 public:
  OldPd(const mjModel* m, std::vector<DrivenJoint> joints, Pd pd, bool clamp)
      : joints_(std::move(joints)), qpos_(qpos_of(m, joints_)), pd_(std::move(pd)), clamp_(clamp) {}
  void control(mjModel* m, mjData* d) override {
    for (size_t k = 0; k < joints_.size(); ++k) {
      const DrivenJoint& j = joints_[k];
      const double u = pd_.kp[k] * (pd_.target[k] - d->qpos[qpos_[k]]);
      const double qd = d->qvel[j.dof];
      d->ctrl[j.actuator] = clamp_ ? std::clamp(u - pd_.kd[k] * qd, -j.limit, j.limit) + pd_.kd[k] * qd : u;
      m->dof_damping[j.dof] = pd_.kd[k];
    }
  }
  bool observe(const mjModel*, const mjData*) override { return false; }
  std::vector<int> dofs() const {
    std::vector<int> out;
    for (const DrivenJoint& j : joints_) out.push_back(j.dof);
    return out;
  }

 private:
  std::vector<DrivenJoint> joints_;
  std::vector<int> qpos_;
  Pd pd_;
  bool clamp_;
};

// One scene: a model, PD gains and an initial state.
struct Scene {
  std::shared_ptr<const SharedModel> model;
  Pd pd;
  std::vector<double> qpos0, qvel0;  // empty: the model's qpos0, zero velocity
};

void set_initial_state(const Scene& s, SimWorker& w) {
  w.reset();
  mjData* d = w.data();
  if (!s.qpos0.empty()) std::copy(s.qpos0.begin(), s.qpos0.end(), d->qpos);
  if (!s.qvel0.empty()) std::copy(s.qvel0.begin(), s.qvel0.end(), d->qvel);
}

struct Outcome {
  RolloutStats stats;
  StepRecorder record;
  JointDrive::Counts counts;
  NetTorqueCheck check;  // on a fresh copy of the model, as `diverse replay` does
  double replay_diff = -1;
};

// Replays the record on fresh model copies: the net-torque check and the qpos difference.
void replay_checks(const Scene& s, Outcome* o) {
  mjModel* m = mj_copyModel(nullptr, s.model->get());
  o->check = check_net_torque(m, o->record, driven_joints(s.model->get()));
  mj_deleteModel(m);
  m = mj_copyModel(nullptr, s.model->get());
  o->replay_diff = replay(m, o->record);
  mj_deleteModel(m);
}

Outcome run_driven(const Scene& s, int steps, SaturatedDrive saturated = SaturatedDrive::kExplicit,
                   Damping damping = Damping::kMujoco) {
  SimWorker worker(s.model);
  set_initial_state(s, worker);
  JointDrive drive(driven_joints(s.model->get()), saturated, damping);
  DrivenPd hooks(worker.model(), &drive, s.pd);
  Outcome o;
  o.stats = run_rollout(worker, hooks, steps, drive, &o.record);
  o.counts = drive.counts();
  replay_checks(s, &o);
  return o;
}

Outcome run_old(const Scene& s, int steps, bool clamp) {
  SimWorker worker(s.model);
  set_initial_state(s, worker);
  OldPd hooks(worker.model(), driven_joints(s.model->get()), s.pd, clamp);
  Outcome o;
  o.stats = run_rollout(worker, hooks, steps, hooks.dofs(), &o.record);
  replay_checks(s, &o);
  return o;
}

Scene arm_hit_by_box() {
  Scene s{SharedModel::from_xml(kArmHitByBox, "arm_hit_by_box"), {{0}, {200}, {200}}, {}, {}};
  return s;
}

Scene two_link_arm() {
  Scene s{SharedModel::from_xml(kTwoLinkArm, "two_link_arm"), {{2.0, 0.3}, {800, 400}, {120, 60}}, {}, {}};
  return s;
}

// The planar human dropped from 0.4 m onto its feet, held by PD in a slight crouch.
Scene human_drop() {
  Scene s{SharedModel::from_file(kHuman), {}, {}, {}};
  const mjModel* m = s.model->get();
  s.qpos0.assign(m->qpos0, m->qpos0 + m->nq);
  s.qpos0[static_cast<size_t>(m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, "rootz")])] = 0.4;
  for (const DrivenJoint& j : driven_joints(m)) {
    const char* name = mj_id2name(m, mjOBJ_JOINT, m->dof_jntid[j.dof]);
    const std::string n = name;
    double target = 0;
    if (n.rfind("hip", 0) == 0) target = 0.4;
    if (n.rfind("knee", 0) == 0) target = -0.8;
    if (n.rfind("ankle", 0) == 0) target = 0.4;
    s.pd.target.push_back(target);
    s.pd.kp.push_back(4 * j.limit);
    s.pd.kd.push_back(0.4 * j.limit);
  }
  return s;
}

void print(const char* what, const Outcome& o) {
  std::printf("%-28s steps %4d  worst excess %+8.4f at step %4d joint %d  over 1%%: %4d  "
              "redone %ld (redos %ld, all explicit %ld)  replay diff %g\n",
              what, o.stats.steps, o.check.worst_excess, o.check.worst_step, o.check.worst_joint,
              o.check.steps_over_1_percent, o.counts.redone_steps, o.counts.redos,
              o.counts.all_explicit_steps, o.replay_diff);
}

// (a) The net torque stays within the limit through the impacts, exactly; the old way
// exceeds it on the same scenes (so this test fails without the drive).
TEST(JointDrive, NetTorqueHoldsThroughImpactsWhereTheOldWayExceedsIt) {
  const Scene scenes[] = {arm_hit_by_box(), two_link_arm(), human_drop()};
  const char* names[] = {"arm hit by box", "two-link arm into box", "human dropped"};
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE(names[i]);
    const Outcome old = run_old(scenes[i], 600, true);
    const Outcome driven = run_driven(scenes[i], 600);
    print((std::string(names[i]) + ", old").c_str(), old);
    print((std::string(names[i]) + ", drive").c_str(), driven);
    ASSERT_FALSE(old.stats.unstable) << old.stats.instability;
    ASSERT_FALSE(driven.stats.unstable) << driven.stats.instability;
    EXPECT_GT(old.check.worst_excess, 0.05);
    EXPECT_GT(old.check.steps_over_1_percent, 0);
    EXPECT_EQ(driven.check.steps, 600);
    EXPECT_LE(driven.check.worst_excess, 0.0);
    EXPECT_EQ(driven.check.steps_over_1_percent, 0);
    // The recorder's own torques say the same: motor plus the damper on the
    // end-of-step velocity.
    const std::vector<DrivenJoint> joints = driven_joints(scenes[i].model->get());
    const StepRecorder& r = driven.record;
    for (int step = 0; step < r.steps(); ++step) {
      for (size_t k = 0; k < joints.size(); ++k) {
        const double net = r.actuator_force[static_cast<size_t>(step * r.nu + joints[k].actuator)] +
                           r.damping_force[static_cast<size_t>(step * r.ndamp) + k];
        ASSERT_LE(std::fabs(net), joints[k].limit) << "step " << step << " joint " << k;
      }
    }
  }
}

// (b) Steps integrated more than once replay bit for bit with plain mj_step and the
// recorded final ctrl and dof_damping.
TEST(JointDrive, RedoneStepsReplayExactly) {
  const Scene scenes[] = {arm_hit_by_box(), two_link_arm(), human_drop()};
  long redone = 0;
  for (const Scene& s : scenes) {
    const Outcome o = run_driven(s, 600);
    EXPECT_EQ(o.replay_diff, 0.0);
    redone += o.counts.redone_steps;
  }
  EXPECT_GT(redone, 0);
  // Each scene on its own too: the arm's impact needs a redo.
  EXPECT_GT(run_driven(arm_hit_by_box(), 600).counts.redone_steps, 0);
}

// (c) Far from the limits the drive is plain implicit PD (ctrl = u, dof_damping = kd),
// bit for bit, and never integrates twice.
TEST(JointDrive, FarFromTheLimitsItIsPlainImplicitPd) {
  Scene s = arm_hit_by_box();
  std::string xml = kArmHitByBox;
  xml.replace(xml.find("-20 20"), 6, "-1e6 1e6");
  s.model = SharedModel::from_xml(xml, "arm_hit_by_box_strong");
  const Outcome driven = run_driven(s, 600);
  const Outcome plain = run_old(s, 600, false);
  EXPECT_EQ(driven.counts.redos, 0);
  ASSERT_EQ(driven.record.qpos.size(), plain.record.qpos.size());
  EXPECT_EQ(driven.record.qpos, plain.record.qpos);
  EXPECT_EQ(driven.record.ctrl, plain.record.ctrl);
}

// (d) A saturated swing at flight gains: an arm in zero gravity driven towards a target a
// radian away with kd h / I = 4.8 (beyond explicit damping's stability bound of 2). The
// spring part stays beyond the 20 Nm limit all the way, so every step is applied
// explicitly: with the damper on qdot_t the net torque flips between the limit and the
// other way step after step (it still closes on the target on average); with the damper on the predicted
// end-of-step velocity (SaturatedDrive::kStablePd) it swings over and settles at the
// target, within the limit and replaying exactly.
TEST(JointDrive, StablePdKeepsASaturatedSwingFromChattering) {
  constexpr const char* kFreeArm = R"(
<mujoco>
  <option timestep="0.002" integrator="Euler" gravity="0 0 0"/>
  <worldbody>
    <body pos="0 0 1">
      <joint name="shoulder" type="hinge" axis="0 -1 0"/>
      <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.03" mass="1"/>
    </body>
  </worldbody>
  <actuator>
    <motor joint="shoulder" forcelimited="true" forcerange="-20 20"/>
  </actuator>
</mujoco>)";
  const Scene s{SharedModel::from_xml(kFreeArm, "free_arm"), {{1.0}, {400}, {200}}, {}, {}};
  // The arm's inertia about the shoulder: kd h / I must be beyond 2 for the test to mean it.
  {
    SimWorker w(s.model);
    mj_forward(w.model(), w.data());
    ASSERT_GT(200 * 0.002 / w.data()->qM[0], 2.0);
  }
  const int qadr = s.model->get()->jnt_qposadr[0];
  auto sign_flips = [](const Outcome& o) {
    int flips = 0;
    for (int step = 1; step < o.record.steps(); ++step) {
      const double a = o.record.actuator_force[static_cast<size_t>(step - 1)];
      const double b = o.record.actuator_force[static_cast<size_t>(step)];
      if (a * b < 0 && std::fabs(a - b) > 20) ++flips;  // a jump across more than the limit
    }
    return flips;
  };
  // 4 s: overdamped (kp / kd = 2 / s), the arm closes on the target as 1 - e^{-2 t}.
  const Outcome plain = run_driven(s, 2000, SaturatedDrive::kExplicit);
  const Outcome stable = run_driven(s, 2000, SaturatedDrive::kStablePd);
  print("free arm, explicit", plain);
  print("free arm, stable PD", stable);
  const double q_plain = plain.record.qpos[static_cast<size_t>((plain.record.steps() - 1) * plain.record.nq + qadr)];
  const double q_stable = stable.record.qpos[static_cast<size_t>((stable.record.steps() - 1) * stable.record.nq + qadr)];
  std::printf("sign flips across the limit: explicit %d, stable PD %d; final q %.4f / %.4f\n",
              sign_flips(plain), sign_flips(stable), q_plain, q_stable);
  EXPECT_GT(sign_flips(plain), 100);
  EXPECT_EQ(sign_flips(stable), 0);
  EXPECT_NEAR(q_stable, 1.0, 0.01);
  EXPECT_EQ(stable.check.steps, 2000);
  EXPECT_LE(stable.check.worst_excess, 0.0);
  EXPECT_EQ(stable.replay_diff, 0.0);
}

// A heavy trunk on a hip above a light leg that a weld holds to the world (no gravity),
// as a push-off's floor holds the feet: the hip meets the trunk's inertia, about 5 kg m^2,
// but with the leg free its inertia is the leg's, a few hundredths. MuJoCo's implicit
// damping, and the stable PD of a saturated request, divide the hip's damped request by
// 1 + h kd / I_free, about 17 here at 2 ms, so the trunk swings far slower at 2 ms than
// at a fine step; under Damping::kConstrained the damper meets the welded inertia and the
// swing at 2 ms is nearly the swing at 0.0625 ms. Both keep the net torque within the
// limit and replay exactly.
TEST(JointDrive, ConstrainedDampingMeetsTheInertiaTheContactsLeave) {
  constexpr const char* kWeldedLeg = R"(
<mujoco>
  <option timestep="0.002" integrator="Euler" gravity="0 0 0"/>
  <worldbody>
    <body name="leg" pos="0 0 1">
      <joint name="x" type="slide" axis="1 0 0"/>
      <joint name="z" type="slide" axis="0 0 1"/>
      <joint name="pitch" type="hinge" axis="0 -1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.8" size="0.03" mass="0.5"/>
      <body name="trunk">
        <joint name="hip" type="hinge" axis="0 -1 0"/>
        <geom type="capsule" fromto="0 0 0 0 0 0.7" size="0.1" mass="30"/>
      </body>
    </body>
  </worldbody>
  <equality>
    <weld body1="leg"/>
  </equality>
  <actuator>
    <motor joint="hip" forcelimited="true" forcerange="-300 300"/>
  </actuator>
</mujoco>)";
  // 1.5 rad away, kp 400, kd 200: the spring part (600 Nm) is beyond the limit (300 Nm),
  // so the request is saturated and MuJoCo's way applies it by stable PD on the free
  // inertia (SaturatedDrive::kStablePd, as the backflip's push-off does); the welded trunk
  // closes on the target overdamped.
  auto scene_at = [&](double h) {
    std::string xml = kWeldedLeg;
    xml.replace(xml.find("0.002"), 5, std::to_string(h));
    return Scene{SharedModel::from_xml(xml, "welded_leg"), {{1.5}, {400}, {200}}, {}, {}};
  };
  const int hip = 3;  // qpos address of the hip
  // The hip angle at t = 0.2, 0.4, ..., 1.0 s.
  auto angles = [&](double h, Damping damping) {
    const Scene s = scene_at(h);
    const int per = static_cast<int>(std::lround(0.2 / h));
    const Outcome o = run_driven(s, 5 * per, SaturatedDrive::kStablePd, damping);
    EXPECT_EQ(o.check.steps, 5 * per);
    EXPECT_LE(o.check.worst_excess, 0.0);
    EXPECT_EQ(o.replay_diff, 0.0);
    std::vector<double> q;
    for (int k = 1; k <= 5; ++k)
      q.push_back(o.record.qpos[static_cast<size_t>((k * per - 1) * o.record.nq + hip)]);
    return q;
  };
  const std::vector<double> reference = angles(0.0000625, Damping::kConstrained);
  const std::vector<double> reference_mujoco = angles(0.0000625, Damping::kMujoco);
  const std::vector<double> mujoco = angles(0.002, Damping::kMujoco);
  const std::vector<double> constrained = angles(0.002, Damping::kConstrained);
  double worst_mujoco = 0, worst_constrained = 0, fine_apart = 0;
  for (size_t k = 0; k < reference.size(); ++k) {
    std::printf("t %.1f s: hip %.4f rad at 0.0625 ms (MuJoCo's damping %.4f); at 2 ms MuJoCo's %.4f, constrained %.4f\n",
                0.2 * static_cast<double>(k + 1), reference[k], reference_mujoco[k], mujoco[k], constrained[k]);
    worst_mujoco = std::max(worst_mujoco, std::fabs(mujoco[k] - reference[k]));
    worst_constrained = std::max(worst_constrained, std::fabs(constrained[k] - reference[k]));
    fine_apart = std::max(fine_apart, std::fabs(reference_mujoco[k] - reference[k]));
    EXPECT_LT(reference[k], 1.5) << "overdamped: no overshoot";
  }
  EXPECT_LT(fine_apart, 0.01) << "the two ways agree at a fine step";
  // Measured: 0.177 and 0.013 rad (at 0.2 s: 0.262 and 0.426 against 0.439).
  EXPECT_GT(worst_mujoco, 0.1) << "stable PD on the free inertia at 2 ms is off the converged swing";
  EXPECT_LT(worst_constrained, 0.02);
}

// Under Damping::kConstrained every joint's torque is the solution of its own equation,
// tau_k = u_k - kd_k c_k (qdot + h x),  H x = S^T tau,  H = M + J^T R^-1 J,
// or is held at its limit. Checked here independently of how the drive solves it (one
// factorization and a rank-one update per held joint): the planar human limp after a drop
// onto its feet, standing, toppling and lying on the floor, requests drawn so that several joints saturate, some with
// their damper on a sum of velocities (a link's world pitch rate) as the jump controller
// asks.
TEST(JointDrive, ConstrainedTorquesSolveTheirEquationsOrAreHeldAtTheirLimits) {
  const Scene s = human_drop();
  SimWorker worker(s.model);
  set_initial_state(s, worker);
  mjModel* m = worker.model();
  mjData* d = worker.data();
  const std::vector<DrivenJoint> joints = driven_joints(m);
  const int n = static_cast<int>(joints.size()), nv = m->nv;
  ASSERT_FALSE(mj_isSparse(m));
  for (int i = 0; i < 400; ++i) mj_step(m, d);  // fallen: feet, knees or trunk on the floor
  unsigned state = 12345;
  auto uniform = [&state] {  // deterministic, in [0, 1)
    state = state * 1664525u + 1013904223u;
    return static_cast<double>(state >> 8) / 16777216.0;
  };
  int held = 0, free = 0, with_rows = 0, contact_trials = 0;
  for (int trial = 0; trial < 60; ++trial) {
    mj_step1(m, d);
    if (d->nefc == 0) {  // in the air for a moment: nothing held
      mj_step2(m, d);
      continue;
    }
    ++contact_trials;
    JointDrive drive(joints, SaturatedDrive::kExplicit, Damping::kConstrained);
    std::vector<std::vector<DampedDof>> rows(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k) {
      const double limit = joints[static_cast<size_t>(k)].limit;
      const double u = (2 * uniform() - 1) * 1.6 * limit, kd = 0.5 * limit * uniform();
      if (trial % 2 == 1 && k % 3 == 0) {
        // the world pitch rate of the link below: root pitch plus the joints above it
        rows[static_cast<size_t>(k)] = {{2, 1.0}, {joints[static_cast<size_t>(k)].dof, 1.0}};
        if (k > 0) rows[static_cast<size_t>(k)].push_back({joints[static_cast<size_t>(k - 1)].dof, -0.5});
        drive.set(k, u, kd, rows[static_cast<size_t>(k)]);
        ++with_rows;
      } else {
        drive.set(k, u, kd);
      }
    }
    drive.apply(m, d);
    // H and x = H^-1 S^T tau, from the step's constraint rows.
    Eigen::MatrixXd H(nv, nv);
    mj_fullM(m, H.data(), d->qM);
    for (int i = 0; i < d->nefc; ++i)
      for (int a = 0; a < nv; ++a)
        for (int b = 0; b < nv; ++b)
          H(a, b) += d->efc_J[i * nv + a] * d->efc_J[i * nv + b] / d->efc_R[i];
    Eigen::VectorXd torque = Eigen::VectorXd::Zero(nv);
    for (int k = 0; k < n; ++k) torque[joints[static_cast<size_t>(k)].dof] = d->ctrl[joints[static_cast<size_t>(k)].actuator];
    const Eigen::VectorXd x = H.ldlt().solve(torque);
    for (int k = 0; k < n; ++k) {
      const DrivenJoint& j = joints[static_cast<size_t>(k)];
      std::vector<DampedDof> c = rows[static_cast<size_t>(k)];
      if (c.empty()) c = {{j.dof, 1.0}};
      double velocity = 0, change = 0;
      for (const DampedDof& t : c) {
        velocity += t.weight * d->qvel[t.dof];
        change += t.weight * x[t.dof];
      }
      const double tau = d->ctrl[j.actuator];
      const double own = drive.u(k) - drive.kd(k) * (velocity + m->opt.timestep * change);
      EXPECT_LE(std::fabs(tau), j.limit) << "joint " << k;
      EXPECT_EQ(m->dof_damping[j.dof], 0.0);
      if (std::fabs(tau) == j.limit) {
        ++held;
      } else {
        ++free;
        EXPECT_NEAR(tau, own, 1e-9 * j.limit) << "trial " << trial << " joint " << k;
      }
    }
    // On to another lying pose: a few steps without the drawn requests.
    for (int k = 0; k < n; ++k) d->ctrl[joints[static_cast<size_t>(k)].actuator] = 0;
    for (int i = 0; i < 5; ++i) mj_step(m, d);
  }
  std::printf("%d steps with contacts: %d joint-steps held at their limit, %d solved, %d with a damped sum\n",
              contact_trials, held, free, with_rows);
  EXPECT_GT(contact_trials, 30);
  EXPECT_GT(held, 40);
  EXPECT_GT(free, 40);
}

// (e) A 1 kg block on a slide joint, no gravity: the Euler step solves
// (m + h kd) a = ctrl - kd v0, and the net force motor + damper is m a.
TEST(CheckNetTorque, SlidingBlockHasTheClosedFormNetForce) {
  constexpr const char* kBlock = R"(
<mujoco>
  <option timestep="0.01" integrator="Euler" gravity="0 0 0"/>
  <worldbody>
    <body>
      <joint name="slide" type="slide" axis="1 0 0"/>
      <geom type="sphere" size="0.1" mass="1" contype="0" conaffinity="0"/>
    </body>
  </worldbody>
  <actuator><motor joint="slide" forcelimited="true" forcerange="-1 1"/></actuator>
</mujoco>)";
  auto model = SharedModel::from_xml(kBlock, "block");
  const std::vector<DrivenJoint> joints = driven_joints(model->get());
  ASSERT_EQ(joints.size(), 1u);
  EXPECT_EQ(joints[0].actuator, 0);
  EXPECT_EQ(joints[0].dof, 0);
  EXPECT_EQ(joints[0].limit, 1.0);

  StepRecorder r;
  r.nq = 1;
  r.nu = 1;
  r.ndamp = 1;
  r.timestep = 0.01;
  r.qpos0 = {0};
  r.qvel0 = {-1};
  r.damped_dofs = {0};
  // Step 0: ctrl 1 against v0 = -1 with kd = 2: a = (1 + 2) / (1 + 0.02), net 3 / 1.02,
  // 194 % over the 1 N limit. Step 1: no damping, ctrl 0.5: net 0.5, 50 % under.
  r.damping = {{0, {2.0}}, {1, {0.0}}};
  r.ctrl = {1.0, 0.5};
  mjModel* m = mj_copyModel(nullptr, model->get());
  const NetTorqueCheck c = check_net_torque(m, r, joints);
  mj_deleteModel(m);
  EXPECT_EQ(c.steps, 2);
  EXPECT_FALSE(c.blew_up);
  EXPECT_NEAR(c.worst_torque, 3 / 1.02, 1e-12);
  EXPECT_NEAR(c.worst_excess, 3 / 1.02 - 1, 1e-12);
  EXPECT_EQ(c.worst_step, 0);
  EXPECT_EQ(c.worst_joint, 0);
  EXPECT_EQ(c.steps_over_1_percent, 1);

  // Only step 1: within the limit, the worst excess is 0.5 / 1 - 1.
  r.damping = {{0, {0.0}}};
  r.ctrl = {0.5};
  m = mj_copyModel(nullptr, model->get());
  const NetTorqueCheck within = check_net_torque(m, r, joints);
  mj_deleteModel(m);
  EXPECT_NEAR(within.worst_excess, -0.5, 1e-12);
  EXPECT_EQ(within.steps_over_1_percent, 0);
}

// Only plain motors with gear 1 and a symmetric force limit on a hinge or slide joint
// that nothing else drives count as driven joints.
TEST(DrivenJoints, FromActuatorsAlone) {
  constexpr const char* kMixed = R"(
<mujoco>
  <worldbody>
    <body><joint name="a" type="hinge"/><geom size="0.1" mass="1"/></body>
    <body><joint name="b" type="hinge"/><geom size="0.1" mass="1"/></body>
    <body><joint name="c" type="hinge"/><geom size="0.1" mass="1"/></body>
    <body><joint name="d" type="slide"/><geom size="0.1" mass="1"/></body>
    <body><joint name="e" type="hinge"/><geom size="0.1" mass="1"/></body>
    <body><joint name="f" type="ball"/><geom size="0.1" mass="1"/></body>
    <body><joint name="g" type="hinge"/><geom size="0.1" mass="1"/></body>
    <body><joint name="h" type="hinge"/><geom size="0.1" mass="1"/></body>
  </worldbody>
  <actuator>
    <motor joint="a" forcelimited="true" forcerange="-30 30"/>
    <motor joint="b" gear="2" forcelimited="true" forcerange="-30 30"/>
    <motor joint="c" forcelimited="true" forcerange="-20 30"/>
    <motor joint="d" forcelimited="true" forcerange="-5 5"/>
    <motor joint="e"/>
    <motor joint="f" forcelimited="true" forcerange="-30 30"/>
    <position joint="g" kp="10" forcelimited="true" forcerange="-30 30"/>
    <motor joint="h" forcelimited="true" forcerange="-30 30"/>
    <motor joint="h" forcelimited="true" forcerange="-30 30"/>
  </actuator>
</mujoco>)";
  auto model = SharedModel::from_xml(kMixed, "mixed");
  const mjModel* m = model->get();
  const std::vector<DrivenJoint> joints = driven_joints(m);
  ASSERT_EQ(joints.size(), 2u);
  EXPECT_EQ(joints[0].actuator, 0);
  EXPECT_EQ(joints[0].dof, m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, "a")]);
  EXPECT_EQ(joints[0].limit, 30.0);
  EXPECT_EQ(joints[1].actuator, 3);
  EXPECT_EQ(joints[1].dof, m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, "d")]);
  EXPECT_EQ(joints[1].limit, 5.0);

  // The planar human: its 16 hinge motors, with the limits of SPEC section 3.
  auto human = SharedModel::from_file(kHuman);
  const std::vector<DrivenJoint> body = driven_joints(human->get());
  ASSERT_EQ(body.size(), 16u);
  for (const DrivenJoint& j : body) {
    EXPECT_TRUE(j.limit == 300 || j.limit == 200 || j.limit == 50) << j.limit;
  }
}

}  // namespace
}  // namespace diverse
