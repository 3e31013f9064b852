#include "optimize/diversity.h"

#include <array>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/error.h"
#include "core/thread_pool.h"
#include "optimize/objective.h"

namespace diverse {
namespace {

struct PointOutcome : Outcome {
  Eigen::VectorXd x;
};

// Points in [0, 1]^dim; feasible inside a ball around the reference; squared Euclidean
// distance. Points with x[0] > fail_above are failed evaluations with a NaN constraint
// (a simulation that blew up). Counts evaluations.
class BallProblem : public DiversityProblem {
 public:
  BallProblem(int dim, double radius, double fail_above = 2.0, double weight = 5000.0)
      : dim_(dim), radius_(radius), fail_above_(fail_above), weight_(weight) {}
  int dim() const override { return dim_; }
  Eigen::VectorXd reference() const override { return Eigen::VectorXd::Constant(dim_, 0.4); }
  std::shared_ptr<const Outcome> evaluate(const Eigen::VectorXd& x, int) const override {
    evaluations.fetch_add(1);
    auto out = std::make_shared<PointOutcome>();
    out->x = x;
    if (x[0] > fail_above_) {
      out->failed = true;
      out->constraint = std::numeric_limits<double>::quiet_NaN();
      return out;
    }
    const double e = std::max(0.0, (x - reference()).norm() - radius_);
    out->constraint = weight_ * e * e;
    return out;
  }
  double distance(const Outcome& a, const Outcome& b) const override {
    return (static_cast<const PointOutcome&>(a).x - static_cast<const PointOutcome&>(b).x)
        .squaredNorm();
  }
  mutable std::atomic<long long> evaluations{0};

 private:
  int dim_;
  double radius_;
  double fail_above_;
  double weight_;
};

// A fixed outcome for objective tests.
std::shared_ptr<const Outcome> point(double x, double constraint = 0.0, bool failed = false) {
  auto out = std::make_shared<PointOutcome>();
  out->x = Eigen::VectorXd::Constant(1, x);
  out->constraint = constraint;
  out->failed = failed;
  return out;
}

// ---- The objective (paper eq. 1) -------------------------------------------------------

TEST(DiversityObjective, ThreeMotionsByHand) {
  // M0, M1, M2 at 0, 1, 3 on a line: d01 = 1, d02 = 9, d12 = 4; dmin = 1, 1, 4.
  // D = -(0 + 0.5 + 2) + 2 (1 + 9 + 4) + (N + 1) K (1 + 1 + 4) with N + 1 = 3.
  const BallProblem problem(1, 1.0);
  const std::vector<std::shared_ptr<const Outcome>> set{point(0.0), point(1.0, 0.5),
                                                        point(3.0, 2.0)};
  const DiversityScore k10 = score_diversity(problem, set, 10.0);
  EXPECT_DOUBLE_EQ(k10.D, -2.5 + 28.0 + 3 * 10.0 * 6.0);  // 205.5
  EXPECT_DOUBLE_EQ(score_diversity(problem, set, 0.0).D, 25.5);
  EXPECT_DOUBLE_EQ(k10.distance(0, 1), 1.0);
  EXPECT_DOUBLE_EQ(k10.distance(0, 2), 9.0);
  EXPECT_DOUBLE_EQ(k10.distance(2, 1), 4.0);
  EXPECT_EQ(k10.dmin, Eigen::Vector3d(1.0, 1.0, 4.0));
  EXPECT_EQ(k10.constraint, Eigen::Vector3d(0.0, 0.5, 2.0));
  for (int i = 0; i < 3; ++i) EXPECT_EQ(k10.distance(i, i), 0.0);
  EXPECT_EQ(k10.distance, k10.distance.transpose());
}

TEST(DiversityObjective, MatrixFormAgreesAndDminWeightIsNPlusOneTimesK) {
  Eigen::MatrixXd d(4, 4);
  d << 0, 2, 3, 5,  //
      2, 0, 7, 1,   //
      3, 7, 0, 4,   //
      5, 1, 4, 0;
  const Eigen::Vector4d c(0.0, 1.0, 0.0, 3.0);
  Eigen::VectorXd dmin;
  const double k = 2.5;
  const double value = diversity_objective(d, c, k, &dmin);
  EXPECT_EQ(dmin, Eigen::Vector4d(2, 1, 3, 1));
  // Sum over ordered pairs of d (2 x 22), minus C (4), plus (N + 1) K sum(dmin) with
  // N + 1 = 4 (literal eq. 1).
  EXPECT_DOUBLE_EQ(value, 44.0 - 4.0 + 4 * k * 7.0);
  // Raising K by 1 adds (N + 1) sum(dmin).
  EXPECT_DOUBLE_EQ(diversity_objective(d, c, k + 1.0) - value, 4 * 7.0);
}

TEST(DiversityObjective, FailedOutcomesScoreBadlyButFinite) {
  const BallProblem problem(1, 1.0);
  auto blown_up = std::make_shared<PointOutcome>();
  blown_up->x = Eigen::VectorXd::Constant(1, std::numeric_limits<double>::infinity());
  blown_up->failed = true;
  blown_up->constraint = std::numeric_limits<double>::quiet_NaN();
  const std::vector<std::shared_ptr<const Outcome>> set{point(0.0), point(1.0), blown_up};
  const DiversityScore s = score_diversity(problem, set, 10.0);
  EXPECT_TRUE(std::isfinite(s.D));
  EXPECT_EQ(s.constraint[2], kFailedConstraint);
  EXPECT_EQ(s.distance(0, 2), 0.0);
  EXPECT_EQ(s.distance(1, 2), 0.0);
  EXPECT_LT(s.D, -0.5 * kFailedConstraint);
  // A failure flagged with a finite constraint keeps that value.
  const DiversityScore flagged =
      score_diversity(problem, {point(0.0), point(1.0), point(5.0, 50000.0, true)}, 10.0);
  EXPECT_EQ(flagged.constraint[2], 50000.0);
  EXPECT_EQ(flagged.distance(0, 2), 0.0);
  EXPECT_TRUE(is_failure(*point(0.0, std::numeric_limits<double>::infinity())));
  EXPECT_FALSE(is_failure(*point(0.0, 3.0)));
}

TEST(DiversityObjective, RejectsBrokenProblemData) {
  const BallProblem problem(1, 1.0);
  EXPECT_THROW(score_diversity(problem, {point(0.0), point(1.0, -1.0)}, 10.0), std::logic_error);
  EXPECT_THROW(diversity_objective(Eigen::MatrixXd::Zero(1, 1), Eigen::VectorXd::Zero(1), 1.0),
               std::logic_error);
  EXPECT_THROW(diversity_objective(Eigen::MatrixXd::Zero(3, 3), Eigen::VectorXd::Zero(2), 1.0),
               std::logic_error);
  auto nan_point = point(std::numeric_limits<double>::quiet_NaN());
  EXPECT_THROW(score_diversity(problem, {point(0.0), nan_point}, 10.0), std::logic_error);
}

// ---- Options and names -----------------------------------------------------------------

TEST(DiversityOptions, StrategyNames) {
  EXPECT_EQ(parse_strategy("round-robin"), DiversityStrategy::kRoundRobin);
  EXPECT_EQ(parse_strategy("progressive"), DiversityStrategy::kProgressive);
  EXPECT_EQ(parse_strategy("joint"), DiversityStrategy::kJoint);
  EXPECT_EQ(parse_strategy("simultaneous"), DiversityStrategy::kSimultaneous);
  try {
    parse_strategy("greedy", "--strategy");
    FAIL();
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(),
                 "--strategy: expected one of round-robin, progressive, joint, simultaneous, got "
                 "'greedy'");
  }
}

TEST(DiversityOptions, ConstraintRuleNames) {
  EXPECT_EQ(parse_constraint_rule("dominant"), ConstraintRule::kDominant);
  EXPECT_EQ(parse_constraint_rule("penalty"), ConstraintRule::kPenalty);
  EXPECT_EQ(DiversityOptions{}.constraints, ConstraintRule::kDominant);
  try {
    parse_constraint_rule("soft");
    FAIL();
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(), "--constraints: expected one of dominant, penalty, got 'soft'");
  }
}

TEST(DiversityOptions, ValidationAndJsonRoundTrip) {
  DiversityOptions o;
  EXPECT_NO_THROW(validate(o));
  auto bad = [](auto mutate) {
    DiversityOptions b;
    mutate(b);
    return b;
  };
  EXPECT_THROW(validate(bad([](auto& b) { b.variations = 0; })), std::invalid_argument);
  EXPECT_THROW(validate(bad([](auto& b) { b.k = -1.0; })), std::invalid_argument);
  EXPECT_THROW(validate(bad([](auto& b) { b.k = std::nan(""); })), std::invalid_argument);
  EXPECT_THROW(validate(bad([](auto& b) { b.popsize = 1; })), std::invalid_argument);
  EXPECT_THROW(validate(bad([](auto& b) { b.sigma0 = 0.0; })), std::invalid_argument);
  EXPECT_THROW(validate(bad([](auto& b) { b.max_generations = 0; })), std::invalid_argument);
  EXPECT_THROW(validate(bad([](auto& b) { b.window = -1; })), std::invalid_argument);
  // The optimizer validates too, and checks the problem's reference is normalized.
  const BallProblem problem(2, 0.3);
  ThreadPool pool(1);
  EXPECT_THROW(DiversityOptimizer(problem, bad([](auto& b) { b.popsize = 0; }), pool),
               std::invalid_argument);
  struct OutOfRange : BallProblem {
    OutOfRange() : BallProblem(2, 0.3) {}
    Eigen::VectorXd reference() const override { return Eigen::Vector2d(0.5, 1.5); }
  };
  const OutOfRange out_of_range;
  EXPECT_THROW(DiversityOptimizer(out_of_range, DiversityOptions{}, pool), std::logic_error);
  o.variations = 7;
  o.k = 3.25;
  o.strategy = DiversityStrategy::kJoint;
  o.constraints = ConstraintRule::kPenalty;
  o.point = VariationPoint::kMean;
  o.seed = 0xfedcba9876543210ULL;
  const DiversityOptions back = diversity_options_from_json(to_json(o));
  EXPECT_EQ(to_json(back), to_json(o));
  EXPECT_EQ(back.seed, o.seed);
}

// Parameterized suites run once per strategy, named after it ("roundrobin", ...).
const auto kAllStrategies =
    ::testing::Values(DiversityStrategy::kRoundRobin, DiversityStrategy::kProgressive,
                      DiversityStrategy::kJoint, DiversityStrategy::kSimultaneous);
std::string strategy_test_name(const ::testing::TestParamInfo<DiversityStrategy>& info) {
  std::string name = to_string(info.param);
  name.erase(std::remove(name.begin(), name.end(), '-'), name.end());
  return name;
}

// ---- Constraint rules ------------------------------------------------------------------

// A constraint weight of 1 is far too weak for the distances of points spread over the
// unit square: under the penalty rule diversity buys violation, under the dominant rule
// it cannot, whatever the strategy.
class ConstraintRules : public ::testing::TestWithParam<DiversityStrategy> {};

TEST_P(ConstraintRules, DominantKeepsTheResultFeasibleWherePenaltyDoesNot) {
  const BallProblem weak(2, 0.1, 2.0, /*weight=*/1.0);
  ThreadPool pool(1);
  DiversityOptions o;
  o.variations = 3;
  o.strategy = GetParam();
  o.max_generations = 90;
  o.window = 0;
  o.seed = 5;

  o.constraints = ConstraintRule::kPenalty;
  DiversityOptimizer penalty(weak, o, pool);
  penalty.run();
  EXPECT_GT(penalty.result().score.constraint.maxCoeff(), 0.0);

  o.constraints = ConstraintRule::kDominant;
  DiversityOptimizer dominant(weak, o, pool);
  dominant.run();
  const DiversityResult r = dominant.result();
  EXPECT_EQ(r.score.constraint.maxCoeff(), 0.0);
  // Feasible, and spread: every variation left M_0 by a good part of the ball's radius.
  for (int i = 1; i < r.score.dmin.size(); ++i) EXPECT_GT(r.score.dmin[i], 0.05 * 0.05) << i;
}

INSTANTIATE_TEST_SUITE_P(AllStrategies, ConstraintRules,
                         kAllStrategies, strategy_test_name);

// ---- Where a variation stands ------------------------------------------------------------

// Best-sample: no evaluation beyond the samples, every variation stands at P_0 or at one
// of its own evaluated samples, and since a variation only moves to a candidate that beats
// where it stands (the others held still), the current set never gets worse from one step
// to the next: its total C never rises and, at equal C, its D never falls.
class BestSample : public ::testing::TestWithParam<DiversityStrategy> {};

TEST_P(BestSample, StandsOnEvaluatedSamplesAndNeverWorsensTheSet) {
  const BallProblem problem(2, 0.3);
  ThreadPool pool(2);
  DiversityOptions o;
  o.variations = 3;
  o.strategy = GetParam();
  o.max_generations = 12;
  o.window = 0;
  o.seed = 11;
  ASSERT_EQ(o.point, VariationPoint::kBestSample);  // the default
  DiversityOptimizer opt(problem, o, pool);
  std::vector<std::vector<Eigen::VectorXd>> standing;
  opt.set_callback([&](const DiversityRecord&) { standing.push_back(opt.current_parameters()); });
  opt.run();
  EXPECT_EQ(opt.evaluations(), 1 + 12 * 3 * 16);
  EXPECT_EQ(opt.evaluations(), problem.evaluations.load());
  const auto& log = opt.log();
  ASSERT_FALSE(log.empty());
  for (std::size_t s = 1; s < log.size(); ++s) {
    const double before = log[s - 1].constraint.sum(), after = log[s].constraint.sum();
    EXPECT_LE(after, before) << "step " << s;
    if (after == before && GetParam() != DiversityStrategy::kProgressive) {
      EXPECT_GE(log[s].D, log[s - 1].D) << "step " << s;
    }
  }
  // Every point stood on is P_0 or lies in [0, 1]^2 (a reflected CMA sample), and the
  // result is the best set, all feasible here since P_0 is.
  for (const auto& set : standing) {
    for (const auto& x : set) EXPECT_TRUE((x.array() >= 0.0).all() && (x.array() <= 1.0).all());
  }
  EXPECT_EQ(opt.result().score.constraint.maxCoeff(), 0.0);
  EXPECT_GT(opt.result().score.D, 1.0);
  // A path has a point per step that moved its variation, and ends where it stands.
  for (int v = 1; v <= 3; ++v) {
    const auto& path = opt.paths()[v];
    EXPECT_EQ(path.front().x, problem.reference());
    EXPECT_EQ(path.back().x, opt.current_parameters()[v]);
    EXPECT_LE(path.size(), 13u);
    for (std::size_t k = 1; k < path.size(); ++k) {
      EXPECT_NE(path[k].x, path[k - 1].x);
      EXPECT_GT(path[k].step, path[k - 1].step);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllStrategies, BestSample,
                         kAllStrategies, strategy_test_name);

TEST(DiversityOptions, VariationPointNames) {
  EXPECT_EQ(parse_variation_point("best-sample"), VariationPoint::kBestSample);
  EXPECT_EQ(parse_variation_point("mean"), VariationPoint::kMean);
  try {
    parse_variation_point("median");
    FAIL();
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(), "--point: expected one of best-sample, mean, got 'median'");
  }
}

// ---- Strategies ------------------------------------------------------------------------

// The paper's literal bookkeeping (variations stand at their CMA means), whose evaluation
// counts the tests below spell out; best-sample has tests of its own.
DiversityOptions small_options(DiversityStrategy strategy, long long generations) {
  DiversityOptions o;
  o.variations = 3;
  o.strategy = strategy;
  o.point = VariationPoint::kMean;
  o.max_generations = generations;
  o.window = 0;
  o.seed = 7;
  return o;
}

TEST(DiversityRoundRobin, OneGenerationStepsEveryVariationInTurn) {
  const BallProblem problem(2, 0.3);
  ThreadPool pool(1);
  const DiversityOptions o = small_options(DiversityStrategy::kRoundRobin, 5);
  DiversityOptimizer opt(problem, o, pool);
  int callbacks = 0;
  opt.set_callback([&](const DiversityRecord&) {
    ++callbacks;
    EXPECT_THROW(opt.checkpoint(), std::logic_error);  // mid-generation
  });
  opt.run();
  EXPECT_EQ(opt.stop_reason(), DiversityStop::kMaxGenerations);
  EXPECT_EQ(opt.generation(), 5);
  ASSERT_EQ(opt.log().size(), 15u);
  EXPECT_EQ(callbacks, 15);
  for (std::size_t s = 0; s < 15; ++s) {
    const DiversityRecord& r = opt.log()[s];
    EXPECT_EQ(r.step, static_cast<long long>(s) + 1);
    EXPECT_EQ(r.generation, static_cast<long long>(s) / 3 + 1);
    EXPECT_EQ(r.variation, static_cast<int>(s % 3) + 1);
    // P0 once, then per step lambda samples and the new mean.
    EXPECT_EQ(r.evaluations, 1 + r.step * (16 + 1));
    EXPECT_EQ(r.constraint.size(), 4);
    EXPECT_EQ(r.dmin.size(), 4);
    EXPECT_TRUE(std::isfinite(r.D));
  }
  EXPECT_EQ(opt.evaluations(), problem.evaluations.load());
  ASSERT_EQ(opt.paths().size(), 4u);
  EXPECT_EQ(opt.paths()[0].size(), 1u);
  for (int v = 1; v <= 3; ++v) {
    ASSERT_EQ(opt.paths()[v].size(), 6u);
    EXPECT_EQ(opt.paths()[v][0].x, problem.reference());
    EXPECT_EQ(opt.paths()[v].back().x, opt.current_parameters()[v]);
  }

  // The last record describes the current set; the result is the best set ever scored
  // (dominant rule: least total C first, then highest D).
  const DiversityScore current = score_diversity(
      problem, {problem.evaluate(opt.current_parameters()[0], 0),
                problem.evaluate(opt.current_parameters()[1], 0),
                problem.evaluate(opt.current_parameters()[2], 0),
                problem.evaluate(opt.current_parameters()[3], 0)},
      o.k);
  EXPECT_EQ(opt.log().back().D, current.D);
  const DiversityResult result = opt.result();
  double least_violation = std::numeric_limits<double>::infinity();
  for (const auto& r : opt.log()) least_violation = std::min(least_violation, r.constraint.sum());
  double best = -std::numeric_limits<double>::infinity();
  for (const auto& r : opt.log()) {
    if (r.constraint.sum() == least_violation) best = std::max(best, r.D);
  }
  EXPECT_EQ(result.score.constraint.sum(), least_violation);
  EXPECT_EQ(result.score.D, best);
  EXPECT_EQ(result.score.D, score_diversity(problem, result.outcomes, o.k).D);
  EXPECT_EQ(result.parameters.size(), 4u);
  EXPECT_EQ(result.parameters[0], problem.reference());
  // Diversity went up from the all-at-P0 start (D = 0 there).
  EXPECT_GT(result.score.D, 1.0);
}

TEST(DiversityProgressive, AddsVariationsOneAtATimeWithinBudgetShares) {
  const BallProblem problem(2, 0.3);
  ThreadPool pool(1);
  const DiversityOptions o = small_options(DiversityStrategy::kProgressive, 30);
  DiversityOptimizer opt(problem, o, pool);
  opt.run();
  // Shares: 30 / 3 = 10, then (30 - 10) / 2 = 10, then 10: N steps per generation.
  EXPECT_EQ(opt.generation(), 30);
  ASSERT_EQ(opt.log().size(), 90u);
  for (std::size_t s = 0; s < 90; ++s) {
    const DiversityRecord& r = opt.log()[s];
    const int variation = static_cast<int>(s) / 30 + 1;
    EXPECT_EQ(r.variation, variation) << "step " << s;
    EXPECT_EQ(r.generation, static_cast<long long>(s) / 3 + 1);
    EXPECT_EQ(r.constraint.size(), variation + 1);  // only the motions added so far
  }
  EXPECT_EQ(opt.evaluations(), 1 + 90 * 17);
  // Variation 1 is frozen at the best point of its phase: a point of its path.
  const DiversityResult result = opt.result();
  ASSERT_EQ(result.parameters.size(), 4u);
  bool on_path = false;
  for (const auto& p : opt.paths()[1]) on_path = on_path || p.x == result.parameters[1];
  EXPECT_TRUE(on_path);
  EXPECT_EQ(opt.paths()[1].size(), 31u);
  EXPECT_EQ(opt.paths()[1].back().generation, 10);
  EXPECT_EQ(opt.paths()[3].front().generation, 0);
  EXPECT_EQ(opt.paths()[3][1].generation, 21);
}

TEST(DiversityProgressive, StagnationEndsAPhaseEarly) {
  const BallProblem problem(2, 0.3);
  ThreadPool pool(1);
  DiversityOptions o = small_options(DiversityStrategy::kProgressive, 300);
  o.window = 5;
  o.epsilon = 1e9;  // any window counts as stagnant
  DiversityOptimizer opt(problem, o, pool);
  opt.run();
  EXPECT_EQ(opt.generation(), 15);  // three phases of exactly one window each
  EXPECT_EQ(opt.stop_reason(), DiversityStop::kStagnation);
}

TEST(DiversityJoint, OneInstanceOverAllVariations) {
  const BallProblem problem(2, 0.3);
  ThreadPool pool(1);
  const DiversityOptions o = small_options(DiversityStrategy::kJoint, 5);
  DiversityOptimizer opt(problem, o, pool);
  opt.run();
  ASSERT_EQ(opt.log().size(), 5u);
  for (const auto& r : opt.log()) EXPECT_EQ(r.variation, 0);
  // lambda sets of N evaluations, then the N means.
  EXPECT_EQ(opt.evaluations(), 1 + 5 * (16 * 3 + 3));
  EXPECT_EQ(opt.evaluations(), problem.evaluations.load());
  for (int v = 1; v <= 3; ++v) EXPECT_EQ(opt.paths()[v].size(), 6u);
  EXPECT_GT(opt.result().score.D, 0.0);
}

// Records the size of every batch the optimizer asks for, evaluating on one thread.
class CountingBatch : public BatchEvaluator {
 public:
  explicit CountingBatch(const DiversityProblem& problem) : problem_(problem) {}
  std::vector<std::shared_ptr<const Outcome>> evaluate(const std::vector<Eigen::VectorXd>& xs) override {
    sizes.push_back(xs.size());
    std::vector<std::shared_ptr<const Outcome>> out;
    for (const auto& x : xs) out.push_back(problem_.evaluate(x, 0));
    return out;
  }
  std::vector<std::size_t> sizes;

 private:
  const DiversityProblem& problem_;
};

TEST(DiversitySimultaneous, EveryVariationsGenerationInOneBatch) {
  const BallProblem problem(2, 0.3);
  ThreadPool pool(1);
  for (VariationPoint point : {VariationPoint::kBestSample, VariationPoint::kMean}) {
    SCOPED_TRACE(to_string(point));
    DiversityOptions o = small_options(DiversityStrategy::kSimultaneous, 5);
    o.point = point;
    CountingBatch batch(problem);
    DiversityOptimizer opt(problem, o, pool, &batch);
    opt.run();
    // M_0, then per generation one batch of N x lambda (and, standing at means, the N
    // new means in one more).
    std::vector<std::size_t> expected{1};
    for (int g = 0; g < 5; ++g) {
      expected.push_back(3 * 16);
      if (point == VariationPoint::kMean) expected.push_back(3);
    }
    EXPECT_EQ(batch.sizes, expected);
    EXPECT_EQ(opt.evaluations(), 1 + 5 * (3 * 16 + (point == VariationPoint::kMean ? 3 : 0)));
    ASSERT_EQ(opt.log().size(), 5u);
    for (const auto& r : opt.log()) EXPECT_EQ(r.variation, 0);
    EXPECT_GT(opt.result().score.D, 0.0);
  }
  // The same budget as round-robin standing at means, whose batches hold one variation's
  // lambda and the previous step's new mean (the last one's alone at the generation's end).
  CountingBatch round_robin(problem);
  DiversityOptions o = small_options(DiversityStrategy::kRoundRobin, 5);
  DiversityOptimizer rr(problem, o, pool, &round_robin);
  rr.run();
  EXPECT_EQ(round_robin.sizes.size(), 1u + 5 * 4);
  EXPECT_EQ(round_robin.sizes[1], 16u);
  EXPECT_EQ(round_robin.sizes[2], 17u);
  EXPECT_EQ(round_robin.sizes[4], 1u);
  EXPECT_EQ(rr.evaluations(), 1 + 5 * 3 * (16 + 1));
}

// Variation 1's first generation is the same in both strategies (the same CMA stream,
// scored against the same starting set); variation 2's differs, since in round-robin its
// samples see where variation 1 moved, in simultaneous they do not.
TEST(DiversitySimultaneous, SamplesAreScoredAgainstTheSetAsTheGenerationWasDrawn) {
  const BallProblem problem(2, 0.3);
  ThreadPool pool(1);
  DiversityOptions o = small_options(DiversityStrategy::kSimultaneous, 1);
  o.point = VariationPoint::kBestSample;
  DiversityOptimizer simultaneous(problem, o, pool);
  simultaneous.run();
  o.strategy = DiversityStrategy::kRoundRobin;
  DiversityOptimizer round_robin(problem, o, pool);
  round_robin.step();
  const nlohmann::json a = simultaneous.checkpoint()["cma"], b = round_robin.checkpoint()["cma"];
  EXPECT_EQ(a[0], b[0]);
  EXPECT_NE(a[1], b[1]);
}

TEST(DiversityTermination, StagnationWindow) {
  const BallProblem problem(2, 0.3);
  ThreadPool pool(1);
  DiversityOptions o = small_options(DiversityStrategy::kRoundRobin, 1000);
  o.window = 4;
  o.epsilon = 1e9;
  DiversityOptimizer opt(problem, o, pool);
  opt.run();
  EXPECT_EQ(opt.generation(), 4);
  EXPECT_EQ(opt.stop_reason(), DiversityStop::kStagnation);
  EXPECT_FALSE(opt.step());  // nothing more once done
  EXPECT_EQ(opt.generation(), 4);

  // A realistic epsilon stops well before the limit once D levels off.
  o.epsilon = 1e-6;
  o.window = 20;
  DiversityOptimizer settled(problem, o, pool);
  settled.run();
  EXPECT_EQ(settled.stop_reason(), DiversityStop::kStagnation);
  EXPECT_LT(settled.generation(), 1000);
}

TEST(DiversityFailures, BlownUpSamplesNeverMakeDNonFinite) {
  // Everything with x[0] > 0.55 fails, well inside the reach of sigma0 = 0.2 from 0.4.
  const BallProblem problem(2, 0.3, 0.55);
  ThreadPool pool(2);
  for (DiversityStrategy s : {DiversityStrategy::kRoundRobin, DiversityStrategy::kProgressive,
                              DiversityStrategy::kJoint, DiversityStrategy::kSimultaneous}) {
    DiversityOptions o = small_options(s, 30);
    o.sigma0 = 0.2;
    DiversityOptimizer opt(problem, o, pool);
    opt.run();
    for (const auto& r : opt.log()) ASSERT_TRUE(std::isfinite(r.D)) << to_string(s);
    const DiversityResult result = opt.result();
    for (const auto& out : result.outcomes) EXPECT_FALSE(is_failure(*out)) << to_string(s);
    for (const auto& p : result.parameters) EXPECT_LE(p[0], 0.55) << to_string(s);
  }
}

// ---- Determinism and checkpoints -------------------------------------------------------

void expect_identical(const DiversityOptimizer& a, const DiversityOptimizer& b) {
  ASSERT_EQ(a.log().size(), b.log().size());
  for (std::size_t i = 0; i < a.log().size(); ++i) {
    EXPECT_EQ(to_json(a.log()[i]), to_json(b.log()[i])) << "record " << i;
    EXPECT_EQ(a.log()[i].D, b.log()[i].D);
  }
  ASSERT_EQ(a.paths().size(), b.paths().size());
  for (std::size_t v = 0; v < a.paths().size(); ++v) {
    ASSERT_EQ(a.paths()[v].size(), b.paths()[v].size());
    for (std::size_t k = 0; k < a.paths()[v].size(); ++k) {
      EXPECT_EQ(a.paths()[v][k].x, b.paths()[v][k].x);
      EXPECT_EQ(a.paths()[v][k].step, b.paths()[v][k].step);
    }
  }
  const DiversityResult ra = a.result(), rb = b.result();
  EXPECT_EQ(ra.score.D, rb.score.D);
  EXPECT_EQ(ra.score.distance, rb.score.distance);
  EXPECT_EQ(ra.score.constraint, rb.score.constraint);
  EXPECT_EQ(ra.score.dmin, rb.score.dmin);
  ASSERT_EQ(ra.parameters.size(), rb.parameters.size());
  for (std::size_t i = 0; i < ra.parameters.size(); ++i) EXPECT_EQ(ra.parameters[i], rb.parameters[i]);
  EXPECT_EQ(ra.generations, rb.generations);
  EXPECT_EQ(ra.evaluations, rb.evaluations);
  EXPECT_EQ(ra.stop, rb.stop);
  EXPECT_EQ(a.checkpoint(), b.checkpoint());
}

class DiversityStrategies : public ::testing::TestWithParam<DiversityStrategy> {};

TEST_P(DiversityStrategies, BitIdenticalForOneTwoAndThreeThreads) {
  const BallProblem problem(3, 0.3);
  for (VariationPoint point : {VariationPoint::kMean, VariationPoint::kBestSample}) {
  SCOPED_TRACE(to_string(point));
  DiversityOptions o = small_options(GetParam(), 24);
  o.point = point;
  o.window = 10;
  ThreadPool one(1), two(2), three(3);
  DiversityOptimizer a(problem, o, one), b(problem, o, two), c(problem, o, three);
  a.run();
  b.run();
  c.run();
  expect_identical(a, b);
  expect_identical(a, c);
  // A different seed gives a different run.
  o.seed += 1;
  DiversityOptimizer d(problem, o, one);
  d.run();
  EXPECT_NE(a.result().score.D, d.result().score.D);
  }
}

TEST_P(DiversityStrategies, CheckpointResumeMatchesUninterruptedRun) {
  const BallProblem problem(3, 0.3);
  for (VariationPoint point : {VariationPoint::kMean, VariationPoint::kBestSample}) {
  SCOPED_TRACE(to_string(point));
  DiversityOptions o = small_options(GetParam(), 24);  // progressive: phases of 8
  o.point = point;
  ThreadPool one(1), two(2);
  DiversityOptimizer whole(problem, o, one);
  whole.run();

  for (int split : {1, 7, 8, 13}) {
    DiversityOptimizer first(problem, o, one);
    for (int g = 0; g < split; ++g) first.step();
    // Through text, as a checkpoint file would go, and onto another thread count.
    const std::string text = first.checkpoint().dump();
    DiversityOptimizer resumed =
        DiversityOptimizer::from_checkpoint(problem, nlohmann::json::parse(text), two);
    EXPECT_EQ(resumed.generation(), split);
    EXPECT_EQ(resumed.checkpoint(), first.checkpoint());
    resumed.run();
    expect_identical(whole, resumed);
  }
  // A finished run restores as finished.
  DiversityOptimizer done =
      DiversityOptimizer::from_checkpoint(problem, whole.checkpoint(), one);
  EXPECT_TRUE(done.done());
  EXPECT_EQ(done.result().score.D, whole.result().score.D);
  }
}

INSTANTIATE_TEST_SUITE_P(All, DiversityStrategies,
                         kAllStrategies, strategy_test_name);

TEST(DiversityCheckpoint, RejectsACheckpointOfAnotherProblem) {
  const BallProblem problem(2, 0.3);
  ThreadPool pool(1);
  DiversityOptimizer opt(problem, small_options(DiversityStrategy::kRoundRobin, 3), pool);
  opt.step();
  const nlohmann::json state = opt.checkpoint();

  const BallProblem wider(3, 0.3);
  try {
    DiversityOptimizer::from_checkpoint(wider, state, pool);
    FAIL();
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(), "checkpoint: reference: expected 3 parameters, got 2");
  }
  nlohmann::json moved = state;
  moved["reference"][0] = 0.5;
  try {
    DiversityOptimizer::from_checkpoint(problem, moved, pool);
    FAIL();
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(), "checkpoint: reference: expected the problem's reference parameters");
  }
  nlohmann::json other = state;
  other["format"] = "something else";
  try {
    DiversityOptimizer::from_checkpoint(problem, other, pool);
    FAIL();
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(), "checkpoint: format: expected \"diverse.diversity_checkpoint\"");
  }
  // A problem whose outcomes differ from the ones checkpointed is caught.
  const BallProblem tighter(2, 0.05);
  EXPECT_THROW(DiversityOptimizer::from_checkpoint(tighter, state, pool), std::logic_error);
}

}  // namespace
}  // namespace diverse

namespace diverse {
namespace {

// The ball problem with a dear check: evaluate() gives points that meet the ball
// constraint as provisional; confirm() finds that those with x[0] > 0.45 fail it (C =
// 1 + how far past), as a motion that holds at its timestep may fail at half of it. The
// ledger counts evaluations and confirmations.
class CheckedBallProblem : public BallProblem {
 public:
  CheckedBallProblem() : BallProblem(3, 0.3) {}
  std::shared_ptr<const Outcome> evaluate(const Eigen::VectorXd& x, int worker) const override {
    auto out = std::make_shared<PointOutcome>(static_cast<const PointOutcome&>(*BallProblem::evaluate(x, worker)));
    out->provisional = !out->failed && out->constraint == 0;
    return out;
  }
  std::shared_ptr<const Outcome> confirm(const Eigen::VectorXd& x, const Outcome& outcome,
                                         int) const override {
    EXPECT_TRUE(outcome.provisional);
    confirmations.fetch_add(1);
    auto out = std::make_shared<PointOutcome>(static_cast<const PointOutcome&>(outcome));
    EXPECT_EQ(out->x, x);
    out->provisional = false;
    if (x[0] > kLimit) out->constraint = 1 + (x[0] - kLimit);
    return out;
  }
  void tally(const Outcome&, nlohmann::json& ledger) const override {
    const long long total = ledger.is_object() ? ledger.value("total", 0LL) : 0LL;
    ledger["total"] = total + 1;
  }
  static constexpr double kLimit = 0.45;
  mutable std::atomic<long long> confirmations{0};
};

class Confirmation : public ::testing::TestWithParam<DiversityStrategy> {};

TEST_P(Confirmation, EveryVariationStandsOnlyWhereItsCheckHolds) {
  const CheckedBallProblem problem;
  DiversityOptions o = small_options(GetParam(), 30);
  o.point = VariationPoint::kBestSample;
  ThreadPool two(2);
  DiversityOptimizer opt(problem, o, two);
  opt.run();
  // Without the check, variations spread over the whole ball (x[0] up to 0.7); with it,
  // every point of the result, and every point a path went through, passed it.
  const DiversityResult r = opt.result();
  for (std::size_t i = 0; i < r.parameters.size(); ++i) {
    EXPECT_LE(r.parameters[i][0], CheckedBallProblem::kLimit) << "M" << i;
    EXPECT_FALSE(r.outcomes[i]->provisional) << "M" << i;
    EXPECT_EQ(r.outcomes[i]->constraint, 0.0) << "M" << i;
  }
  for (const auto& path : opt.paths())
    for (const PathPoint& p : path) EXPECT_LE(p.x[0], CheckedBallProblem::kLimit);
  // The checks ran where they decided something: far fewer than the feasible samples.
  long long feasible = 0;
  for (const DiversityRecord& record : opt.log()) feasible += record.feasible;
  EXPECT_GT(opt.confirmations(), 0);
  EXPECT_EQ(opt.confirmations(), problem.confirmations.load());
  // (The joint strategy scores whole sets, so it confirms every provisional motion.)
  if (GetParam() != DiversityStrategy::kJoint) {
    EXPECT_LT(opt.confirmations(), feasible / 2);
  }
  // Every evaluation and confirmation was tallied once.
  EXPECT_EQ(opt.ledger().value("total", 0LL), opt.evaluations() + opt.confirmations());
  EXPECT_EQ(opt.log().back().confirmations, opt.confirmations());
}

TEST_P(Confirmation, DeterministicAndResumable) {
  const CheckedBallProblem problem;
  for (VariationPoint point : {VariationPoint::kMean, VariationPoint::kBestSample}) {
  SCOPED_TRACE(to_string(point));
  DiversityOptions o = small_options(GetParam(), 16);
  o.point = point;
  ThreadPool one(1), three(3);
  DiversityOptimizer a(problem, o, one), b(problem, o, three);
  a.run();
  b.run();
  expect_identical(a, b);
  DiversityOptimizer first(problem, o, one);
  for (int g = 0; g < 7; ++g) first.step();
  DiversityOptimizer resumed =
      DiversityOptimizer::from_checkpoint(problem, nlohmann::json::parse(first.checkpoint().dump()), three);
  EXPECT_EQ(resumed.confirmations(), first.confirmations());
  EXPECT_EQ(resumed.ledger(), first.ledger());
  resumed.run();
  expect_identical(a, resumed);
  EXPECT_EQ(resumed.ledger(), a.ledger());
  }
}

INSTANTIATE_TEST_SUITE_P(All, Confirmation, kAllStrategies, strategy_test_name);

}  // namespace
}  // namespace diverse

namespace diverse {
namespace {

// Best-sample round-robin simulates every variation's samples of a generation in one
// batch and confirms two candidates at a time, yet moves exactly as with one batch per
// variation and one check at a time. The reference is that run (the same seed, before
// either): its best D, where the variations stand and how many checks it made.
TEST(DiversityRoundRobin, OneBatchPerGenerationMovesAsOneBatchPerVariation) {
  const CheckedBallProblem problem;
  DiversityOptions o = small_options(DiversityStrategy::kRoundRobin, 30);
  o.point = VariationPoint::kBestSample;
  ThreadPool two(2);
  CountingBatch batch(problem);
  DiversityOptimizer opt(problem, o, two, &batch);
  opt.run();
  const DiversityResult r = opt.result();
  EXPECT_EQ(r.score.D, 0x1.0572f9e52cc95p+4);
  const std::vector<std::array<double, 3>> reference{
      {0x1.999999999999ap-2, 0x1.999999999999ap-2, 0x1.999999999999ap-2},
      {0x1.2dc74fc7cbe31p-2, 0x1.554d4ffeb2b89p-1, 0x1.f27925347cc6bp-2},
      {0x1.8245d8363490fp-2, 0x1.82584caf72467p-2, 0x1.a1bb4e77248f2p-4},
      {0x1.ccbbdfad4849dp-2, 0x1.b20594a7cef93p-4, 0x1.9ace4ac5446b6p-2}};
  ASSERT_EQ(r.parameters.size(), reference.size());
  for (std::size_t i = 0; i < reference.size(); ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(r.parameters[i][k], reference[i][static_cast<std::size_t>(k)]) << "M" << i;
  // M_0, then one batch of N x lambda per generation.
  ASSERT_EQ(batch.sizes.size(), 31u);
  for (std::size_t g = 1; g < batch.sizes.size(); ++g) EXPECT_EQ(batch.sizes[g], 3u * 16u);
  // One check at a time made 107; two at a time wastes the second where the first held.
  EXPECT_EQ(opt.confirmations(), 114);
  EXPECT_EQ(opt.confirmations(), problem.confirmations.load());
  EXPECT_EQ(opt.ledger().value("total", 0LL), opt.evaluations() + opt.confirmations());
}

}  // namespace
}  // namespace diverse
