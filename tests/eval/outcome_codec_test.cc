// Outcomes travelling between processes (distribute/cluster.h): MotionProblem::encode and
// decode reproduce every field bit for bit, refuse bytes they did not write, and an
// optimizer whose batches go through another evaluator (here: in reverse order, every
// outcome through encode and decode, as a worker rank's would) ends exactly where the
// thread pool's does.
#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>
#include <string>

#include "core/thread_pool.h"
#include "eval/motion_problem.h"
#include "optimize/batch_evaluator.h"
#include "optimize/diversity.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {
namespace {

const std::string kTask = std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_high.toml";

struct Fixture {
  Fixture() : evaluator(load_task(kTask)) {
    m0 = evaluator.load_parameters(evaluator.task().m0);
    shaped_m0 = evaluator.with_shape(m0, evaluator.shapes().identity());
  }
  TaskEvaluator evaluator;
  ParameterSet m0, shaped_m0;
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

bool same_bits(const double* a, const double* b, Eigen::Index n) {
  return std::memcmp(a, b, static_cast<std::size_t>(n) * sizeof(double)) == 0;
}

void expect_identical(const MotionOutcome& a, const MotionOutcome& b) {
  EXPECT_TRUE(same_bits(&a.constraint, &b.constraint, 1));
  EXPECT_EQ(a.failed, b.failed);
  EXPECT_EQ(a.fell, b.fell);
  EXPECT_TRUE(same_bits(&a.landing_x, &b.landing_x, 1));
  EXPECT_TRUE(same_bits(&a.peak_com_z, &b.peak_com_z, 1));
  EXPECT_TRUE(same_bits(&a.task_constraint, &b.task_constraint, 1));
  EXPECT_TRUE(same_bits(&a.effort, &b.effort, 1));
  EXPECT_TRUE(same_bits(&a.positive_work, &b.positive_work, 1));
  EXPECT_TRUE(same_bits(&a.effort_ratio, &b.effort_ratio, 1));
  EXPECT_TRUE(same_bits(&a.distance_to_m0, &b.distance_to_m0, 1));
  ASSERT_EQ(a.scales.size(), b.scales.size());
  EXPECT_TRUE(same_bits(a.scales.data(), b.scales.data(), a.scales.size()));
  ASSERT_EQ(a.features.link_lengths.size(), b.features.link_lengths.size());
  EXPECT_TRUE(same_bits(a.features.link_lengths.data(), b.features.link_lengths.data(),
                        a.features.link_lengths.size()));
  ASSERT_EQ(a.features.poses.size(), b.features.poses.size());
  for (std::size_t k = 0; k < a.features.poses.size(); ++k) {
    const Pose& p = a.features.poses[k];
    const Pose& q = b.features.poses[k];
    ASSERT_EQ(p.link_com.cols(), q.link_com.cols());
    EXPECT_TRUE(same_bits(p.link_com.data(), q.link_com.data(), p.link_com.size())) << k;
    ASSERT_EQ(p.link_mass.size(), q.link_mass.size());
    EXPECT_TRUE(same_bits(p.link_mass.data(), q.link_mass.data(), p.link_mass.size())) << k;
    ASSERT_EQ(p.angles.size(), q.angles.size());
    EXPECT_TRUE(same_bits(p.angles.data(), q.angles.data(), p.angles.size())) << k;
    EXPECT_TRUE(same_bits(p.root.coeffs().data(), q.root.coeffs().data(), 4)) << k;
  }
}

const MotionOutcome& motion(const std::shared_ptr<const Outcome>& o) {
  return static_cast<const MotionOutcome&>(*o);
}

TEST(OutcomeCodec, RoundTripsAFlightBitForBit) {
  Fixture& f = fixture();
  // With bounds, so that every field of the outcome holds a value.
  const MotionProblem problem(f.evaluator, DistanceSpec{Metric::kMassDistance, 0.0}, f.shaped_m0.normalized(), 1, true,
                              MotionBounds{1.5, 100.0});
  const auto outcome = problem.evaluate(f.shaped_m0.normalized(), 0);
  ASSERT_FALSE(outcome->failed);
  ASSERT_EQ(motion(outcome).effort_ratio, 1.0);
  ASSERT_GT(motion(outcome).effort, 0.0);
  ASSERT_EQ(motion(outcome).features.poses.size(), 20u);  // 10 per airborne phase
  ASSERT_GT(motion(outcome).scales.size(), 0);
  const std::string bytes = MotionProblem::encode(*outcome);
  const auto back = MotionProblem::decode(bytes);
  expect_identical(motion(outcome), motion(back));
  // Every distance the run computes is therefore the same.
  EXPECT_EQ(problem.distance(*outcome, *back, Metric::kWeightedJointAngles), 0.0);
  EXPECT_EQ(MotionProblem::encode(*back), bytes);
}

TEST(OutcomeCodec, RoundTripsAFailure) {
  Fixture& f = fixture();
  const MotionProblem problem(f.evaluator, DistanceSpec{Metric::kMassDistance, 0.0}, f.shaped_m0.normalized(), 1, true);
  Eigen::VectorXd x = f.shaped_m0.normalized();
  x[0] = 1.5;  // outside the box: a failed rollout with a penalty
  const auto outcome = problem.evaluate(x, 0);
  ASSERT_TRUE(outcome->failed);
  const auto back = MotionProblem::decode(MotionProblem::encode(*outcome));
  expect_identical(motion(outcome), motion(back));
  EXPECT_TRUE(back->failed);
  EXPECT_GT(back->constraint, 0.0);
}

TEST(OutcomeCodec, RefusesBytesItDidNotWrite) {
  Fixture& f = fixture();
  const MotionProblem problem(f.evaluator, Metric::kMassDistance, f.m0.normalized(), 1);
  const std::string bytes = MotionProblem::encode(*problem.evaluate(f.m0.normalized(), 0));
  for (std::size_t cut : {std::size_t{0}, std::size_t{3}, std::size_t{20}, bytes.size() / 2, bytes.size() - 1})
    EXPECT_THROW(MotionProblem::decode(bytes.substr(0, cut)), std::invalid_argument) << cut;
  EXPECT_THROW(MotionProblem::decode(bytes + "x"), std::invalid_argument);
  std::string other = bytes;
  other[0] = 'Z';
  EXPECT_THROW(MotionProblem::decode(other), std::invalid_argument);
}

// Evaluates a batch the way no thread pool would: last sample first, each outcome
// rebuilt from its bytes.
class ReversedEvaluator : public BatchEvaluator {
 public:
  explicit ReversedEvaluator(const MotionProblem& problem) : problem_(problem) {}
  std::vector<std::shared_ptr<const Outcome>> evaluate(const std::vector<Eigen::VectorXd>& xs) override {
    std::vector<std::shared_ptr<const Outcome>> out(xs.size());
    for (std::size_t k = xs.size(); k-- > 0;)
      out[k] = MotionProblem::decode(MotionProblem::encode(*problem_.evaluate(xs[k], 0)));
    batches += 1;
    return out;
  }
  int batches = 0;

 private:
  const MotionProblem& problem_;
};

TEST(OutcomeCodec, AnotherBatchEvaluatorGivesTheSameRun) {
  Fixture& f = fixture();
  const MotionProblem problem(f.evaluator, Metric::kMassDistance, f.m0.normalized(), 2);
  DiversityOptions options;
  options.variations = 2;
  options.popsize = 4;
  options.max_generations = 2;
  options.seed = 5;
  ThreadPool pool(2);
  DiversityOptimizer local(problem, options, pool);
  local.run();
  ReversedEvaluator reversed(problem);
  DiversityOptimizer through(problem, options, pool, &reversed);
  through.run();
  EXPECT_EQ(reversed.batches, 3);  // M0, then one batch per generation
  EXPECT_EQ(local.checkpoint().dump(), through.checkpoint().dump());
  const DiversityResult a = local.result(), b = through.result();
  EXPECT_EQ(a.score.D, b.score.D);
  EXPECT_EQ(a.evaluations, b.evaluations);
  // A restored optimizer re-evaluates its sets through the evaluator too.
  ReversedEvaluator again(problem);
  const DiversityOptimizer restored =
      DiversityOptimizer::from_checkpoint(problem, through.checkpoint(), pool, &again);
  EXPECT_EQ(again.batches, 1);
  EXPECT_EQ(restored.checkpoint().dump(), through.checkpoint().dump());
}

}  // namespace
}  // namespace diverse
