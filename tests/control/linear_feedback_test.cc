// The linear_feedback module (control/module_linear_feedback.h) and the features a skill
// names (control/skill_feature.h): the selected joints' targets are offset by gain (f -
// reference) within +-limit, every step or held from the phase's first; at gain 0 a
// rollout is the one without the module, bit for bit; a free root's pitch and pitch rate
// are measured in the heading frame, and `on = "turned"` is refused for a free root.
#include <gtest/gtest.h>

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "control/skill_controller.h"
#include "control/skill_feature.h"
#include "core/error.h"
#include "physics/rollout.h"
#include "support/text_files.h"
#include "task/evaluate.h"
#include "tiny_biped.h"

namespace diverse {
namespace {

const std::string kRoot = DIVERSE_SOURCE_DIR;

// A one-phase skill for the tiny biped: knees at -1.4 at once, the feedback module on.
std::string one_phase(const std::string& module) {
  return R"(name = "feedback"
root = "planar"
pairs = ["hip", "knee", "ankle"]
[targets.bent]
knee = -1.4
other = 0.0
[[modules]]
name = "fb"
kind = "linear_feedback"
)" + module + R"(
[[phases]]
name = "only"
targets = "bent"
modules = ["fb"]
)";
}

struct Probe {
  TaskEvaluator ev;
  std::unique_ptr<SimWorker> w;
  std::unique_ptr<Controller> c;
  JointDrive drive;
  explicit Probe(const std::string& name, const std::string& module)
      : ev(tiny_biped::task(name, one_phase(module))), w(ev.make_worker()), c(ev.task().controller_type->make(ev.body(), *ev.task().controller_config, {})), drive(make_drive(ev.body())) {
    mj_resetData(w->model(), w->data());
    mj_forward(w->model(), w->data());
    c->reset(w->model(), w->data());
  }
  // One control step at the state in the worker; the left knee's target.
  double knee_target() {
    const Character& body = ev.body();
    c->control(w->model(), w->data(), scan_contacts(w->model(), w->data(), body), drive);
    const int knee_l = body.groups[static_cast<size_t>(body.find_group("knee"))].joints[0];
    return dynamic_cast<SkillController&>(*c).targets()[static_cast<size_t>(knee_l)];
  }
  // Raises the body by dz (m) and recomputes the state.
  void raise(double dz) {
    w->data()->qpos[ev.body().root_z_qpos] += dz;
    mj_forward(w->model(), w->data());
  }
  double com_z() const { return c->com()[2]; }
};

TEST(LinearFeedback, OffsetsTheSelectedTargetsByTheFeature) {
  Probe every("fb_every", "feature = \"com_z\"\ntarget = \"knee\"\ngain = -0.5\nreference = 0.2\n");
  const double t0 = every.knee_target();
  const double z0 = every.com_z();
  EXPECT_GT(z0, 0.3);
  EXPECT_NEAR(t0, -1.4 - 0.5 * (z0 - 0.2), 1e-12);
  // Read every step: 10 cm higher, 5 cm... 0.05 rad more bent.
  every.raise(0.1);
  const double t1 = every.knee_target();
  EXPECT_NEAR(t1, -1.4 - 0.5 * (every.com_z() - 0.2), 1e-12);
  EXPECT_NEAR(t1 - t0, -0.05, 1e-9);

  // Held from the phase's first step (sample = 1): raising the body changes nothing.
  Probe held("fb_held", "feature = \"com_z\"\ntarget = \"knee\"\ngain = -0.5\nreference = 0.2\nsample = 1\n");
  const double h0 = held.knee_target();
  held.raise(0.1);
  EXPECT_EQ(held.knee_target(), h0);

  // Within the limit.
  Probe clamped("fb_clamped", "feature = \"com_z\"\ntarget = \"knee\"\ngain = -0.5\nlimit = 0.05\n");
  EXPECT_NEAR(clamped.knee_target(), -1.4 - 0.05, 1e-12);

  // Only the selected groups: the hips keep their target.
  Probe hips("fb_hips", "feature = \"com_z\"\ntarget = \"hip\"\ngain = 1.0\n");
  hips.knee_target();
  const Character& body = hips.ev.body();
  const int hip_l = body.groups[static_cast<size_t>(body.find_group("hip"))].joints[0];
  const int hip_r = body.groups[static_cast<size_t>(body.find_group("hip"))].joints[1];
  const auto& target = dynamic_cast<SkillController&>(*hips.c).targets();
  EXPECT_NEAR(target[static_cast<size_t>(hip_l)], hips.com_z(), 1e-12);
  EXPECT_NEAR(target[static_cast<size_t>(hip_r)], hips.com_z(), 1e-12);
}

// A crouch and a push on the tiny biped (tiny_biped::skill's target sets), with and
// without a feedback module in the push: at gain 0 every recorded state is the same, to
// the last bit; at a gain that bends the knees the jump differs.
TEST(LinearFeedback, AtGainZeroTheRolloutIsTheOneWithoutIt) {
  auto skill = [](const std::string& gain) {
    const std::string module = gain.empty() ? "" : R"(
[[modules]]
name = "fb"
kind = "linear_feedback"
feature = "com_vz"
target = "knee"
gain = )" + gain + "\n";
    const std::string modules = gain.empty() ? "[]" : "[\"fb\"]";
    return tiny_biped::skill(module + R"(
[[phases]]
name = "crouch"
targets = "crouch"
duration = 0.4
next = [{ to = "push", on = "duration" }]
[[phases]]
name = "push"
targets = "push"
interpolate = false
modules = )" + modules + R"(
next = [{ to = "stand", on = "time", after = 0.3 }]
[[phases]]
name = "stand"
targets = "stand"
)");
  };
  auto trace = [&](const std::string& name, const std::string& gain) {
    const TaskEvaluator ev(tiny_biped::task(name, skill(gain)));
    StepRecorder record;
    EvaluationOptions o;
    o.samples_per_phase = 0;
    o.recorder = &record;
    auto w = ev.make_worker();
    ev.evaluate({}, *w, o);
    return record.qpos;
  };
  const auto without = trace("fb_none", "");
  const auto zero = trace("fb_zero", "0.0");
  const auto bent = trace("fb_bent", "-0.3");
  ASSERT_FALSE(without.empty());
  EXPECT_EQ(zero, without);
  EXPECT_NE(bent, without);
}

// A free root (the 3D human) pitched back by 0.3 rad after a turn of 1 rad about the
// vertical: pitch 0.3; turning backwards at 2 rad/s: pitch rate 2.
TEST(SkillFeature, AFreeRootsPitchIsInTheHeadingFrame) {
  const TaskEvaluator ev(load_task(kRoot + "/tasks/jump_backwards.toml"));
  const Character& body = ev.body();
  auto w = ev.make_worker();
  const mjModel* m = w->model();
  mjData* d = w->data();
  mj_resetData(m, d);
  double yaw[4], pitch[4], q[4];
  const double up[3] = {0, 0, 1}, lateral[3] = {0, 1, 0};
  mju_axisAngle2Quat(yaw, up, 1.0);
  mju_axisAngle2Quat(pitch, lateral, -0.3);  // about +y tips the top forward: -0.3 is back
  mju_mulQuat(q, yaw, pitch);
  double* root = d->qpos + body.root_qpos + 3;
  double standing[4];
  mju_copy4(standing, root);
  mju_mulQuat(root, q, standing);
  // Angular velocity about the heading's -y (backwards), in the root's own frame.
  double world_w[3] = {std::sin(1.0) * 2.0, -std::cos(1.0) * 2.0, 0.0}, local_w[3];
  double inv[4];
  mju_negQuat(inv, root);
  mju_rotVecQuat(local_w, world_w, inv);
  for (int k = 0; k < 3; ++k) d->qvel[body.root_dof + 3 + k] = local_w[k];
  mj_forward(m, d);
  const std::array<double, 3> zero{};
  EXPECT_NEAR(skill_feature(SkillFeature::kPitch, body, m, d, zero, zero), 0.3, 1e-9);
  EXPECT_NEAR(skill_feature(SkillFeature::kPitchRate, body, m, d, zero, zero), 2.0, 1e-9);
}

TEST(SkillFeature, TurnedIsRefusedForAFreeRoot) {
  const TaskEvaluator ev(load_task(kRoot + "/tasks/jump_backwards.toml"));
  std::string text = test_files::read_text(kRoot + "/skills/jump3d.toml");
  const std::string from = "{ to = \"fall\", on = \"peak\" }";
  text.replace(text.find(from), from.size(), "{ to = \"fall\", on = \"turned\", angle = 0.5 }");
  const std::string file = tiny_biped::write_skill("turned_free", text);
  try {
    bind_skill(load_skill_file(file), ev.body(), ev.model().get());
    ADD_FAILURE() << "accepted on = \"turned\" for a free root";
  } catch (const UserError& e) {
    const std::string all = test_files::read_text(file);
    const int line = 1 + static_cast<int>(std::count(all.begin(), all.begin() + static_cast<long>(all.find("on = \"turned\"")), '\n'));
    EXPECT_EQ(std::string(e.what()), file + ": line " + std::to_string(line) +
                                         ": phases.rise.next.on: expected a planar root for on = \"turned\" (the root's pitch "
                                         "coordinate), but the character " + ev.body().spec->file +
                                         " has a free root: use on = \"feature\", feature = \"pitch\"");
  }
}

}  // namespace
}  // namespace diverse
