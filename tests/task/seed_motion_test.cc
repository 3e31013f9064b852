// Searching for input motions: the perturbations the robustness term and the robustness
// check use stay in the normalized box, follow their seed alone and have the asked-for
// spread; the robustness check tells a motion's neighbourhood apart from random
// controllers; the search's own requirement on the flight rotation is enforced; the
// robustness term keeps the search independent of the number of threads; and a
// requirement beyond the task (`--robust`) is judged only on candidates that meet the
// task, a candidate that fails it never being the result.
#include "task/seed_motion.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <mutex>
#include <string>
#include <vector>

#include "task/evaluate.h"

namespace diverse {
namespace {

const std::string kTasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";
// The high jump with the paper's foot targets and its input motion then, which hops before
// the jump and lands 2 cm apart at the two timesteps (tests/task/data/jump_high_paper_feet.toml):
// a neighbourhood part of which parts at half the step, as the tests of the check need.
const std::string kPaperFeet = std::string(DIVERSE_SOURCE_DIR) + "/tests/task/data/jump_high_paper_feet.toml";

TEST(Perturb, StaysInTheBoxAndReflectsAtItsBounds) {
  // The direction of sample 0 of seed 9, read off a point far from the bounds.
  const Eigen::VectorXd mid = Eigen::VectorXd::Constant(6, 0.5);
  const Eigen::VectorXd z = (perturb(mid, 1e-3, 1, 9)[0] - mid) / 1e-3;
  // Scaled so that the largest step is 0.4: from 0.1 and 0.9 some steps cross a bound and
  // come back into the box as mirror images.
  const double sigma = 0.4 / z.cwiseAbs().maxCoeff();
  const Eigen::VectorXd lo = perturb(Eigen::VectorXd::Constant(6, 0.1), sigma, 1, 9)[0];
  const Eigen::VectorXd hi = perturb(Eigen::VectorXd::Constant(6, 0.9), sigma, 1, 9)[0];
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(lo[i], std::fabs(0.1 + sigma * z[i]), 1e-9) << i;
    EXPECT_NEAR(hi[i], 1 - std::fabs(0.9 + sigma * z[i] - 1), 1e-9) << i;
  }
  // Steps of any size, from anywhere in the box, stay in it.
  Eigen::VectorXd x(4);
  x << 0.0, 1.0, 0.5, 0.999;
  for (const Eigen::VectorXd& y : perturb(x, 0.7, 50, 3)) {
    EXPECT_GE(y.minCoeff(), 0.0);
    EXPECT_LE(y.maxCoeff(), 1.0);
  }
}

TEST(Perturb, DependsOnTheSeedOnlyAndHasTheAskedSpread) {
  const Eigen::VectorXd x = Eigen::VectorXd::Constant(90, 0.5);
  const auto a = perturb(x, 0.02, 3, 11), b = perturb(x, 0.02, 200, 11), c = perturb(x, 0.02, 3, 12);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(a[k], b[k]) << k;  // sample k does not depend on count
  EXPECT_NE(a[0], c[0]);
  double sum = 0, sum2 = 0;
  for (const Eigen::VectorXd& y : b) {
    sum += (y - x).sum();
    sum2 += (y - x).squaredNorm();
  }
  const double n = 200.0 * 90;
  EXPECT_NEAR(sum / n, 0.0, 0.001);
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.02, 0.001);
}

TEST(Robustness, TellsAMotionsNeighbourhoodFromRandomControllers) {
  const Task task = load_task(kTasks + "jump_high.toml");
  const TaskEvaluator ev(task);
  const ParameterSet m0 = ev.load_parameters(task.m0);
  const RobustnessReport r = measure_robustness(task, m0, {1e-9, 0.5}, 4, 2);
  EXPECT_EQ(r.constraint, 0.0);
  EXPECT_EQ(r.constraint_fine, 0.0);
  ASSERT_EQ(r.levels.size(), 2u);
  EXPECT_EQ(r.levels[0].sigma, 1e-9);
  EXPECT_EQ(r.levels[0].samples, 4);
  EXPECT_EQ(r.levels[0].met, 4);  // a billionth of the ranges changes nothing that matters
  EXPECT_EQ(r.levels[1].met, 0);  // half the ranges: a random controller
  EXPECT_EQ(r.levels[1].fraction(), 0.0);
}

// A sigma's perturbations do not depend on the other sigmas measured with it: the same
// 8 constraint values at 0.03 alone, after another sigma, and in another order. (They once
// came from the sigma's index in the list, so `--check-sigmas 0.01 0.02` and
// `--check-sigmas 0.005 0.01 0.02` reported different counts at 0.02.)
TEST(Robustness, ASigmasPerturbationsDoNotDependOnTheOtherSigmas) {
  const Task task = load_task(kTasks + "jump_high.toml");
  const TaskEvaluator ev(task);
  const ParameterSet m0 = ev.load_parameters(task.m0);
  const RobustnessReport alone = measure_robustness(task, m0, {0.03}, 8, 2);
  const RobustnessReport after = measure_robustness(task, m0, {0.005, 0.03}, 8, 2);
  const RobustnessReport before = measure_robustness(task, m0, {0.03, 0.005}, 8, 2);
  ASSERT_EQ(alone.levels[0].constraints.size(), 8u);
  EXPECT_EQ(after.levels[1].constraints, alone.levels[0].constraints);
  EXPECT_EQ(before.levels[0].constraints, alone.levels[0].constraints);
  EXPECT_EQ(after.levels[0].constraints, before.levels[1].constraints);
  // and they are samples of a neighbourhood, not one repeated point
  EXPECT_NE(alone.levels[0].constraints, std::vector<double>(8, alone.levels[0].constraints[0]));
  EXPECT_NE(robustness_seed(task, 0.03), robustness_seed(task, 0.02));
}

// Convergence in the timestep: the high jump's input motion and its neighbours come down
// within a centimetre of one spot at the task's step, half and a quarter of it, and nearer
// as the step shrinks; those of jump_over's input motion found under stable PD
// (tests/task/data/jump_over_stable_pd.toml) part as far between half and a quarter of the step as
// between the step and half of it (a neighbourhood riding on chaotic dynamics), already in
// their peak heights, set at take-off, and its input motion lands 17 cm further at a quarter
// of the step, where it falls. Thread counts
// do not change the figures, and a walk has no touch-down to compare.
TEST(Robustness, ConvergenceInTheTimestepTellsAChaoticNeighbourhood) {
  const Task high = load_task(kTasks + "jump_high.toml");
  const RobustnessReport h = measure_robustness(high, TaskEvaluator(high).load_parameters(high.m0), {0.005}, 8, 2, true);
  const TimestepConvergence& hc = h.levels[0].convergence;
  EXPECT_EQ(hc.compared, 8);
  EXPECT_LT(hc.half_mean, 0.01);
  EXPECT_LT(hc.quarter_mean, 0.01);
  EXPECT_LE(hc.half_mean, hc.half_max);
  EXPECT_NEAR(h.touchdown_x[1], h.touchdown_x[2], 0.01);
  EXPECT_LT(hc.peak_quarter_mean, 0.005);  // its take-off converges (measured: 3.6 mm)
  EXPECT_EQ(h.constraint_quarter, 0.0);

  const Task over = load_task(std::string(DIVERSE_SOURCE_DIR) + "/tests/task/data/jump_over_stable_pd.toml");
  const ParameterSet m0 = TaskEvaluator(over).load_parameters(over.m0);
  const RobustnessReport o = measure_robustness(over, m0, {0.005}, 8, 2, true);
  const TimestepConvergence& oc = o.levels[0].convergence;
  EXPECT_EQ(oc.compared, 8);
  EXPECT_GT(oc.quarter_mean, 0.03);
  EXPECT_GT(oc.quarter_mean, 0.5 * oc.half_mean);
  EXPECT_GT(oc.peak_quarter_mean, 0.005);  // the parting starts in the push-off
  EXPECT_GT(std::fabs(o.touchdown_x[2] - o.touchdown_x[1]), 0.1);
  EXPECT_GE(o.constraint_quarter, over.constraints.fall_penalty);
  // The same figures on one thread.
  const RobustnessReport one = measure_robustness(over, m0, {0.005}, 8, 1, true);
  EXPECT_EQ(one.levels[0].convergence.quarter_mean, oc.quarter_mean);
  EXPECT_EQ(one.levels[0].convergence.half_max, oc.half_max);

  const Task walk = load_task(kTasks + "robot_silly_walk.toml");
  EXPECT_THROW(measure_robustness(walk, TaskEvaluator(walk).load_parameters(walk.m0), {0.005}, 1, 1, true),
               std::logic_error);
}

// A perturbation meets the task as the diversity optimizer judges it: where the task has
// the half-timestep check, one that meets it at 2 ms but lands elsewhere (or falls) at 1 ms
// does not count. The high jump's input motion with the paper's foot targets lands 2.0 cm apart at the two timesteps
// (3 cm allowed): steps of a thousandth of the ranges already part some of them (6 of
// the 16 that meet the task at 2 ms).
TEST(Robustness, ThePerturbationsAreJudgedWithTheHalfTimestepCheck) {
  Task task = load_task(kPaperFeet);
  ASSERT_TRUE(task.constraints.half_timestep);
  const TaskEvaluator ev(task);
  const ParameterSet m0 = ev.load_parameters(task.m0);
  const RobustnessReport checked = measure_robustness(task, m0, {1e-3}, 16, 2);
  task.constraints.half_timestep = false;
  const RobustnessReport unchecked = measure_robustness(task, m0, {1e-3}, 16, 2);
  EXPECT_GE(unchecked.levels[0].met, 10);
  EXPECT_LE(checked.levels[0].met, unchecked.levels[0].met - 4) << checked.levels[0].met;
}

TEST(SeedMotion, AFlightRotationRequirementTheMotionMissesIsAViolation) {
  // The backflip M0 meets its task, but no candidate near it turns a full 2 pi between
  // take-off and touch-down.
  const Task task = load_task(kTasks + "backflip.toml");
  const TaskEvaluator ev(task);
  const ParameterSet m0 = ev.load_parameters(task.m0);
  SeedOptions options;
  options.threads = 2;
  options.generations = 1;
  options.min_flight_rotation = 2 * M_PI;
  const SeedResult r = seed_motion(task, m0, options);
  EXPECT_GT(r.constraint, 0.0);
  EXPECT_EQ(r.evaluations, 2 * (1 + task.seed.popsize));
}

TEST(SeedMotion, TheRobustnessTermGivesTheSameResultOnAnyNumberOfThreads) {
  const Task task = load_task(kTasks + "jump_high.toml");
  const TaskEvaluator ev(task);
  const ParameterSet m0 = ev.load_parameters(task.m0);
  SeedOptions options;
  options.generations = 1;
  options.perturbations = 2;
  options.perturbation_sigma = 0.02;
  options.selection_samples = 8;
  options.threads = 1;
  const SeedResult one = seed_motion(task, m0, options);
  options.threads = 2;
  const SeedResult two = seed_motion(task, m0, options);
  EXPECT_EQ(one.parameters.values(), two.parameters.values());
  EXPECT_EQ(one.robustness, two.robustness);
  EXPECT_EQ(one.lowest_mean.values(), two.lowest_mean.values());
  EXPECT_EQ(one.selected, two.selected);
  // The generation's rollouts, then the selection's: each candidate at both timesteps and
  // at its 8 perturbations.
  EXPECT_EQ(one.evaluations, 4 * (1 + task.seed.popsize) + one.selection_candidates * (2 + 8));
  EXPECT_EQ(two.evaluations, one.evaluations);
}

// The push term (SeedOptions::pushes): every candidate is also simulated with its root
// pushed, as the robustness suite pushes, and the pushed rollouts count in the objective
// and in the share of the robustness rollouts that meet the task. A push too small to
// matter leaves the high jump's input motion meeting the task in nearly every one; a push
// of 3 m/s, which no standing or landing human holds, in nearly none. Each candidate costs
// its two rollouts (both timesteps) and one per push.
TEST(SeedMotion, PushesAreSimulatedAndCountInTheObjectiveAndTheShare) {
  const Task task = load_task(kTasks + "jump_high.toml");
  const TaskEvaluator ev(task);
  const ParameterSet m0 = ev.load_parameters(task.m0);
  SeedOptions options;
  options.threads = 2;
  options.generations = 1;
  options.sigma = 1e-4;  // candidates next to the input motion, which holds pushes it cannot feel
  options.pushes = 6;
  options.selection_samples = 0;
  options.objective = SeedObjective::kShare;
  options.push_speed = 1e-6;
  const SeedResult gentle = seed_motion(task, m0, options);
  options.push_speed = 3.0;
  const SeedResult hard = seed_motion(task, m0, options);
  EXPECT_EQ(gentle.constraint, 0.0);
  EXPECT_GE(gentle.robustness, 5.0 / 6.0);
  EXPECT_LE(hard.robustness, 1.0 / 6.0);
  // The start, the generation and the result, each at both timesteps and at its 6 pushes.
  EXPECT_EQ(gentle.evaluations, 8 * (1 + task.seed.popsize));
  // The same on two threads as on one.
  options.threads = 1;
  const SeedResult one = seed_motion(task, m0, options);
  EXPECT_EQ(one.parameters.values(), hard.parameters.values());
  EXPECT_EQ(one.robustness, hard.robustness);
}

// The share objective counts the rollouts that miss the task, and ranks the misses among
// themselves: a near miss (C = 25, a landing 7 cm out) costs about as much as a fall, and
// a candidate with half its rollouts meeting ranks above one whose rollouts all miss
// narrowly, which the mean C ranks the other way round.
TEST(SeedMotion, TheShareObjectiveRanksMeetingAboveNearMisses) {
  using enum SeedObjective;
  EXPECT_EQ(objective_term(kShare, 0.0), 0.0);
  EXPECT_GT(objective_term(kShare, 1e-9), 1.0);
  EXPECT_LT(objective_term(kShare, 25.0), objective_term(kShare, 1e5));
  EXPECT_LT(objective_term(kShare, 3e5), 1.13);
  EXPECT_EQ(objective_term(kMeanC, 25.0), 25.0);
  auto mean = [](SeedObjective o, const std::vector<double>& c) {
    double sum = 0;
    for (double v : c) sum += objective_term(o, v);
    return sum / static_cast<double>(c.size());
  };
  const std::vector<double> half_met{0, 0, 0, 0, 1e5, 1e5, 1e5, 1e5};
  const std::vector<double> all_near{25, 25, 25, 25, 25, 25, 25, 25};
  EXPECT_LT(mean(kShare, half_met), mean(kShare, all_near));
  EXPECT_GT(mean(kMeanC, half_met), mean(kMeanC, all_near));

  // A search with it reports objectives on its scale: at most 1.13 for any candidate.
  const Task task = load_task(kTasks + "jump_high.toml");
  const TaskEvaluator ev(task);
  SeedOptions options;
  options.threads = 2;
  options.generations = 1;
  options.perturbations = 2;
  options.perturbation_sigma = 0.03;
  options.selection_samples = 0;
  options.objective = kShare;
  std::vector<double> lowest;
  options.log = [&](const std::string& line) {
    const auto at = line.find("lowest f=");
    if (at != std::string::npos) lowest.push_back(std::stod(line.substr(at + 9)));
  };
  const SeedResult r = seed_motion(task, ev.load_parameters(task.m0), options);
  ASSERT_EQ(lowest.size(), 1u);
  EXPECT_LE(lowest[0], 1.13);
  EXPECT_GE(lowest[0], -task.seed.robustness * 0.1);
  EXPECT_NEAR(r.lowest_mean_f, lowest[0], 1e-5);  // printed to 6 digits
}

// The selection that ends a search with perturbations: every candidate is judged on the same
// fixed perturbations, and the result is the one that meets the task whose perturbations
// meet it most often, so a search from a motion that meets the task never returns one that
// holds fewer of them. Counted here from outside, with the half-timestep check as the
// diversity optimizer judges a sample.
TEST(SeedMotion, TheSelectionNeverReturnsAMotionHoldingLessOfItsPerturbationsThanTheStart) {
  const Task task = load_task(kTasks + "jump_high.toml");
  const TaskEvaluator ev(task);
  const ParameterSet m0 = ev.load_parameters(task.m0);
  SeedOptions options;
  options.threads = 2;
  options.generations = 2;
  options.sigma = 0.02;
  options.perturbations = 2;
  options.perturbation_sigma = 0.03;
  options.selection_samples = 12;
  std::vector<std::string> lines;
  options.log = [&](const std::string& line) { lines.push_back(line); };
  const SeedResult r = seed_motion(task, m0, options);
  ASSERT_EQ(r.constraint, 0.0);
  ASSERT_FALSE(r.selected.empty());
  // The start and the CMA-ES mean are always among the candidates, and so is every
  // generation's candidate that met the task, up to six.
  EXPECT_GE(r.selection_candidates, 2);
  EXPECT_LE(r.selection_candidates, 8);
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines.back().rfind("selection on 12 perturbations of each", 0), 0u) << lines.back();
  EXPECT_NE(lines.back().find("chosen: " + r.selected), std::string::npos) << lines.back();

  EvaluationOptions judged;
  judged.samples_per_phase = 0;
  judged.half_timestep_check = true;
  auto worker = ev.make_worker();
  auto held = [&](const ParameterSet& p) {
    int met = 0;
    for (const Eigen::VectorXd& y : selection_perturbations(task, p.normalized(), options))
      met += ev.evaluate_normalized(y, *worker, judged).constraint == 0 ? 1 : 0;
    return met;
  };
  const int start_held = held(m0);
  const int result_held = held(r.parameters);
  EXPECT_GE(result_held, start_held);
  EXPECT_DOUBLE_EQ(r.robustness, result_held / 12.0);
  // The perturbations are the selection's own, not the robustness check's.
  EXPECT_NE(selection_perturbations(task, m0.normalized(), options)[0],
            perturb(m0.normalized(), 0.03, 1, robustness_seed(task, 0.03))[0]);

  // Without the selection, the result is the candidate with the lowest objective.
  options.selection_samples = 0;
  const SeedResult plain = seed_motion(task, m0, options);
  EXPECT_TRUE(plain.selected.empty());
  EXPECT_EQ(plain.selection_candidates, 0);
  EXPECT_EQ(plain.evaluations, 4 * (1 + 2 * task.seed.popsize));
}

// The landing spot is where the feet touch down and where they rest, whichever moved more.
TEST(SeedMotion, LandingShiftIsTheLargerOfTouchdownAndRest) {
  MotionSummary a, b;
  a.touchdown_feet_x = 1.00;
  b.touchdown_feet_x = 0.98;
  a.feet_x = 1.10;
  b.feet_x = 1.15;
  EXPECT_NEAR(landing_shift(a, b), 0.05, 1e-12);
  EXPECT_NEAR(landing_shift(b, a), 0.05, 1e-12);
  b.touchdown_feet_x = 0.9;
  EXPECT_NEAR(landing_shift(a, b), 0.10, 1e-12);
  EXPECT_EQ(landing_shift(a, a), 0.0);
}

// A perturbation of jump_high's input motion meets its task at both timesteps, but lands
// 11 cm apart at the two (more than the 3 cm an input motion is searched for within): to the
// search it is not yet an input motion, and neither is any candidate of one generation
// close around it. (At 1 ms it topples two seconds after it slows down: the landing counts
// as at rest once slow, balanced or not, as in tests/task/half_timestep_test.cc.)
TEST(SeedMotion, LandingSpotsApartAtTheTwoTimestepsAreAViolation) {
  Task task = load_task(kPaperFeet);
  task.simulation.balanced_rest = false;
  const TaskEvaluator ev(task);
  const ParameterSet m0 = ev.load_parameters(std::string(DIVERSE_SOURCE_DIR) +
                                             "/tests/task/data/jump_high_lands_apart.json");
  const RobustnessReport check = measure_robustness(task, m0, {}, 0, 1);
  EXPECT_EQ(check.constraint, 0.0);
  EXPECT_EQ(check.constraint_fine, 0.0);
  EXPECT_GT(check.landing_shift, kTimestepAgreement);
  SeedOptions options;
  options.threads = 2;
  options.generations = 1;
  options.sigma = 1e-6;  // candidates barely different from M0
  const SeedResult r = seed_motion(task, m0, options);
  const double d = check.landing_shift - kTimestepAgreement;
  EXPECT_GT(r.constraint, 0.0);  // M0's K_c d^2 or a candidate's smaller one, never 0
  EXPECT_LE(r.constraint, task.constraints.weight * d * d + 1e-12);
}

// A requirement beyond the task is judged only on candidates that meet the task at both
// timesteps, and one it rejects gets its penalty: with a requirement that rejects
// everything, no candidate near jump_high's input motion (which meets the task) is
// accepted. (A millionth of the ranges from it, some candidates may miss the task by a
// hair: it lands 2.0 cm apart at the two timesteps, 3 cm allowed.)
TEST(SeedMotion, ARequirementIsJudgedOnlyOnCandidatesThatMeetTheTask) {
  const Task task = load_task(kTasks + "jump_high.toml");
  const TaskEvaluator ev(task);
  const ParameterSet m0 = ev.load_parameters(task.m0);
  std::mutex mutex;
  std::vector<ParameterSet> judged;
  SeedOptions options;
  options.threads = 2;
  options.generations = 1;
  options.sigma = 1e-6;  // candidates barely different from M0: they meet the task too
  options.requirement.name = "never";
  options.requirement.penalty = 25;
  options.requirement.check = [&](const ParameterSet& p) {
    const std::lock_guard<std::mutex> lock(mutex);
    judged.push_back(p);
    return SeedRequirement::Verdict{false, 3};
  };
  const SeedResult r = seed_motion(task, m0, options);
  EXPECT_GT(r.constraint, 0.0);  // nothing was accepted
  EXPECT_EQ(r.requirement_held, 0);
  // The start (which meets the task) and most candidates were judged, and the result
  // once more when it met the task: then its C is the penalty.
  EXPECT_GT(r.requirement_checks, task.seed.popsize / 2);
  EXPECT_EQ(static_cast<long long>(judged.size()), r.requirement_checks + (r.requirement_failed ? 1 : 0));
  if (r.requirement_failed) {
    EXPECT_EQ(r.constraint, 25.0);
  }
  EXPECT_EQ(r.evaluations, 2 * (1 + task.seed.popsize) + 3 * r.requirement_checks);
  // Each judged candidate met the task at the task's timestep and at half of it.
  EvaluationOptions fine;
  fine.timestep_scale = 0.5;
  for (const ParameterSet& p : judged) {
    EXPECT_EQ(ev.evaluate_named(p).constraint, 0.0);
    EXPECT_EQ(ev.evaluate_named(p, fine).constraint, 0.0);
  }

  // A candidate that misses the task is not judged: far from M0 (sigma 0.3), most miss.
  judged.clear();
  options.sigma = 0.3;
  const SeedResult far = seed_motion(task, m0, options);
  EXPECT_EQ(static_cast<long long>(judged.size()), far.requirement_checks + (far.requirement_failed ? 1 : 0));
  EXPECT_LT(far.requirement_checks, 1 + task.seed.popsize);
  EXPECT_GT(far.constraint, 0.0);
}

// A requirement every candidate passes changes nothing but the count of rollouts.
TEST(SeedMotion, ARequirementEveryCandidatePassesChangesNothing) {
  const Task task = load_task(kTasks + "jump_high.toml");
  const TaskEvaluator ev(task);
  const ParameterSet m0 = ev.load_parameters(task.m0);
  SeedOptions options;
  options.threads = 2;
  options.generations = 1;
  options.sigma = 0.003;
  const SeedResult plain = seed_motion(task, m0, options);
  std::atomic<int> calls{0};
  options.requirement.name = "always";
  options.requirement.penalty = 25;
  options.requirement.check = [&](const ParameterSet&) {
    ++calls;
    return SeedRequirement::Verdict{true, 1};
  };
  const SeedResult with = seed_motion(task, m0, options);
  EXPECT_EQ(with.parameters.values(), plain.parameters.values());
  EXPECT_EQ(with.constraint, plain.constraint);
  EXPECT_FALSE(with.requirement_failed);
  EXPECT_EQ(with.requirement_held, with.requirement_checks);
  EXPECT_GT(with.requirement_checks, 0);
  EXPECT_EQ(with.evaluations, plain.evaluations + with.requirement_checks);
  EXPECT_EQ(calls.load(), with.requirement_checks + (plain.constraint == 0 ? 1 : 0));
  // A requirement without a penalty would let a failure meet the task: refused.
  options.requirement.penalty = 0;
  EXPECT_THROW(seed_motion(task, m0, options), std::invalid_argument);
}

}  // namespace
}  // namespace diverse
