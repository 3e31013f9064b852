// Metric tests: hand-computed values (planar and 3D), metric axioms, the invariances the
// paper's definitions promise (COM alignment makes distances independent of where a
// motion is), the root's rotation distance, and the planar callers' compatibility paths.
#include "metric/metric.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "core/error.h"
#include "core/rng.h"

namespace diverse {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// ---------------------------------------------------------------------------------------
// Planar poses through the compatibility path (the root pitch is the last angle).

// Three links on a line: masses 1, 2, 1 kg; link 0 is a "hand", link 2 a "foot".
// Angles: one joint angle, then the root pitch.
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
  layout.angle_weights = Eigen::Vector2d(1.0, 4.0);  // joint weight 1, root weight 4
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

// The two 3D poses of the hand-computed tests. Masses 1, 2, 1 kg (total 4); link 0 is a
// hand, link 2 a foot.
//   A world COMs (1, 2, 3), (0, 0, 1), (-1, 2, 1): COM (0, 4, 6) / 4 = (0, 1, 1.5),
//     aligned (1, 1, 1.5), (0, -1, -0.5), (-1, 1, -0.5).
//   B world COMs (12, -18, 9), (10, -20, 5), (8, -20, 5): COM (40, -78, 24) / 4 =
//     (10, -19.5, 6), aligned (2, 1.5, 3), (0, -0.5, -1), (-2, -0.5, -1).
//   Aligned B - A: (1, 0.5, 1.5), (0, 0.5, -0.5), (-1, -1.5, -0.5); squared norms
//     3.5, 0.5, 3.5.
//   HF = 3.5 + 3.5 = 7; MD = 1 * 3.5 + 2 * 0.5 + 1 * 3.5 = 8.
// Joint angles A (0.1, 3.0), B (0.4, -3.0): differences 0.3 and 6 - 2 pi (wrapped).
// Roots: A 60 degrees about x, (w, x, y, z) = (sqrt(3)/2, 1/2, 0, 0); B 60 degrees about y,
// (sqrt(3)/2, 0, 1/2, 0), passed to make_pose as -2 B = (-sqrt(3), 0, -1, 0) (the same
// orientation: make_pose normalizes, and q and -q are one rotation). <A, B> = 3/4, so the
// root angle is 2 acos(3/4) = 1.445468495626831 rad (82.8 degrees).
// Weights: joints 2, 0.5; root 3. WJA = 2 * 0.09 + 0.5 (2 pi - 6)^2 + 3 (2 acos 0.75)^2.
Pose hand_pose_a() {
  Eigen::Matrix3Xd com(3, 3);
  com.col(0) = Eigen::Vector3d(1, 2, 3);
  com.col(1) = Eigen::Vector3d(0, 0, 1);
  com.col(2) = Eigen::Vector3d(-1, 2, 1);
  return make_pose(com, Eigen::Vector3d(1, 2, 1), Eigen::Vector2d(0.1, 3.0),
                   Eigen::Quaterniond(std::sqrt(3.0) / 2, 0.5, 0, 0));
}

Pose hand_pose_b() {
  Eigen::Matrix3Xd com(3, 3);
  com.col(0) = Eigen::Vector3d(12, -18, 9);
  com.col(1) = Eigen::Vector3d(10, -20, 5);
  com.col(2) = Eigen::Vector3d(8, -20, 5);
  return make_pose(com, Eigen::Vector3d(1, 2, 1), Eigen::Vector2d(0.4, -3.0),
                   Eigen::Quaterniond(-std::sqrt(3.0), 0, -1, 0));
}

MetricLayout hand_layout() {
  MetricLayout layout;
  layout.hand_foot_links = {0, 2};
  layout.angle_weights = Eigen::Vector2d(2.0, 0.5);
  layout.root_weight = 3.0;
  return layout;
}

TEST(MakePose, SubtractsWholeBodyCentreOfMassIn3D) {
  const Pose a = hand_pose_a();
  const Pose b = hand_pose_b();
  Eigen::Matrix3Xd expected_a(3, 3), expected_b(3, 3);
  expected_a << 1, 0, -1,  //
      1, -1, 1,            //
      1.5, -0.5, -0.5;
  expected_b << 2, 0, -2,  //
      1.5, -0.5, -0.5,     //
      3, -1, -1;
  EXPECT_NEAR((a.link_com - expected_a).cwiseAbs().maxCoeff(), 0.0, 1e-15);
  EXPECT_NEAR((b.link_com - expected_b).cwiseAbs().maxCoeff(), 0.0, 1e-14);
  // The root is stored normalized; the sign is kept as given.
  EXPECT_NEAR(b.root.w(), -std::sqrt(3.0) / 2, 1e-15);
  EXPECT_NEAR(b.root.y(), -0.5, 1e-15);
  EXPECT_NEAR(b.root.norm(), 1.0, 1e-15);
  EXPECT_EQ(a.angles, Eigen::Vector2d(0.1, 3.0));
}

TEST(MakePose, PlanarCallersPassTheRootPitchLast) {
  Eigen::Matrix3Xd com = Eigen::Matrix3Xd::Zero(3, 2);
  const Eigen::Vector2d mass(1, 1);
  const Pose p = make_pose(com, mass, Eigen::Vector3d(0.1, -0.2, 0.8));
  ASSERT_EQ(p.angles.size(), 2);
  EXPECT_EQ(p.angles[0], 0.1);
  EXPECT_EQ(p.angles[1], -0.2);
  // planar_root(0.8): (w, x, y, z) = (cos 0.4, 0, -sin 0.4, 0).
  EXPECT_NEAR(p.root.w(), std::cos(0.4), 1e-15);
  EXPECT_NEAR(p.root.x(), 0.0, 1e-15);
  EXPECT_NEAR(p.root.y(), -std::sin(0.4), 1e-15);
  EXPECT_NEAR(p.root.z(), 0.0, 1e-15);
  // No angles at all: no joint angles and the identity root.
  const Pose empty = make_pose(com, mass, Eigen::VectorXd());
  EXPECT_EQ(empty.angles.size(), 0);
  EXPECT_EQ(empty.root.w(), 1.0);
  EXPECT_EQ(empty.root.vec().norm(), 0.0);
}

TEST(MakePose, RejectsInconsistentInput) {
  const Eigen::Matrix3Xd com = Eigen::Matrix3Xd::Zero(3, 2);
  EXPECT_THROW(make_pose(com, Eigen::Vector3d(1, 1, 1), Eigen::VectorXd()), std::logic_error);
  EXPECT_THROW(make_pose(com, Eigen::Vector2d(0, 0), Eigen::VectorXd()), std::logic_error);
  EXPECT_THROW(make_pose(com, Eigen::Vector2d(1, 1), Eigen::VectorXd(),
                         Eigen::Quaterniond(0, 0, 0, 0)),
               std::logic_error);
  EXPECT_THROW(make_pose(com, Eigen::Vector2d(1, 1), Eigen::VectorXd(),
                         Eigen::Quaterniond(std::numeric_limits<double>::quiet_NaN(), 0, 0, 0)),
               std::logic_error);
}

TEST(PoseDistance, HandComputedValues) {
  const MetricLayout layout = line_layout();
  const Pose a = line_pose(1.0, 0.0, 0.1);
  const Pose b = line_pose(2.0, 5.0, 0.4);
  // Outer links move by 1 m each: HF = 1 + 1; MD = 1*1 + 2*0 + 1*1.
  EXPECT_DOUBLE_EQ(pose_distance(Metric::kHandsFeet, a, b, layout), 2.0);
  EXPECT_DOUBLE_EQ(pose_distance(Metric::kMassDistance, a, b, layout), 2.0);
  // WJA = 1 * 0.3^2 (joint) + 4 * 0.15^2 (root pitch 0.05 vs 0.2).
  EXPECT_NEAR(pose_distance(Metric::kWeightedJointAngles, a, b, layout),
              0.09 + 4.0 * 0.0225, 1e-12);
}

TEST(PoseDistance, HandComputedValuesIn3D) {
  const MetricLayout layout = hand_layout();
  const Pose a = hand_pose_a();
  const Pose b = hand_pose_b();
  EXPECT_NEAR(pose_distance(Metric::kHandsFeet, a, b, layout), 7.0, 1e-13);
  EXPECT_NEAR(pose_distance(Metric::kMassDistance, a, b, layout), 8.0, 1e-13);
  const double root_angle = 2.0 * std::acos(0.75);
  EXPECT_NEAR(root_angle, 1.445468495626831, 1e-15);
  EXPECT_NEAR(rotation_angle(a.root, b.root), root_angle, 1e-15);
  const double wrapped = 2.0 * kPi - 6.0;  // -3 - 3 = -6 wraps to 2 pi - 6 = 0.2832
  const double wja = 2.0 * 0.09 + 0.5 * wrapped * wrapped + 3.0 * root_angle * root_angle;
  EXPECT_NEAR(wja, 6.488234474650283, 1e-12);
  EXPECT_NEAR(pose_distance(Metric::kWeightedJointAngles, a, b, layout), wja, 1e-13);
  // Only the root term depends on root_weight.
  MetricLayout no_root = layout;
  no_root.root_weight = 0.0;
  EXPECT_NEAR(pose_distance(Metric::kWeightedJointAngles, a, b, no_root),
              2.0 * 0.09 + 0.5 * wrapped * wrapped, 1e-14);
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

TEST(PoseDistance, RejectsPosesAndLayoutsThatDoNotFit) {
  const Pose a = hand_pose_a();
  const Pose b = hand_pose_b();
  MetricLayout layout = hand_layout();
  layout.angle_weights = Eigen::Vector4d(1, 1, 1, 1);  // neither 2 (joints) nor 3 (+ root)
  EXPECT_THROW(pose_distance(Metric::kWeightedJointAngles, a, b, layout), std::logic_error);
  layout = hand_layout();
  layout.hand_foot_links = {0, 3};
  EXPECT_THROW(pose_distance(Metric::kHandsFeet, a, b, layout), std::logic_error);
  layout = hand_layout();
  const Pose planar = line_pose(1.0, 0.0, 0.1);  // 1 joint angle vs 2
  EXPECT_THROW(pose_distance(Metric::kWeightedJointAngles, a, planar, layout), std::logic_error);
  EXPECT_THROW(pose_distance(Metric::kShape, a, b, layout), std::logic_error);
}

// ---------------------------------------------------------------------------------------
// The root's rotation distance.

Eigen::Quaterniond random_rotation(Rng& rng) {
  Eigen::Vector4d v;
  for (int i = 0; i < 4; ++i) v[i] = rng.normal();
  return Eigen::Quaterniond(v[0], v[1], v[2], v[3]).normalized();
}

Eigen::Vector3d random_axis(Rng& rng) {
  return Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal()).normalized();
}

TEST(PlanarRoot, TurnsCounterClockwiseAboutMinusY) {
  // x to the right, z up: a positive pitch turns +x towards +z, like every hinge of the
  // planar human.
  const Eigen::Vector3d x_turned = planar_root(kPi / 2) * Eigen::Vector3d::UnitX();
  EXPECT_NEAR((x_turned - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-15);
  const Eigen::Vector3d z_turned = planar_root(0.3) * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR((z_turned - Eigen::Vector3d(-std::sin(0.3), 0, std::cos(0.3))).norm(), 0.0, 1e-15);
  // The y axis stays.
  EXPECT_NEAR((planar_root(1.2) * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitY()).norm(),
              0.0, 1e-15);
  // A backflip's full turn (+2 pi) is the quaternion -1: the same orientation.
  EXPECT_NEAR(planar_root(2 * kPi).w(), -1.0, 1e-15);
  EXPECT_NEAR(rotation_angle(planar_root(2 * kPi), planar_root(0.0)), 0.0, 1e-15);
}

TEST(RotationAngle, QAndMinusQAreTheSameOrientation) {
  Rng rng(21);
  for (int k = 0; k < 100; ++k) {
    const Eigen::Quaterniond q = random_rotation(rng);
    const Eigen::Quaterniond minus_q(-q.w(), -q.x(), -q.y(), -q.z());
    EXPECT_NEAR(rotation_angle(q, minus_q), 0.0, 1e-15);
    EXPECT_EQ(rotation_angle(q, q), 0.0);
    // Non-unit quaternions: the angle of the rotations they stand for.
    const Eigen::Quaterniond scaled(3 * q.w(), 3 * q.x(), 3 * q.y(), 3 * q.z());
    EXPECT_NEAR(rotation_angle(scaled, q), 0.0, 1e-15);
  }
}

TEST(RotationAngle, NinetyDegreesAboutAnyAxisIsHalfPi) {
  Rng rng(22);
  std::vector<Eigen::Vector3d> axes = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                       Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitY(),
                                       Eigen::Vector3d(1, 1, 1).normalized()};
  for (int k = 0; k < 50; ++k) axes.push_back(random_axis(rng));
  for (const Eigen::Vector3d& axis : axes) {
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(kPi / 2, axis));
    const Eigen::Quaterniond q = random_rotation(rng);
    EXPECT_NEAR(rotation_angle(Eigen::Quaterniond::Identity(), turn), kPi / 2, 1e-15);
    // Turning in the body frame or in the world frame: the same angle.
    EXPECT_NEAR(rotation_angle(q, q * turn), kPi / 2, 1e-14);
    EXPECT_NEAR(rotation_angle(q, turn * q), kPi / 2, 1e-14);
    // 270 degrees one way is 90 the other: the shorter rotation counts.
    const Eigen::Quaterniond turn270(Eigen::AngleAxisd(1.5 * kPi, axis));
    EXPECT_NEAR(rotation_angle(q, q * turn270), kPi / 2, 1e-14);
    // Half a turn is pi, the largest angle.
    const Eigen::Quaterniond turn180(Eigen::AngleAxisd(kPi, axis));
    EXPECT_NEAR(rotation_angle(q, q * turn180), kPi, 1e-14);
  }
}

TEST(RotationAngle, AccurateForSmallAnglesAndNearPi) {
  Rng rng(23);
  for (double angle : {1e-3, 1e-6, 1e-8, 1e-9, 1e-12}) {
    const Eigen::Vector3d axis = random_axis(rng);
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(angle, axis));
    // From the identity, the relative error is at rounding level.
    EXPECT_NEAR(rotation_angle(Eigen::Quaterniond::Identity(), turn), angle, 1e-12 * angle)
        << angle;
    // From any orientation, the absolute error is: well below 1e-9 (2 acos |<q, q'>| would
    // be off by ~1e-8 here).
    const Eigen::Quaterniond q = random_rotation(rng);
    EXPECT_NEAR(rotation_angle(q, q * turn), angle, 1e-14) << angle;
    EXPECT_NEAR(rotation_angle(q * turn, q), angle, 1e-14) << angle;
    // Near pi.
    const Eigen::Quaterniond near_half(Eigen::AngleAxisd(kPi - angle, axis));
    EXPECT_NEAR(rotation_angle(q, q * near_half), kPi - angle, 1e-14) << angle;
  }
}

TEST(RotationAngle, IsSymmetricBoundedAndSatisfiesTheTriangleInequality) {
  // The rotation angle itself is a metric on orientations (the squared angle in WJA is not).
  Rng rng(24);
  for (int k = 0; k < 300; ++k) {
    const Eigen::Quaterniond a = random_rotation(rng);
    const Eigen::Quaterniond b = random_rotation(rng);
    const Eigen::Quaterniond c = random_rotation(rng);
    const double ab = rotation_angle(a, b);
    EXPECT_NEAR(ab, rotation_angle(b, a), 1e-14);
    EXPECT_GE(ab, 0.0);
    EXPECT_LE(ab, kPi);
    EXPECT_LE(rotation_angle(a, c), ab + rotation_angle(b, c) + 1e-14);
    // The angle of the relative rotation, from Eigen's own conversion for comparison.
    const double eigen_angle = Eigen::AngleAxisd(a.conjugate() * b).angle();
    EXPECT_NEAR(ab, std::min(eigen_angle, 2 * kPi - eigen_angle), 1e-12);
  }
}

TEST(AngleDifference, WrapsAroundTheCircle) {
  EXPECT_NEAR(angle_difference(359 * kDeg, -1 * kDeg), 0.0, 1e-12);  // the same angle
  EXPECT_NEAR(angle_difference(359 * kDeg, 1 * kDeg), -2 * kDeg, 1e-12);
  EXPECT_NEAR(angle_difference(1 * kDeg, 359 * kDeg), 2 * kDeg, 1e-12);
  EXPECT_NEAR(angle_difference(10 * kDeg, 350 * kDeg), 20 * kDeg, 1e-12);
  EXPECT_NEAR(angle_difference(-170 * kDeg, 170 * kDeg), 20 * kDeg, 1e-12);
  EXPECT_NEAR(angle_difference(0.3, 0.1), 0.2, 1e-15);
  EXPECT_NEAR(angle_difference(kPi, 0.0), kPi, 1e-15);  // (-pi, pi]
  EXPECT_NEAR(angle_difference(0.0, kPi), kPi, 1e-15);
}

TEST(RotationAngle, PlanarPitchesWrapAroundTheCircle) {
  // The root term of a planar pose: 359 and 1 degrees of pitch are 2 degrees apart, 359
  // and -1 degrees are the same pitch; a backflip's 2 pi + 0.1 is 0.1 from 0.
  EXPECT_NEAR(rotation_angle(planar_root(359 * kDeg), planar_root(1 * kDeg)), 2 * kDeg, 1e-14);
  EXPECT_NEAR(rotation_angle(planar_root(359 * kDeg), planar_root(-1 * kDeg)), 0.0, 1e-14);
  EXPECT_NEAR(rotation_angle(planar_root(179 * kDeg), planar_root(-179 * kDeg)), 2 * kDeg, 1e-14);
  EXPECT_NEAR(rotation_angle(planar_root(2 * kPi + 0.1), planar_root(0.0)), 0.1, 1e-14);
  EXPECT_NEAR(rotation_angle(planar_root(0.0), planar_root(kPi)), kPi, 1e-15);
}

// ---------------------------------------------------------------------------------------
// The planar human: the quaternion root term equals the wrapped pitch difference.

// WJA as it was before the root became a quaternion: every angle, root pitch last,
// wrapped difference squared times its weight.
double planar_wja_reference(const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                            const Eigen::VectorXd& weights) {
  double sum = 0.0;
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    const double d = angle_difference(a[i], b[i]);
    sum += weights[i] * d * d;
  }
  return sum;
}

TEST(PlanarRoot, RotationAngleEqualsTheWrappedPitchDifference) {
  Rng rng(31);
  for (int k = 0; k < 2000; ++k) {
    // Pitches over several turns (a backflip reaches 2 pi and more), some pairs close.
    const double a = 15.0 * (rng.uniform() - 0.5);
    const double b = (k % 4 == 0) ? a + 1e-7 * rng.normal() : 15.0 * (rng.uniform() - 0.5);
    const double wrapped = std::abs(angle_difference(a, b));
    const double angle = rotation_angle(planar_root(a), planar_root(b));
    EXPECT_NEAR(angle, wrapped, 1e-14) << a << " " << b;
    EXPECT_NEAR(angle * angle, wrapped * wrapped, 1e-13) << a << " " << b;
  }
}

// A planar human's 16 joint angles plus root pitch, with the Lee et al. weights the
// callers use (hips, knees, waist, shoulders, elbows and the root weigh 1).
Eigen::VectorXd planar_human_weights() {
  const char* names[] = {"hip_l",    "hip_r",       "knee_l",      "knee_r",     "ankle_l",
                         "ankle_r",  "waist_lower", "waist_upper", "shoulder_l", "shoulder_r",
                         "elbow_l",  "elbow_r",     "wrist_l",     "wrist_r",    "neck",
                         "head",     "root"};
  Eigen::VectorXd w(17);
  for (int i = 0; i < 17; ++i) w[i] = lee2002_joint_weight(names[i]);
  return w;
}

MotionFeatures planar_motion(Rng& rng, int samples, Eigen::VectorXd* all_angles) {
  MotionFeatures m;
  Eigen::VectorXd mass = Eigen::VectorXd::Constant(17, 80.0 / 17);
  for (int k = 0; k < samples; ++k) {
    Eigen::Matrix3Xd com(3, 17);
    for (int j = 0; j < 17; ++j) com.col(j) = Eigen::Vector3d(rng.normal(), 0.0, rng.normal() + 1);
    Eigen::VectorXd angles(17);
    for (int j = 0; j < 16; ++j) angles[j] = rng.normal();
    angles[16] = 7.0 * rng.uniform() - 0.5;  // a backflip's root pitch: -0.5 .. 6.5 rad
    all_angles->segment(17 * k, 17) = angles;
    m.poses.push_back(make_pose(com, mass, angles));  // compatibility path
  }
  return m;
}

TEST(PlanarRoot, WjaOfPlanarCallersIsUnchanged) {
  Rng rng(32);
  const int samples = 20;
  Eigen::VectorXd angles_a(17 * samples), angles_b(17 * samples);
  const MotionFeatures a = planar_motion(rng, samples, &angles_a);
  const MotionFeatures b = planar_motion(rng, samples, &angles_b);
  const Eigen::VectorXd weights = planar_human_weights();

  // The callers' layout: one weight per angle, the root's last.
  MetricLayout compat;
  compat.angle_weights = weights;
  compat.root_weight = 123.0;  // not used when the root's weight is the last angle weight
  // The new layout: joint weights, the root's apart.
  MetricLayout layout;
  layout.angle_weights = weights.head(16);
  layout.root_weight = weights[16];

  double reference = 0.0;
  for (int k = 0; k < samples; ++k) {
    const Eigen::VectorXd pa = angles_a.segment(17 * k, 17), pb = angles_b.segment(17 * k, 17);
    const double ref = planar_wja_reference(pa, pb, weights);
    reference += ref;
    EXPECT_NEAR(pose_distance(Metric::kWeightedJointAngles, a.poses[k], b.poses[k], compat), ref,
                1e-12);
    EXPECT_EQ(pose_distance(Metric::kWeightedJointAngles, a.poses[k], b.poses[k], compat),
              pose_distance(Metric::kWeightedJointAngles, a.poses[k], b.poses[k], layout));
    // Built through the new make_pose, with the root as a quaternion: the same pose.
    const Pose new_a = make_pose(a.poses[k].link_com, a.poses[k].link_mass, pa.head(16),
                                 planar_root(pa[16]));
    EXPECT_EQ(new_a.angles, a.poses[k].angles);
    EXPECT_EQ(new_a.root.coeffs(), a.poses[k].root.coeffs());
  }
  EXPECT_GT(reference, 10.0);
  EXPECT_NEAR(motion_distance(Metric::kWeightedJointAngles, a, b, compat), reference,
              1e-12 * reference);
  EXPECT_NEAR(motion_distance(Metric::kWeightedJointAngles, a, b, layout), reference,
              1e-12 * reference);

  // With equal root pitches the root term is exactly 0 and WJA matches bit for bit.
  MotionFeatures b_same_root = b;
  for (int k = 0; k < samples; ++k) {
    b_same_root.poses[k].root = a.poses[k].root;
    Eigen::VectorXd pb = angles_b.segment(17 * k, 17);
    pb[16] = angles_a[17 * k + 16];
    const Eigen::VectorXd pa = angles_a.segment(17 * k, 17);
    EXPECT_EQ(pose_distance(Metric::kWeightedJointAngles, a.poses[k], b_same_root.poses[k],
                            compat),
              planar_wja_reference(pa, pb, weights));
  }
}

// ---------------------------------------------------------------------------------------
// Motions: axioms and invariances, planar and 3D.

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

// A free-root 3D character: 6 links (masses of a small human or a bird robot), 9 joint
// angles (ball joints give three), a root orientation anywhere, link COMs within a metre
// of `where`.
MotionFeatures random_motion_3d(Rng& rng, int samples, const Eigen::Vector3d& where) {
  MotionFeatures m;
  Eigen::VectorXd mass(6);
  mass << 30, 12, 8, 8, 4, 4;
  for (int k = 0; k < samples; ++k) {
    Eigen::Matrix3Xd com(3, 6);
    for (int j = 0; j < 6; ++j)
      com.col(j) = where + Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal());
    Eigen::VectorXd angles(9);
    for (int j = 0; j < 9; ++j) angles[j] = 2.0 * rng.normal();
    m.poses.push_back(make_pose(com, mass, angles, random_rotation(rng)));
  }
  m.link_lengths.resize(6);
  for (int j = 0; j < 6; ++j) m.link_lengths[j] = 0.2 + 0.3 * rng.uniform();
  return m;
}

MetricLayout layout_3d() {
  MetricLayout layout;
  layout.hand_foot_links = {2, 3, 4, 5};
  layout.angle_weights.resize(9);
  layout.angle_weights << 1, 1, 1, 0.5, 0.5, 0.5, 0, 2, 1;
  layout.root_weight = 1.5;
  return layout;
}

// The translated copy of a motion: every link COM moved by `shift` (the same draws).
MotionFeatures translated(const MotionFeatures& m, const std::vector<Eigen::Vector3d>& shift) {
  MotionFeatures out = m;
  for (std::size_t k = 0; k < m.poses.size(); ++k) {
    const Pose& p = m.poses[k];
    const Eigen::Matrix3Xd world = p.link_com.colwise() + shift[k % shift.size()];
    out.poses[k] = make_pose(world, p.link_mass, p.angles, p.root);
  }
  return out;
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
    const double ab = motion_distance(metric, a, b, layout);
    EXPECT_NEAR(ab, motion_distance(metric, b, a, layout), 1e-13 * ab);
    EXPECT_GT(ab, 0.0);
  }
}

TEST(MotionDistance, AxiomsForEveryMetricIn3D) {
  Rng rng(8);
  const MetricLayout layout = layout_3d();
  std::vector<MotionFeatures> motions;
  for (int i = 0; i < 12; ++i) motions.push_back(random_motion_3d(rng, 20, Eigen::Vector3d(0, 0, 1)));
  for (Metric metric : {Metric::kHandsFeet, Metric::kMassDistance,
                        Metric::kWeightedJointAngles, Metric::kShape}) {
    SCOPED_TRACE(to_string(metric));
    for (const MotionFeatures& a : motions) {
      EXPECT_EQ(motion_distance(metric, a, a, layout), 0.0);
      for (const MotionFeatures& b : motions) {
        if (&a == &b) continue;
        const double ab = motion_distance(metric, a, b, layout);
        EXPECT_GT(ab, 0.0);
        EXPECT_NEAR(ab, motion_distance(metric, b, a, layout), 1e-13 * ab);
      }
    }
  }
}

TEST(MotionDistance, SquareRootsSatisfyTheTriangleInequalityTheDistancesDoNot) {
  // HF, MD and WJA are sums of weighted squares, so sqrt(d) is a (semi)metric: a weighted
  // Euclidean norm of aligned link positions, or of wrapped angle differences and root
  // angles, each of which is a metric. d itself is not: for b halfway between a and c,
  // d(a, c) = 4 d(a, b) = 2 (d(a, b) + d(b, c)).
  Rng rng(9);
  const MetricLayout layout = layout_3d();
  std::vector<MotionFeatures> motions;
  for (int i = 0; i < 10; ++i) motions.push_back(random_motion_3d(rng, 5, Eigen::Vector3d::Zero()));
  for (Metric metric : kMotionMetrics) {
    SCOPED_TRACE(to_string(metric));
    for (const MotionFeatures& a : motions)
      for (const MotionFeatures& b : motions)
        for (const MotionFeatures& c : motions) {
          const double ac = std::sqrt(motion_distance(metric, a, c, layout));
          const double ab = std::sqrt(motion_distance(metric, a, b, layout));
          const double bc = std::sqrt(motion_distance(metric, b, c, layout));
          EXPECT_LE(ac, ab + bc + 1e-12);
        }
  }
  // The midpoint counterexample, by hand: one hand link 0 at x = 0, 1, 2 relative to the
  // other link (masses 1, 1), joint angle 0, 0.5, 1, root turned 0, 0.25, 0.5 rad about z.
  MetricLayout line;
  line.hand_foot_links = {0};
  line.angle_weights = Eigen::VectorXd::Ones(1);
  line.root_weight = 1.0;
  auto pose = [](double t) {
    Eigen::Matrix3Xd com = Eigen::Matrix3Xd::Zero(3, 2);
    com(0, 0) = t;
    return make_pose(com, Eigen::Vector2d(1, 1), Eigen::VectorXd::Constant(1, 0.5 * t),
                     Eigen::Quaterniond(Eigen::AngleAxisd(0.25 * t, Eigen::Vector3d::UnitZ())));
  };
  const Pose a = pose(0), b = pose(1), c = pose(2);
  // Aligned hand x: t/2, so HF(a, b) = 0.25, HF(a, c) = 1; MD: two links move t/2 each.
  EXPECT_NEAR(pose_distance(Metric::kHandsFeet, a, b, line), 0.25, 1e-15);
  EXPECT_NEAR(pose_distance(Metric::kHandsFeet, a, c, line), 1.0, 1e-15);
  EXPECT_NEAR(pose_distance(Metric::kMassDistance, a, b, line), 0.5, 1e-15);
  EXPECT_NEAR(pose_distance(Metric::kMassDistance, a, c, line), 2.0, 1e-15);
  // WJA: 0.5^2 + 0.25^2 = 0.3125 for a step, 1 + 0.25 = 1.25 for two.
  EXPECT_NEAR(pose_distance(Metric::kWeightedJointAngles, a, b, line), 0.3125, 1e-15);
  EXPECT_NEAR(pose_distance(Metric::kWeightedJointAngles, a, c, line), 1.25, 1e-15);
  for (Metric metric : kMotionMetrics) {
    SCOPED_TRACE(to_string(metric));
    const double ab = pose_distance(metric, a, b, line), bc = pose_distance(metric, b, c, line);
    const double ac = pose_distance(metric, a, c, line);
    EXPECT_NEAR(ab, bc, 1e-15);
    EXPECT_NEAR(ac, 2.0 * (ab + bc), 1e-14);
    EXPECT_GT(ac, ab + bc);
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

TEST(MotionDistance, InvariantToTranslatingA3DMotionAnywhere) {
  Rng rng(12);
  const MetricLayout layout = layout_3d();
  const MotionFeatures a = random_motion_3d(rng, 20, Eigen::Vector3d(0, 0, 1));
  const MotionFeatures c = random_motion_3d(rng, 20, Eigen::Vector3d(0, 0, 1));
  // One shift for the whole motion, and a different shift at every sample (a motion that
  // travels: alignment is per pose, so it does not matter).
  const std::vector<Eigen::Vector3d> one = {Eigen::Vector3d(123.4, -56.7, 8.9)};
  std::vector<Eigen::Vector3d> travelling;
  for (int k = 0; k < 20; ++k)
    travelling.push_back(Eigen::Vector3d(0.7 * k, -3.0 + 10 * rng.normal(), 0.05 * k * k));
  for (const auto& shift : {one, travelling}) {
    const MotionFeatures a_moved = translated(a, shift);
    for (Metric metric : kMotionMetrics) {
      SCOPED_TRACE(to_string(metric));
      const double ac = motion_distance(metric, a, c, layout);
      EXPECT_GT(ac, 1.0);
      EXPECT_NEAR(motion_distance(metric, a, a_moved, layout), 0.0, 1e-9);
      EXPECT_NEAR(motion_distance(metric, a_moved, c, layout), ac, 1e-9 * ac);
      EXPECT_NEAR(motion_distance(metric, c, a_moved, layout), ac, 1e-9 * ac);
    }
  }
  // The hand-computed poses: B translated by another (-40, 3, 1000) m keeps HF 7 and MD 8.
  const Pose pa = hand_pose_a(), pb = hand_pose_b();
  const Pose pb_moved = make_pose(pb.link_com.colwise() + Eigen::Vector3d(-40, 3, 1000),
                                  pb.link_mass, pb.angles, pb.root);
  EXPECT_NEAR(pose_distance(Metric::kHandsFeet, pa, pb_moved, hand_layout()), 7.0, 1e-11);
  EXPECT_NEAR(pose_distance(Metric::kMassDistance, pa, pb_moved, hand_layout()), 8.0, 1e-11);
}

TEST(MotionDistance, TurningA3DMotionChangesItsDistance) {
  // Alignment removes translation only: the same motion facing another way is another
  // motion. Turning a pose by 30 degrees about the vertical moves its root by exactly 30
  // degrees and its links about the COM.
  Rng rng(13);
  const MetricLayout layout = layout_3d();
  const MotionFeatures a = random_motion_3d(rng, 4, Eigen::Vector3d::Zero());
  const Eigen::Quaterniond yaw(Eigen::AngleAxisd(30 * kDeg, Eigen::Vector3d::UnitZ()));
  MotionFeatures turned = a;
  double md = 0.0;
  for (Pose& p : turned.poses) {
    const Eigen::Matrix3Xd before = p.link_com;
    p = make_pose(yaw.toRotationMatrix() * p.link_com, p.link_mass, p.angles, yaw * p.root);
    md += ((p.link_com - before).colwise().squaredNorm().transpose().array() *
           p.link_mass.array())
              .sum();
  }
  EXPECT_NEAR(motion_distance(Metric::kWeightedJointAngles, a, turned, layout),
              4 * layout.root_weight * std::pow(30 * kDeg, 2), 1e-13);
  EXPECT_GT(md, 1.0);
  EXPECT_NEAR(motion_distance(Metric::kMassDistance, a, turned, layout), md, 1e-12 * md);
  EXPECT_GT(motion_distance(Metric::kHandsFeet, a, turned, layout), 0.1);
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
  EXPECT_EQ(motion_distance(Metric::kWeightedJointAngles, failed, a, layout), 0.0);
}

TEST(ShapeDistance, SumOfAbsoluteLengthDifferences) {
  const Eigen::Vector3d a(0.4, 0.5, 0.3), b(0.2, 0.9, 0.3);
  EXPECT_NEAR(shape_distance(a, b, Eigen::VectorXd()), 0.2 + 0.4, 1e-15);
  EXPECT_NEAR(shape_distance(a, b, Eigen::Vector3d(2, 1, 1)), 0.4 + 0.4, 1e-15);
}

TEST(ShapeDistance, HandValuesAxiomsAndTheLayoutsWeights) {
  // Five links: differences 0.1, -0.25, 0, 0.05, -0.4 m; weights 1 (paper) and 0.5 on the
  // last two.
  Eigen::VectorXd a(5), b(5), c(5);
  a << 0.45, 0.40, 0.30, 0.25, 0.80;
  b << 0.35, 0.65, 0.30, 0.20, 1.20;
  c << 0.50, 0.50, 0.50, 0.50, 0.50;
  EXPECT_NEAR(shape_distance(a, b, Eigen::VectorXd()), 0.8, 1e-15);
  EXPECT_NEAR(shape_distance(a, b, Eigen::VectorXd::Ones(5)), 0.8, 1e-15);
  Eigen::VectorXd w(5);
  w << 1, 1, 1, 0.5, 0.5;
  EXPECT_NEAR(shape_distance(a, b, w), 0.1 + 0.25 + 0.025 + 0.2, 1e-15);
  // An L1 distance: a metric, triangle inequality included.
  EXPECT_EQ(shape_distance(a, a, w), 0.0);
  EXPECT_EQ(shape_distance(a, b, w), shape_distance(b, a, w));
  EXPECT_LE(shape_distance(a, b, w), shape_distance(a, c, w) + shape_distance(c, b, w));
  // motion_distance for the shape metric is the shape distance with the layout's weights,
  // whatever the motions.
  MotionFeatures ma, mb;
  ma.link_lengths = a;
  mb.link_lengths = b;
  MetricLayout layout;
  layout.shape_weights = w;
  EXPECT_NEAR(motion_distance(Metric::kShape, ma, mb, layout), 0.575, 1e-15);
  EXPECT_THROW(shape_distance(a, Eigen::Vector3d(1, 1, 1), Eigen::VectorXd()), std::logic_error);
  EXPECT_THROW(shape_distance(a, b, Eigen::Vector3d(1, 1, 1)), std::logic_error);
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
