// Every jump that takes off and lands has both airborne phases, so the metrics always
// get their 2 x 10 pose samples: a touch-down while still rising (a low, flat jump) is a
// zero-length fall, with the peak at the touch-down.
#include <gtest/gtest.h>

#include "core/rng.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {
namespace {

TEST(FlightPhases, EveryLandedJumpHasAPeakAndTwentyPoses) {
  const TaskEvaluator ev(load_task(resolve_task_path("jump_high")));
  const ParameterSet m0 = ev.load_parameters(ev.task().m0);
  auto worker = ev.make_worker();
  Rng rng(derive_seed(5, {1}));
  int landed = 0;
  for (int k = 0; k < 40; ++k) {
    Eigen::VectorXd x = m0.normalized();
    for (Eigen::Index j = 0; j < x.size(); ++j)
      x[j] = std::clamp(x[j] + 0.15 * rng.normal(), 0.0, 1.0);
    const Evaluation e = ev.evaluate_normalized(x, *worker);
    if (e.failed || e.phases.takeoff() < 0 || e.phases.landing() < 0) continue;
    ++landed;
    EXPECT_GE(e.phases.peak(), e.phases.takeoff()) << k;
    EXPECT_LE(e.phases.peak(), e.phases.landing()) << k;
    EXPECT_EQ(e.poses.size(), 20u) << k;
  }
  EXPECT_GT(landed, 10);
}

}  // namespace
}  // namespace diverse
