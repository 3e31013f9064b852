// A landing that has toppled over the edge of its feet is a fall from that moment
// (TaskSimulation::topple_distance, task/task.h): with both feet down and past the
// landing's first topple_after seconds, the COM and its capture point both more than
// topple_distance outside the soles' outline (sole_outline(), task/support.h). Most of the
// high jump's falls are slow topples over the toes that used to be simulated for a second
// more, until the COM came down to the feet.
#include <gtest/gtest.h>

#include <mujoco/mujoco.h>

#include <string>

#include "core/error.h"
#include "core/thread_pool.h"
#include "task/evaluate.h"
#include "task/seed_motion.h"
#include "task/support.h"
#include "task/task.h"
#include "support/task_variant.h"

namespace diverse {
namespace {

const std::string kTasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";
constexpr const char* kToppled = "toppled over the edge of the feet";

EvaluationOptions plain() {
  EvaluationOptions o;
  o.samples_per_phase = 0;
  return o;
}

// The character standing at the model's qpos0 with both feet on the ground.
struct Standing {
  explicit Standing(const std::string& task_file) : ev(load_task(task_file)), d(mj_makeData(ev.model().get())) {
    mj_forward(ev.model().get(), d);
    contacts.any = true;
    contacts.foot = {true, true};
  }
  ~Standing() { mj_deleteData(d); }
  Standing(const Standing&) = delete;
  Standing& operator=(const Standing&) = delete;
  double margin(double x, double y) const { return sole_outline(ev.model().get(), d, ev.body(), contacts).margin({x, y}); }
  double foot_x(int side) const { return d->xipos[3 * ev.body().feet[static_cast<size_t>(side)]]; }
  TaskEvaluator ev;
  mjData* d;
  ContactState contacts;
};

// The planar human's foot is a capsule from 5 cm behind the ankle to 16 cm ahead of it,
// radius 3 cm: 13.5 cm either side of its middle (the foot's centre of mass).
TEST(SoleMargin, IsTheDistanceToTheEdgeOfThePlanarSoles) {
  const Standing s(kTasks + "jump_high.toml");
  const double middle = s.foot_x(0);
  EXPECT_NEAR(s.margin(middle, 0), 0.135, 1e-6);
  EXPECT_NEAR(s.margin(middle + 0.335, 0), -0.2, 1e-6);  // 20 cm past the toes
  EXPECT_NEAR(s.margin(middle - 0.235, 0), -0.1, 1e-6);  // 10 cm behind the heels
  // A foot in the air is no support; neither foot, none at all.
  ContactState one = s.contacts;
  one.foot = {false, false};
  EXPECT_EQ(sole_outline(s.ev.model().get(), s.d, s.ev.body(), one).margin({middle, 0}), -INFINITY);
}

// The 3D human's feet are boxes 27.4 cm long and 10 cm wide: the outline is the hull of
// both, so a point between the feet is inside and one beside them outside.
TEST(SoleMargin, IsTheDistanceToTheHullOfTheSolesIn3d) {
  const Standing s(kTasks + "jump_backwards.toml");
  const double* left = s.d->geom_xpos + 3 * mj_name2id(s.ev.model().get(), mjOBJ_GEOM, "foot_l");
  const double* right = s.d->geom_xpos + 3 * mj_name2id(s.ev.model().get(), mjOBJ_GEOM, "foot_r");
  const double cx = 0.5 * (left[0] + right[0]), cy = 0.5 * (left[1] + right[1]);
  EXPECT_GT(s.margin(cx, cy), 0.05);
  EXPECT_NEAR(s.margin(cx + 0.137 + 0.1, cy), -0.1, 1e-3);  // 10 cm ahead of the toes
  const double outer = std::max(left[1], right[1]) + 0.05;
  EXPECT_NEAR(s.margin(cx, outer + 0.2), -0.2, 1e-3);  // 20 cm beside the outer edge
}

// Around the high jump's input motion found under the default balance servo
// (tests/task/data/jump_high_default_servo.toml; the steps the optimizer takes early on):
// with the rule, exactly the same perturbations meet the task with the same C, every one
// that fell still falls and none that stood does, most falls end as topples, and those end
// sooner.
TEST(Topple, EndsTheHighJumpsTopplesSoonerAndChangesNoOtherOutcome) {
  Task without = load_task(std::string(DIVERSE_SOURCE_DIR) + "/tests/task/data/jump_high_default_servo.toml");
  without.simulation.topple_distance = 0;
  Task with = without;
  with.simulation.topple_distance = 0.05;
  const TaskEvaluator a(without), b(with);
  const ParameterSet m0 = a.load_parameters(without.m0);
  const int n = 24;
  const auto xs = perturb(m0.normalized(), 0.04, n, 777);
  ThreadPool pool(2);
  std::vector<std::unique_ptr<SimWorker>> wa, wb;
  for (int i = 0; i < 2; ++i) {
    wa.push_back(a.make_worker());
    wb.push_back(b.make_worker());
  }
  std::vector<Evaluation> ea(n), eb(n);
  pool.parallel_for(static_cast<size_t>(n), [&](size_t k, int w) {
    ea[k] = a.evaluate_normalized(xs[k], *wa[static_cast<size_t>(w)], plain());
    eb[k] = b.evaluate_normalized(xs[k], *wb[static_cast<size_t>(w)], plain());
  });
  int met = 0, topples = 0;
  long steps_a = 0, steps_b = 0;
  for (size_t k = 0; k < static_cast<size_t>(n); ++k) {
    EXPECT_EQ(ea[k].fell, eb[k].fell) << k;
    if (!ea[k].fell) {
      EXPECT_EQ(eb[k].constraint, ea[k].constraint) << k;  // simulated exactly as before
      EXPECT_EQ(eb[k].stats.steps, ea[k].stats.steps) << k;
      met += ea[k].constraint == 0;
    }
    if (eb[k].summary.fall_reason == kToppled) {
      ++topples;
      EXPECT_LT(eb[k].stats.steps, ea[k].stats.steps) << k;
      EXPECT_GE(eb[k].summary.end_time - eb[k].phases.landing(), with.simulation.topple_after - 1e-9) << k;
      // ranked as a fall a second or more after touch-down, as a slow topple was
      EXPECT_EQ(eb[k].summary.fall_progress, 1.0) << k;
      EXPECT_GE(eb[k].constraint, with.constraints.fall_penalty) << k;
      EXPECT_LT(eb[k].constraint, 1.1 * with.constraints.fall_penalty) << k;
    }
    steps_a += ea[k].stats.steps;
    steps_b += eb[k].stats.steps;
  }
  EXPECT_GE(met, 6);
  EXPECT_GE(topples, 8);
  EXPECT_LT(static_cast<double>(steps_b), 0.9 * static_cast<double>(steps_a));
}

TEST(Topple, IsReadFromTheTaskAndChecked) {
  const Task plain_task = load_task(kTasks + "jump_high.toml");
  EXPECT_EQ(plain_task.simulation.topple_distance, 0);  // off unless a task asks for it
  EXPECT_DOUBLE_EQ(plain_task.simulation.topple_after, 0.2);
  const Task asked = load_task(
      test_files::task_variant("jump_high", "topple", {}, {{"simulation", "topple_distance = 0.05\ntopple_after = 0.3"}})
          .string());
  EXPECT_DOUBLE_EQ(asked.simulation.topple_distance, 0.05);
  EXPECT_DOUBLE_EQ(asked.simulation.topple_after, 0.3);
  auto refused = [](const std::string& line, const std::string& expected) {
    const auto file = test_files::task_variant("jump_high", "topple_bad", {"topple_distance =", "topple_after ="},
                                               {{"simulation", line}});
    try {
      load_task(file.string());
      ADD_FAILURE() << "expected a UserError for " << line;
    } catch (const UserError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("topple_bad.toml"), std::string::npos) << e.what();
    }
  };
  refused("topple_distance = -0.05", "simulation.topple_distance");
  refused("topple_distance = \"far\"", "simulation.topple_distance");
  refused("topple_after = 9", "simulation.topple_after");
}

}  // namespace
}  // namespace diverse
