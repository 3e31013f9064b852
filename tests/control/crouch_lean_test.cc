// The crouch that leans in (skills/jump_forward.toml: the crouch's balance module `lean`,
// control/module_balance.h, with lean = 0.2): in the crouch the balance servo leads the COM
// along a lean instead of holding it over the feet. On jump_forward's input motion: pushed by 0.3 m/s forward or backward at four moments of
// its crouch, it still lands in its box and stands in 6 of the eight rollouts (measured:
// the forward pushes but the latest, which lands 4 cm past the box, and the backward
// ones but the earliest, which lands short and falls), where the input
// motion found before it without the lean (tests/control/data/jump_forward.no_lean.m0.json,
// under the task with lean = 0, the COM held over the feet) holds none, and its take-off speed stays nearer its own
// unpushed one. Bad values are refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "support/task_errors.h"
#include "support/task_variant.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {
namespace {

EvaluationOptions judged() {
  EvaluationOptions o;
  o.samples_per_phase = 0;
  o.half_timestep_check = true;
  return o;
}

// The COM's forward speed at take-off (m/s), from the first two airborne states.
double takeoff_speed(const TaskEvaluator& ev, const Evaluation& e, SimWorker& worker) {
  const std::size_t nq = static_cast<std::size_t>(ev.model().get()->nq);
  if (e.flight_time.size() < 2) return NAN;
  mjData* d = worker.data();
  const mjModel* m = ev.model().get();
  double x[2];
  for (int k = 0; k < 2; ++k) {
    for (std::size_t i = 0; i < nq; ++i) d->qpos[i] = e.flight_qpos[static_cast<std::size_t>(k) * nq + i];
    mj_kinematics(m, d);
    mj_comPos(m, d);
    x[k] = d->subtree_com[3 * ev.body().root_body];
  }
  return (x[1] - x[0]) / (e.flight_time[1] - e.flight_time[0]);
}

struct Pushed {
  int held = 0;              // of the eight pushed rollouts, those that meet the task
  double worst_speed = 0;    // the largest change of the take-off speed (m/s)
};

Pushed push_the_crouch(const std::string& task_file, const std::string& parameters) {
  const Task task = load_task(task_file);
  const TaskEvaluator ev(task);
  const ParameterSet p = ev.load_parameters(parameters);
  auto worker = ev.make_worker();
  const Evaluation plain = ev.evaluate(p.values(), *worker, judged());
  EXPECT_EQ(plain.constraint, 0.0) << task_file;
  const double v0 = takeoff_speed(ev, plain, *worker);
  const double crouch = plain.phases.begin[1], extend = plain.phases.begin[2];
  Pushed out;
  for (double dv : {0.3, -0.3}) {
    for (double at : {0.1, 0.3, 0.5, 0.7}) {
      EvaluationOptions o = judged();
      o.push.time = crouch + at * (extend - crouch);
      o.push.dv = {dv, 0, 0};
      const Evaluation e = ev.evaluate(p.values(), *worker, o);
      const double v = takeoff_speed(ev, e, *worker);
      std::printf("  push %+.1f m/s at %.0f %% of the crouch: C %g, touch-down x %.3f m, take-off speed %.3f m/s (%.3f)\n",
                  dv, 100 * at, e.constraint, e.summary.touchdown_feet_x, v, v0);
      out.held += e.constraint == 0 && !e.failed;
      out.worst_speed = std::max(out.worst_speed, std::isfinite(v) ? std::fabs(v - v0) : INFINITY);
    }
  }
  return out;
}

TEST(CrouchLean, APushedCrouchComesBackOntoItsPath) {
  const std::string source = DIVERSE_SOURCE_DIR;
  std::printf("with lean = 0.2:\n");
  const Pushed lean = push_the_crouch(source + "/tasks/jump_forward.toml", source + "/tasks/jump_forward.m0.json");
  const std::string without =
      test_files::task_variant("jump_forward", "crouch_lean_off", {}, {{"controller", "lean = { lean = 0.0 }"}}).string();
  std::printf("without it (the input motion found without it):\n");
  const Pushed held_over_feet =
      push_the_crouch(without, source + "/tests/control/data/jump_forward.no_lean.m0.json");
  EXPECT_GE(lean.held, 5);
  EXPECT_LT(held_over_feet.held, lean.held);
  EXPECT_LT(lean.worst_speed, held_over_feet.worst_speed);
}

TEST(CrouchLean, BadValuesAreRefused) {
  auto refused = [](const std::string& name, const std::string& line, const std::string& expected) {
    test_files::expect_task_refused(test_files::task_variant("jump_forward", name, {}, {{"controller", line}}).string(),
                                    expected);
  };
  refused("lean_back", "lean = { lean = -0.2 }", "controller.lean.lean: expected a number in [0, ");
  refused("lean_text", "lean = { lean = \"far\" }", "controller.lean.lean: expected a number");
}

}  // namespace
}  // namespace diverse
