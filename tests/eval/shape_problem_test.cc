// MotionProblem with the body shape as free parameters (paper section 8): the layout of
// the parameter vector, that M0's own shape reproduces the motion-only problem exactly,
// that every outcome is a pure function of x whatever a worker ran before, bodies that
// cannot stand, and the shape and combined distances.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/error.h"
#include "eval/motion_problem.h"
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

// The index of shape parameter "shape.NAME" of the task's shape space.
int shape_param(const Fixture& f, const std::string& name) {
  const auto& specs = f.evaluator.shapes().specs();
  for (std::size_t p = 0; p < specs.size(); ++p)
    if (specs[p].name == "shape." + name) return static_cast<int>(p);
  ADD_FAILURE() << "no shape parameter " << name;
  return 0;
}

const MotionOutcome& motion(const std::shared_ptr<const Outcome>& o) {
  return static_cast<const MotionOutcome&>(*o);
}

// Bit-for-bit equality of two outcomes' pose samples.
void expect_same_poses(const MotionOutcome& a, const MotionOutcome& b) {
  ASSERT_EQ(a.features.poses.size(), b.features.poses.size());
  for (std::size_t k = 0; k < a.features.poses.size(); ++k) {
    EXPECT_EQ(a.features.poses[k].link_com, b.features.poses[k].link_com) << k;
    EXPECT_EQ(a.features.poses[k].angles, b.features.poses[k].angles) << k;
  }
}

// Normalized x of M0's controller with the given shape scales.
Eigen::VectorXd shaped_x(const Fixture& f, const Eigen::VectorXd& scales) {
  return f.evaluator.with_shape(f.m0, scales).normalized();
}

TEST(ShapeProblem, ParametersAreTheControllersFollowedByTheShape) {
  Fixture& f = fixture();
  const MotionProblem problem(f.evaluator, DistanceSpec{Metric::kShape, 0.0}, f.shaped_m0.normalized(), 1, true);
  const int control = f.evaluator.dim();
  ASSERT_EQ(problem.dim(), control + 10);
  EXPECT_EQ(problem.parameters().specs()[static_cast<std::size_t>(control)].name, "shape.pelvis");
  EXPECT_EQ(problem.parameters().specs().back().name, "shape.hand");
  // M0's body: scale 1, normalized (1 - lower) / (upper - lower).
  const Eigen::VectorXd x = problem.reference();
  EXPECT_DOUBLE_EQ(x[control + shape_param(f, "thigh")], (1 - 0.4) / 2.1);
  EXPECT_DOUBLE_EQ(x[control + shape_param(f, "head")], (1 - 0.429) / (2.5 - 0.429));
  const ParameterSet named = problem.named(x);
  for (int p = 0; p < f.evaluator.shapes().size(); ++p)
    EXPECT_NEAR(named.values()[static_cast<std::size_t>(control + p)], 1.0, 1e-15);
  // A scale at the top of its range comes back exactly on the bound.
  Eigen::VectorXd top = x;
  top.tail(f.evaluator.shapes().size()).setOnes();
  for (int p = 0; p < f.evaluator.shapes().size(); ++p) EXPECT_EQ(problem.named(top).values()[static_cast<std::size_t>(control + p)], 2.5);

  // A distance on the shape needs the shape to vary.
  EXPECT_THROW(MotionProblem(f.evaluator, DistanceSpec{Metric::kShape, 0.0}, f.m0.normalized(), 1, false),
               std::logic_error);
}

TEST(ShapeProblem, M0sOwnShapeReproducesTheMotionOnlyProblemExactly) {
  Fixture& f = fixture();
  const MotionProblem plain(f.evaluator, Metric::kMassDistance, f.m0.normalized(), 1);
  const MotionProblem shaped(f.evaluator, DistanceSpec{Metric::kMassDistance, 0.0}, f.shaped_m0.normalized(), 1,
                             true);
  const auto a = plain.evaluate(plain.reference(), 0);
  const auto b = shaped.evaluate(shaped.reference(), 0);
  EXPECT_EQ(a->constraint, 0.0);
  EXPECT_EQ(b->constraint, 0.0);
  EXPECT_EQ(motion(a).peak_com_z, motion(b).peak_com_z);
  EXPECT_EQ(motion(a).landing_x, motion(b).landing_x);
  expect_same_poses(motion(a), motion(b));
  EXPECT_EQ(motion(b).features.poses.size(), 20u);
  // Both know the body's link lengths: the task's, in metres.
  EXPECT_EQ(motion(a).features.link_lengths, f.evaluator.shapes().base_link_lengths());
  EXPECT_EQ(motion(b).features.link_lengths, f.evaluator.shapes().base_link_lengths());
  EXPECT_EQ(plain.distance(*a, *b, Metric::kShape), 0.0);
}

TEST(ShapeProblem, OutcomesArePureFunctionsOfXWhateverTheWorkerRanBefore) {
  Fixture& f = fixture();
  const MotionProblem problem(f.evaluator, DistanceSpec{Metric::kShape, 0.0}, f.shaped_m0.normalized(), 2, true);
  Eigen::VectorXd longer_legs = f.evaluator.shapes().identity();
  longer_legs[shape_param(f, "shin")] = 1.05;
  longer_legs[shape_param(f, "foot")] = 1.1;
  Eigen::VectorXd shorter_arms = f.evaluator.shapes().identity();
  shorter_arms[shape_param(f, "forearm")] = 0.8;
  const Eigen::VectorXd xa = shaped_x(f, longer_legs), xb = shaped_x(f, shorter_arms);

  const auto first = problem.evaluate(xa, 0);   // worker 0 builds shape a
  const auto other = problem.evaluate(xb, 0);   // ... then shape b
  const auto again = problem.evaluate(xa, 0);   // ... then a again
  const auto fresh = problem.evaluate(xa, 1);   // a on a worker that ran nothing else
  const auto repeat = problem.evaluate(xa, 1);  // a reused as it stands
  for (const auto& o : {again, fresh, repeat}) {
    EXPECT_EQ(o->constraint, first->constraint);
    EXPECT_EQ(motion(o).peak_com_z, motion(first).peak_com_z);
    expect_same_poses(motion(o), motion(first));
  }
  // The bodies differ, and so do the motions.
  EXPECT_NE(motion(first).peak_com_z, motion(other).peak_com_z);
  const Eigen::VectorXd& base = f.evaluator.shapes().base_link_lengths();
  const double expected = 2 * (0.05 * base[2] + 0.1 * base[3]) + 2 * 0.2 * base[12];  // shins, feet; forearms
  EXPECT_NEAR(problem.distance(*first, *other), expected, 1e-12);
  EXPECT_EQ(problem.distance(*first, *other), problem.distance(*other, *first));
}

TEST(ShapeProblem, ABodyWhoseHandsStartBelowTheFloorFallsAtOnce) {
  Fixture& f = fixture();
  Eigen::VectorXd scales = f.evaluator.shapes().identity();
  scales[shape_param(f, "upperarm")] = 2.5;
  scales[shape_param(f, "forearm")] = 2.5;
  const auto scene = f.evaluator.shaped_scene(scales);
  ASSERT_TRUE(scene->below_floor());
  SimWorker worker(scene->model);
  const Evaluation e = f.evaluator.evaluate(f.m0.values(), *scene, worker);
  EXPECT_TRUE(e.fell);
  EXPECT_NE(e.summary.fall_reason.find("starts with a hand or arm"), std::string::npos) << e.summary.fall_reason;
  EXPECT_NE(e.summary.fall_reason.find("below the floor"), std::string::npos);
  // The earliest fall: twice the task's fall penalty (beside the terms of a jump that
  // never happened).
  const double fall = 2 * f.evaluator.task().constraints.fall_penalty;
  bool found = false;
  for (const ConstraintTerm& t : e.report.terms) {
    if (t.name != "fall") continue;
    found = true;
    EXPECT_EQ(t.penalty, fall);
  }
  EXPECT_TRUE(found);
  EXPECT_GE(e.constraint, fall);
  // The simulation saw it too: it stopped at the first step.
  EXPECT_LE(e.stats.steps, 1);

  // The base body stands: its hands are above the floor.
  EXPECT_FALSE(f.evaluator.shaped_scene(f.evaluator.shapes().identity())->below_floor());
}

TEST(ShapeProblem, OutOfTheBoxSamplesFailAndCombinedDistancesAddTheWeightedShape) {
  Fixture& f = fixture();
  const DistanceSpec combined{Metric::kMassDistance, 7.5};
  const MotionProblem problem(f.evaluator, combined, f.shaped_m0.normalized(), 1, true);
  Eigen::VectorXd outside = problem.reference();
  outside[problem.dim() - 1] = 1.2;
  const auto failed = problem.evaluate(outside, 0);
  EXPECT_TRUE(failed->failed);
  EXPECT_EQ(failed->constraint, 3 * f.evaluator.task().constraints.fall_penalty);

  Eigen::VectorXd scales = f.evaluator.shapes().identity();
  scales[shape_param(f, "chest")] = 1.1;
  const auto a = problem.evaluate(problem.reference(), 0);
  const auto b = problem.evaluate(shaped_x(f, scales), 0);
  const double md = problem.distance(*a, *b, Metric::kMassDistance);
  const double shape = problem.distance(*a, *b, Metric::kShape);
  EXPECT_GT(md, 0.0);
  EXPECT_NEAR(shape, 0.1 * f.evaluator.shapes().base_link_lengths()[8], 1e-12);
  EXPECT_DOUBLE_EQ(problem.distance(*a, *b), md + 7.5 * shape);
}

TEST(DistanceSpec, ParsesSingleAndCombinedMetrics) {
  EXPECT_EQ(parse_distance("md").metric, Metric::kMassDistance);
  EXPECT_FALSE(parse_distance("md").combined());
  EXPECT_EQ(parse_distance("shape").metric, Metric::kShape);
  const DistanceSpec c = parse_distance("WJA+shape", 3.0);
  EXPECT_EQ(c.metric, Metric::kWeightedJointAngles);
  EXPECT_EQ(c.shape_weight, 3.0);
  EXPECT_EQ(to_string(c), "wja+shape");
  EXPECT_TRUE(c.uses_shape());
  EXPECT_EQ(parse_distance("md+shape").shape_weight, kDefaultShapeWeight);
  auto message = [](const std::string& name, double weight) {
    try {
      parse_distance(name, weight);
    } catch (const UserError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message("md+shape", 0.0),
            "--shape-weight: expected a number > 0 (the weight of the shape distance in md+shape), got 0.000000");
  EXPECT_EQ(message("shape+shape", 1.0),
            "--metric: expected a motion metric (hf, md or wja) before \"+shape\", got 'shape+shape'");
  EXPECT_EQ(message("euclid", 1.0),
            "--metric: unknown metric 'euclid', expected one of hf, md, wja, shape, hf+shape, md+shape, wja+shape");
}

}  // namespace
}  // namespace diverse
