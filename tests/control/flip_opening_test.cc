// Spotting the landing (skills/backflip.toml: the rise ends on `spotted`, the `spotting`
// module with turn = 5.1, control/module_spotting.h): a flip opens when the body, opened
// now, would have turned as far as asked by touch-down, instead of after a fixed rotation
// since take-off. On the backflip's input motion and 32 of its perturbations (sigma 0.02,
// the input-motion check's draws): the perturbed flips touch down at root pitches much
// nearer each other, and more of them meet the task, than the same parameters opened by
// the rotation since take-off (the rise ending on `turned`, angle = 3.3:
// tests/task/data/backflip_open_rotation.skill.toml with the backflip's balance servo).
// Bad values are refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "core/error.h"
#include "support/task_errors.h"
#include "support/skill_variant.h"
#include "support/task_variant.h"
#include "task/evaluate.h"
#include "task/seed_motion.h"
#include "task/task.h"

namespace diverse {
namespace {

const std::string kTasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";

// backflip.toml with `lines` at the top of its [controller] table.
std::string variant(const std::string& name, const std::string& lines) {
  return test_files::task_variant("backflip", "flip_opening_" + name, {}, {{"controller", lines}}).string();
}

// The backflip opened after 3.3 rad of root rotation since take-off, with its servo.
std::string clocked_task() {
  return test_files::task_variant("backflip", "flip_opening_rotation", {"skill ="},
                                  {{"controller", test_files::skill_line("tests/task/data/backflip_open_rotation.skill.toml") +
                                                      "\nbalance = { kp = 4000.0, kd = 800.0, max_force = 800.0 }"}})
      .string();
}

struct Landings {
  int met = 0;
  std::vector<double> pitch;  // rad, the root's pitch at each touch-down
  // The range of the middle 80 % of the touch-down pitches (rad): how far apart the flips
  // come down, the odd perturbation that goes wrong before take-off aside.
  double spread() const {
    std::vector<double> p = pitch;
    std::sort(p.begin(), p.end());
    const size_t cut = p.size() / 10;
    return p[p.size() - 1 - cut] - p[cut];
  }
};

Landings land(const Task& task, const std::vector<Eigen::VectorXd>& xs) {
  const TaskEvaluator ev(task);
  auto worker = ev.make_worker();
  EvaluationOptions o;
  o.samples_per_phase = 0;
  o.half_timestep_check = true;
  Landings out;
  const int pitch = ev.body().root_pitch_qpos;
  for (const Eigen::VectorXd& x : xs) {
    const Evaluation e = ev.evaluate_normalized(x, *worker, o);
    out.met += e.constraint == 0;
    if (e.flight_time.empty()) continue;
    const size_t nq = e.flight_qpos.size() / e.flight_time.size();
    out.pitch.push_back(e.flight_qpos[(e.flight_time.size() - 1) * nq + static_cast<size_t>(pitch)]);
  }
  return out;
}

TEST(FlipOpening, SpotsTheLanding) {
  const Task spotted = load_task(kTasks + "backflip.toml");
  const Task clocked = load_task(clocked_task());
  const TaskEvaluator ev(spotted);
  const ParameterSet m0 = ev.load_parameters(spotted.m0);
  const std::vector<Eigen::VectorXd> xs = perturb(m0.normalized(), 0.02, 32, robustness_seed(spotted, 0.02));
  const Landings a = land(spotted, xs), b = land(clocked, xs);
  ASSERT_EQ(a.pitch.size(), xs.size());
  ASSERT_EQ(b.pitch.size(), xs.size());
  std::printf("touch-down pitch spread (middle 80 %%): spotted %.3f rad (%d of 32 meet the task), turned %.3f rad (%d)\n",
              a.spread(), a.met, b.spread(), b.met);
  EXPECT_LT(a.spread(), 0.6 * b.spread());
  EXPECT_GE(a.met, 16);
  EXPECT_GT(a.met, b.met + 4);
}

TEST(FlipOpening, BadValuesAreRefused) {
  auto refused = [](const std::string& lines, const std::string& expected) {
    test_files::expect_task_refused(variant("bad", lines), expected);
  };
  refused("spotting = { turn = -1 }", "controller.spotting.turn: expected a number in [0, ");
  refused("spotting = { turn = 30 }", "controller.spotting.turn: expected a number in [0, ");
  refused("spotting = { turn = \"late\" }", "controller.spotting.turn: expected a number");
}

}  // namespace
}  // namespace diverse
