// Metric tests: hand-computed values, metric axioms, and the invariances the paper's
// definitions promise (COM alignment makes distances independent of where a motion is).
#include "metric/metric.h"

#include <gtest/gtest.h>

#include <numbers>

#include "core/error.h"
#include "core/rng.h"

namespace diverse {
namespace {

// Three links on a line: masses 1, 2, 1 kg; link 0 is a "hand", link 2 a "foot".
Pose line_pose(double spread, double shift_x, double angle) {
  Eigen::Matrix3Xd com(3, 3);
  com << -spread + shift_x, shift_x, spread + shift_x,  //
      0, 0, 0,                                           //
      1, 1, 1;
  Eigen::VectorXd mass(3);
  mass << 1, 2, 1;
  Eigen::VectorXd angles(2);
  angles << angle, 0.5 * angle;
  return make_pose(com, mass, angles);
}

MetricLayout line_layout() {
  MetricLayout layout;
  layout.hand_foot_links = {0, 2};
  layout.angle_weights = Eigen::Vector2d(1.0, 4.0);
  return layout;
}

TEST(MakePose, SubtractsWholeBodyCentreOfMass) {
  const Pose p = line_pose(1.0, 3.0, 0.0);
  // Mass-weighted COM is at x = 3, z = 1; after alignment the links sit at -1, 0, 1.
  EXPECT_DOUBLE_EQ(p.link_com(0, 0), -1.0);
  EXPECT_DOUBLE_EQ(p.link_com(0, 1), 0.0);
  EXPECT_DOUBLE_EQ(p.link_com(0, 2), 1.0);
  EXPECT_DOUBLE_EQ(p.link_com(2, 1), 0.0);
}

TEST(PoseDistance, HandComputedValues) {
  const MetricLayout layout = line_layout();
  const Pose a = line_pose(1.0, 0.0, 0.1);
  const Pose b = line_pose(2.0, 5.0, 0.4);
  // Outer links move by 1 m each: HF = 1 + 1; MD = 1*1 + 2*0 + 1*1.
  EXPECT_DOUBLE_EQ(pose_distance(Metric::kHandsFeet, a, b, layout), 2.0);
  EXPECT_DOUBLE_EQ(pose_distance(Metric::kMassDistance, a, b, layout), 2.0);
  // WJA = 1 * 0.3^2 + 4 * 0.15^2.
  EXPECT_NEAR(pose_distance(Metric::kWeightedJointAngles, a, b, layout),
              0.09 + 4.0 * 0.0225, 1e-12);
}

TEST(PoseDistance, MassDistanceWeighsHeavyLinks) {
  MetricLayout layout = line_layout();
  Eigen::Matrix3Xd x = Eigen::Matrix3Xd::Zero(3, 2);
  Eigen::Matrix3Xd y = x;
  x(0, 0) = 0.5;   // light link moves +0.5, heavy link -0.1 (COM held by make_pose)
  x(0, 1) = -0.1;
  Eigen::VectorXd mass = Eigen::Vector2d(1.0, 5.0);
  const Pose a = make_pose(x, mass, Eigen::VectorXd::Zero(2));
  const Pose b = make_pose(y, mass, Eigen::VectorXd::Zero(2));
  // COM of a is (0.5 - 0.5) / 6 = 0, so the displacements stay as given.
  EXPECT_NEAR(pose_distance(Metric::kMassDistance, a, b, layout), 1 * 0.25 + 5 * 0.01, 1e-12);
}

TEST(AngleDifference, WrapsAroundTheCircle) {
  const double deg = std::numbers::pi / 180.0;
  EXPECT_NEAR(angle_difference(359 * deg, -1 * deg), 0.0, 1e-12);
  EXPECT_NEAR(angle_difference(10 * deg, 350 * deg), 20 * deg, 1e-12);
  EXPECT_NEAR(angle_difference(-170 * deg, 170 * deg), 20 * deg, 1e-12);
  EXPECT_NEAR(angle_difference(0.3, 0.1), 0.2, 1e-15);
}

MotionFeatures random_motion(Rng& rng, int samples, double shift) {
  MotionFeatures m;
  Eigen::VectorXd mass(5);
  mass << 10, 20, 5, 3, 3;
  for (int k = 0; k < samples; ++k) {
    Eigen::Matrix3Xd com(3, 5);
    for (int j = 0; j < 5; ++j)
      com.col(j) = Eigen::Vector3d(rng.normal() + shift, 0.0, rng.normal() + 1.0);
    Eigen::VectorXd angles(4);
    for (int j = 0; j < 4; ++j) angles[j] = rng.normal();
    m.poses.push_back(make_pose(com, mass, angles));
  }
  m.link_lengths = Eigen::VectorXd::Constant(5, 0.3 + 0.1 * rng.uniform());
  return m;
}

MetricLayout five_link_layout() {
  MetricLayout layout;
  layout.hand_foot_links = {2, 3, 4};
  layout.angle_weights = Eigen::Vector4d(1, 1, 0, 1);
  return layout;
}

TEST(MotionDistance, AxiomsForEveryMetric) {
  Rng rng(7);
  const MetricLayout layout = five_link_layout();
  const MotionFeatures a = random_motion(rng, 20, 0.0);
  const MotionFeatures b = random_motion(rng, 20, 0.0);
  for (Metric metric : {Metric::kHandsFeet, Metric::kMassDistance,
                        Metric::kWeightedJointAngles, Metric::kShape}) {
    SCOPED_TRACE(to_string(metric));
    EXPECT_EQ(motion_distance(metric, a, a, layout), 0.0);
    EXPECT_EQ(motion_distance(metric, a, b, layout), motion_distance(metric, b, a, layout));
    EXPECT_GT(motion_distance(metric, a, b, layout), 0.0);
  }
}

TEST(MotionDistance, InvariantToShiftingAWholeMotion) {
  Rng rng_a(3), rng_b(3), rng_c(4);
  const MetricLayout layout = five_link_layout();
  const MotionFeatures a = random_motion(rng_a, 20, 0.0);
  const MotionFeatures a_shifted = random_motion(rng_b, 20, 12.5);  // same draws, moved 12.5 m
  const MotionFeatures c = random_motion(rng_c, 20, 0.0);
  for (Metric metric : kMotionMetrics) {
    SCOPED_TRACE(to_string(metric));
    EXPECT_NEAR(motion_distance(metric, a, a_shifted, layout), 0.0, 1e-9);
    EXPECT_NEAR(motion_distance(metric, a, c, layout),
                motion_distance(metric, a_shifted, c, layout), 1e-9);
  }
}

TEST(MotionDistance, SumsPoseDistancesOverCorrespondingSamples) {
  Rng rng(11);
  const MetricLayout layout = five_link_layout();
  const MotionFeatures a = random_motion(rng, 3, 0.0);
  const MotionFeatures b = random_motion(rng, 3, 0.0);
  double sum = 0.0;
  for (int k = 0; k < 3; ++k)
    sum += pose_distance(Metric::kMassDistance, a.poses[k], b.poses[k], layout);
  EXPECT_DOUBLE_EQ(motion_distance(Metric::kMassDistance, a, b, layout), sum);
}

TEST(MotionDistance, MotionWithoutSamplesIsAtZero) {
  Rng rng(5);
  const MetricLayout layout = five_link_layout();
  const MotionFeatures a = random_motion(rng, 20, 0.0);
  const MotionFeatures failed;
  EXPECT_EQ(motion_distance(Metric::kMassDistance, a, failed, layout), 0.0);
}

TEST(ShapeDistance, SumOfAbsoluteLengthDifferences) {
  const Eigen::Vector3d a(0.4, 0.5, 0.3), b(0.2, 0.9, 0.3);
  EXPECT_NEAR(shape_distance(a, b, Eigen::VectorXd()), 0.2 + 0.4, 1e-15);
  EXPECT_NEAR(shape_distance(a, b, Eigen::Vector3d(2, 1, 1)), 0.4 + 0.4, 1e-15);
}

TEST(ParseMetric, AcceptsKnownNamesAndRejectsOthers) {
  EXPECT_EQ(parse_metric("MD"), Metric::kMassDistance);
  EXPECT_EQ(parse_metric("wja"), Metric::kWeightedJointAngles);
  EXPECT_EQ(parse_metric("hf"), Metric::kHandsFeet);
  EXPECT_EQ(parse_metric("shape"), Metric::kShape);
  try {
    parse_metric("euclid", "tasks/backflip.toml: metric");
    FAIL() << "expected a UserError";
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(),
                 "tasks/backflip.toml: metric: unknown metric 'euclid', expected one of hf, md, "
                 "wja, shape");
  }
}

TEST(Lee2002Weights, WeighsMajorJointsOnly) {
  EXPECT_EQ(lee2002_joint_weight("left_hip"), 1.0);
  EXPECT_EQ(lee2002_joint_weight("right_knee"), 1.0);
  EXPECT_EQ(lee2002_joint_weight("shoulder_l"), 1.0);
  EXPECT_EQ(lee2002_joint_weight("upper_waist"), 1.0);
  EXPECT_EQ(lee2002_joint_weight("root"), 1.0);
  EXPECT_EQ(lee2002_joint_weight("left_ankle"), 0.0);
  EXPECT_EQ(lee2002_joint_weight("wrist_r"), 0.0);
  EXPECT_EQ(lee2002_joint_weight("neck"), 0.0);
}

}  // namespace
}  // namespace diverse
