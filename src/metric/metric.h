// Distances between motions and between character shapes (paper section 4), for planar
// and 3D characters alike (the planar human; a free-root 3D human; a bird robot).
//
// Motions are compared pose by pose at corresponding samples: the controller's phases
// give the correspondence (10 samples at phase-normalized times in each of the two
// airborne phases of a jump; 10 in each of the 4 phases of a walk step). The motion
// distance is the sum of the pose distances over corresponding samples.
//
// A pose (struct Pose below) holds every link's centre of mass in world axes, relative to
// the whole-body centre of mass (m): subtracting the whole-body COM is the paper's
// alignment step, so distances do not depend on where in the world (x, y and z) a motion
// happens. Only the translation is aligned, not the heading: the same motion performed
// facing another way is a different motion to every metric (its root orientation and
// its link positions in world axes differ). A walk's poses come already turned into the
// stride's heading frame (task/walk_eval.h), so for walks the direction does not count.
//
// Pose distances (paper section 4.1), between poses x and x':
//   HF  (hands + feet):          sum over hands and feet   |x_i - x'_i|^2            (m^2)
//   MD  (mass distance):         sum over all links    m_i |x_i - x'_i|^2       (kg m^2)
//   WJA (weighted joint angles): sum over joints       w_i (theta_i - theta'_i)^2
//                                + w_root angle(q_root, q'_root)^2                (rad^2)
// A joint angle difference is wrapped into (-pi, pi] (angle_difference). The root's
// orientation q_root is a unit quaternion and its term is the angle of the relative
// rotation between the two orientations (rotation_angle), in [0, pi]. For a planar root
// (a pitch about -y, planar_root) that angle is the wrapped pitch difference, so the
// planar human's WJA is the sum over its joints and its root pitch of w_i (wrapped
// difference)^2. A multi-axis joint enters as one angle per degree of freedom (the
// MetricLayout gives one weight per angle).
// Shape distance (paper section 4.2): sum over links w_i |L_i - L'_i|, w_i = 1.
//
// These are squared distances: d(a, a) = 0, d(a, b) = d(b, a) >= 0, but the triangle
// inequality holds for their square roots (weighted Euclidean norms of the aligned link
// positions, or of the wrapped angle differences and the root angle), not for the
// distances themselves.
//
// All functions are pure and thread-safe.
#pragma once

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace diverse {

// One pose prepared for comparison.
struct Pose {
  // Centre of mass of every link, world axes, relative to the whole-body centre of
  // mass (m).
  Eigen::Matrix3Xd link_com;
  Eigen::VectorXd link_mass;  // kg, one per link
  Eigen::VectorXd angles;     // joint angles only (rad), one per joint degree of freedom
  Eigen::Quaterniond root = Eigen::Quaterniond::Identity();  // root orientation, world frame
};

// Builds a Pose from world-frame link COM positions (3 x links, m): subtracts the
// mass-weighted whole-body COM so that poses compare independently of where they are.
// `root` is normalized (std::logic_error unless it has a finite, nonzero norm).
Pose make_pose(const Eigen::Matrix3Xd& world_link_com, const Eigen::VectorXd& link_mass,
               const Eigen::VectorXd& joint_angles, const Eigen::Quaterniond& root);

// Compatibility: serves callers that pass the planar root pitch as the last angle.
// `angles` is the joint angles followed by the root pitch; the pose gets the joint angles
// (all but the last) and root = planar_root(last). An empty `angles` gives no joint angles
// and the identity root.
Pose make_pose(const Eigen::Matrix3Xd& world_link_com, const Eigen::VectorXd& link_mass,
               const Eigen::VectorXd& angles);

// The planar human's root orientation: a rotation by `pitch` (rad) about -y, the axis
// every hinge of the planar human turns about (counter-clockwise positive with x to the
// right and z up; a backflip turns the root by +2 pi).
Eigen::Quaterniond planar_root(double pitch);

// The angle (rad, in [0, pi]) of the relative rotation between two orientations:
// angle(q, q') = 2 acos |<q, q'>|, the length of the shortest rotation taking one to the
// other. q and -q are the same orientation (angle 0). It is computed as
// 2 atan2(|vec(r)|, |w(r)|) with r = conj(q) q' (so w(r) = <q, q'>), which is accurate
// to rounding over the whole range, near 0 and near pi included: the acos form loses half
// the digits near 0 (acos(1 - e) ~ sqrt(2 e), so a rounding error of 1e-16 in the dot
// product becomes 1.5e-8 rad), as does an asin form near pi. Non-unit (nonzero)
// quaternions give the angle of their normalized rotations.
double rotation_angle(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b);

// Which links and angles each metric looks at; fixed per character.
struct MetricLayout {
  std::vector<int> hand_foot_links;  // link indices into Pose::link_com
  // One weight per joint angle (Pose::angles). Compatibility: serves callers that pass the
  // planar root pitch as the last angle; with one more entry than the poses' joint angles,
  // the last entry is the root's weight and root_weight is not used.
  Eigen::VectorXd angle_weights;
  double root_weight = 1.0;          // w_root of the root orientation term
  Eigen::VectorXd shape_weights;     // one per link length; empty means all 1
};

enum class Metric { kHandsFeet, kMassDistance, kWeightedJointAngles, kShape };

// "hf", "md", "wja", "shape" (case-insensitive); throws UserError naming `where`.
Metric parse_metric(const std::string& name, const std::string& where = "--metric");
const char* to_string(Metric metric);  // "hf", "md", "wja", "shape"
// The three motion metrics, in the order summaries list them.
inline constexpr Metric kMotionMetrics[] = {Metric::kHandsFeet, Metric::kMassDistance,
                                            Metric::kWeightedJointAngles};

// The distance a diversity run maximizes: one metric, or a motion metric plus a weighted
// shape distance, d = d_metric + shape_weight * d_shape. The paper optimizes one metric at
// a time and leaves an objective that rewards both motion and shape diversity to future
// work (section 8); the combination is ours. The two scales differ: MD summed over 20
// poses of an 80 kg body is in kg m^2 and reaches tens between motions, the shape distance
// sums |dL| over 17 links in m and reaches a few, so the weight (units of the motion
// metric per metre) sets the exchange rate. Written "md", "shape", "md+shape", ...
struct DistanceSpec {
  Metric metric = Metric::kMassDistance;
  double shape_weight = 0.0;  // > 0: a combined distance (metric is then a motion metric)
  bool combined() const { return shape_weight > 0.0; }
  // True when the distance looks at the body shape, so shape must vary to move it.
  bool uses_shape() const { return metric == Metric::kShape || combined(); }
};
// Default weight of "<metric>+shape": 10, the ratio of the paper's MD diversity to its
// shape diversity under their own objectives (table 1: 30.6 / 3.05 for the forward jump,
// 21.8 / 1.76 for the backflip), so that each half moves the sum about as much.
inline constexpr double kDefaultShapeWeight = 10.0;

// "hf", "md", "wja", "shape" (or "sd"), or a motion metric followed by "+shape" ("md+shape";
// case-insensitive). `shape_weight` is the combined distance's weight (UserError naming
// `weight_where` unless it is finite and > 0); single metrics ignore it. Unknown names
// throw UserError naming `where`.
DistanceSpec parse_distance(const std::string& name, double shape_weight = kDefaultShapeWeight,
                            const std::string& where = "--metric",
                            const std::string& weight_where = "--shape-weight");
std::string to_string(const DistanceSpec& spec);  // "md", "shape", "md+shape"

// The corresponding pose samples of one motion, and the body that made it.
struct MotionFeatures {
  std::vector<Pose> poses;      // empty when the motion never reached the sampled phases
  Eigen::VectorXd link_lengths; // shape s (m), one per shape-parameterized link
};

// One pose distance (HF, MD or WJA; see the top of this file). Throws std::logic_error
// when the poses or the layout do not fit together (link counts, a hand/foot index out of
// range, angle counts, weight counts) or for Metric::kShape, which compares bodies.
double pose_distance(Metric metric, const Pose& a, const Pose& b, const MetricLayout& layout);

// Sum of pose distances over corresponding samples. A motion without samples (it failed
// before its sampled phases) is at distance 0 from everything: its constraint penalty,
// not the metric, scores it. For Metric::kShape this is shape_distance.
double motion_distance(Metric metric, const MotionFeatures& a, const MotionFeatures& b,
                       const MetricLayout& layout);

double shape_distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                      const Eigen::VectorXd& weights);

// Difference a - b of two angles wrapped into (-pi, pi]: 359 and 1 degrees are -2 degrees
// apart, 359 and -1 degrees (the same angle) 0.
double angle_difference(double a, double b);

// WJA weights. The paper uses "the WJA weights suggested in a previous study on pose
// similarity metrics" (its ref. [38]: Wang and Bodenheimer, "An Evaluation of a Cost
// Metric for Selecting Transitions between Motion Segments", SCA 2003), which fitted
// per-joint weights to the joint-angle metric of Lee et al. 2002. That table could not
// be obtained here, so we use the documented fallback of Lee et al. 2002 ("Interactive
// Control of Avatars Animated with Human Motion Data", SIGGRAPH 2002): weight 1 for
// shoulders, elbows, hips, knees, pelvis (root) and spine, 0 for all other joints.
double lee2002_joint_weight(const std::string& joint_name);

}  // namespace diverse
