// Distances between motions and between character shapes (paper section 4).
//
// Motions are compared pose by pose at corresponding samples: the controller's phases
// give the correspondence (10 samples at phase-normalized times in each of the two
// airborne phases of a jump; 10 in each of the 4 phases of a walk step). The motion
// distance is the sum of the pose distances over corresponding samples.
//
// Pose distances (paper section 4.1), with link centre-of-mass positions taken after
// aligning the two poses' whole-body centres of mass:
//   HF  (hands + feet):          sum over hands and feet   |x_i - x'_i|^2
//   MD  (mass distance):         sum over all links    m_i |x_i - x'_i|^2
//   WJA (weighted joint angles): sum over joints and root  w_i (theta_i - theta'_i)^2
// Shape distance (paper section 4.2): sum over links w_i |L_i - L'_i|, w_i = 1.
//
// All functions are pure and thread-safe.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

namespace diverse {

enum class Metric { kHandsFeet, kMassDistance, kWeightedJointAngles, kShape };

// "hf", "md", "wja", "shape" (case-insensitive); throws UserError naming `where`.
Metric parse_metric(const std::string& name, const std::string& where = "--metric");
const char* to_string(Metric metric);  // "hf", "md", "wja", "shape"
// The three motion metrics, in the order summaries list them.
inline constexpr Metric kMotionMetrics[] = {Metric::kHandsFeet, Metric::kMassDistance,
                                            Metric::kWeightedJointAngles};

// One pose prepared for comparison.
struct Pose {
  // Centre of mass of every link, world axes, relative to the whole-body centre of
  // mass (m). Subtracting the whole-body COM is the paper's alignment step.
  Eigen::Matrix3Xd link_com;
  Eigen::VectorXd link_mass;  // kg, one per link
  Eigen::VectorXd angles;     // joint angles followed by the root angle (rad)
};

// Builds a Pose from world-frame link COM positions (3 x links, m): subtracts the
// mass-weighted whole-body COM so that poses compare independently of where they are.
Pose make_pose(const Eigen::Matrix3Xd& world_link_com, const Eigen::VectorXd& link_mass,
               const Eigen::VectorXd& angles);

// The corresponding pose samples of one motion, and the body that made it.
struct MotionFeatures {
  std::vector<Pose> poses;      // empty when the motion never reached the sampled phases
  Eigen::VectorXd link_lengths; // shape s (m), one per shape-parameterized link
};

// Which links and angles each metric looks at; fixed per character.
struct MetricLayout {
  std::vector<int> hand_foot_links;  // link indices into Pose::link_com
  Eigen::VectorXd angle_weights;     // one per entry of Pose::angles
  Eigen::VectorXd shape_weights;     // one per link length; empty means all 1
};

double pose_distance(Metric metric, const Pose& a, const Pose& b, const MetricLayout& layout);

// Sum of pose distances over corresponding samples. A motion without samples (it failed
// before its sampled phases) is at distance 0 from everything: its constraint penalty,
// not the metric, scores it. For Metric::kShape this is shape_distance.
double motion_distance(Metric metric, const MotionFeatures& a, const MotionFeatures& b,
                       const MetricLayout& layout);

double shape_distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                      const Eigen::VectorXd& weights);

// Difference of two angles wrapped into (-pi, pi], so 359 and -1 degrees are 2 apart.
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
