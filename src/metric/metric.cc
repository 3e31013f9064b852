#include "metric/metric.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "core/error.h"

namespace diverse {

Metric parse_metric(const std::string& name, const std::string& where) {
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower == "hf") return Metric::kHandsFeet;
  if (lower == "md") return Metric::kMassDistance;
  if (lower == "wja") return Metric::kWeightedJointAngles;
  if (lower == "shape" || lower == "sd") return Metric::kShape;
  throw_field_error(where, "", "unknown metric '" + name + "', expected one of hf, md, wja, shape");
}

DistanceSpec parse_distance(const std::string& name, double shape_weight, const std::string& where,
                            const std::string& weight_where) {
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const std::string suffix = "+shape";
  if (lower.size() > suffix.size() && lower.compare(lower.size() - suffix.size(), suffix.size(), suffix) == 0) {
    const std::string base = name.substr(0, name.size() - suffix.size());
    DistanceSpec spec;
    spec.metric = parse_metric(base, where);
    if (spec.metric == Metric::kShape)
      throw_field_error(where, "", "expected a motion metric (hf, md or wja) before \"+shape\", got '" + name + "'");
    if (!(std::isfinite(shape_weight) && shape_weight > 0.0))
      throw_field_error(weight_where, "", "expected a number > 0 (the weight of the shape distance in " +
                                              name + "), got " + std::to_string(shape_weight));
    spec.shape_weight = shape_weight;
    return spec;
  }
  try {
    return DistanceSpec{parse_metric(name, where), 0.0};
  } catch (const UserError&) {
    throw_field_error(where, "", "unknown metric '" + name +
                                     "', expected one of hf, md, wja, shape, hf+shape, md+shape, wja+shape");
  }
}

std::string to_string(const DistanceSpec& spec) {
  std::string name = to_string(spec.metric);
  if (spec.combined()) name += "+shape";
  return name;
}

const char* to_string(Metric metric) {
  switch (metric) {
    case Metric::kHandsFeet: return "hf";
    case Metric::kMassDistance: return "md";
    case Metric::kWeightedJointAngles: return "wja";
    case Metric::kShape: return "shape";
  }
  return "?";
}

double angle_difference(double a, double b) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  double d = std::fmod(a - b, kTwoPi);
  if (d > std::numbers::pi) d -= kTwoPi;
  if (d <= -std::numbers::pi) d += kTwoPi;
  return d;
}

Pose make_pose(const Eigen::Matrix3Xd& world_link_com, const Eigen::VectorXd& link_mass,
               const Eigen::VectorXd& joint_angles, const Eigen::Quaterniond& root) {
  if (world_link_com.cols() != link_mass.size())
    throw std::logic_error("make_pose: one mass per link expected");
  const double total = link_mass.sum();
  if (!(total > 0.0)) throw std::logic_error("make_pose: total mass must be positive");
  const double root_norm = root.norm();
  if (!(std::isfinite(root_norm) && root_norm > 0.0))
    throw std::logic_error("make_pose: the root orientation must be a finite, nonzero quaternion");
  const Eigen::Vector3d com = world_link_com * link_mass / total;
  Pose pose;
  pose.link_com = world_link_com.colwise() - com;
  pose.link_mass = link_mass;
  pose.angles = joint_angles;
  pose.root = Eigen::Quaterniond(root.coeffs() / root_norm);
  return pose;
}

// Compatibility: serves callers that pass the planar root pitch as the last angle.
Pose make_pose(const Eigen::Matrix3Xd& world_link_com, const Eigen::VectorXd& link_mass,
               const Eigen::VectorXd& angles) {
  if (angles.size() == 0)
    return make_pose(world_link_com, link_mass, angles, Eigen::Quaterniond::Identity());
  const Eigen::Index joints = angles.size() - 1;
  return make_pose(world_link_com, link_mass, angles.head(joints), planar_root(angles[joints]));
}

Eigen::Quaterniond planar_root(double pitch) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(pitch, -Eigen::Vector3d::UnitY()));
}

double rotation_angle(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  // r = conj(a) b takes a to b; its scalar part is <a, b>. atan2 of the vector part's
  // norm over |scalar part| is half the rotation angle, accurate near 0 and near pi, and
  // independent of the quaternions' norms. |w| picks the shorter of the two rotations
  // that r and -r describe.
  const Eigen::Quaterniond r = a.conjugate() * b;
  return 2.0 * std::atan2(r.vec().norm(), std::abs(r.w()));
}

double pose_distance(Metric metric, const Pose& a, const Pose& b, const MetricLayout& layout) {
  switch (metric) {
    case Metric::kHandsFeet: {
      if (a.link_com.cols() != b.link_com.cols())
        throw std::logic_error("pose_distance: poses have different link counts");
      double sum = 0.0;
      for (int link : layout.hand_foot_links) {
        if (link < 0 || link >= a.link_com.cols())
          throw std::logic_error("pose_distance: a hand or foot link index is out of range");
        sum += (a.link_com.col(link) - b.link_com.col(link)).squaredNorm();
      }
      return sum;
    }
    case Metric::kMassDistance: {
      if (a.link_com.cols() != b.link_com.cols() || a.link_mass.size() != b.link_mass.size() ||
          a.link_mass.size() != a.link_com.cols())
        throw std::logic_error("pose_distance: poses have different link counts");
      // Link masses are equal for the same character; the mean keeps d symmetric if not.
      const Eigen::VectorXd mass = 0.5 * (a.link_mass + b.link_mass);
      return ((a.link_com - b.link_com).colwise().squaredNorm().transpose().array() *
              mass.array())
          .sum();
    }
    case Metric::kWeightedJointAngles: {
      const Eigen::Index joints = a.angles.size();
      if (b.angles.size() != joints)
        throw std::logic_error("pose_distance: poses have different joint angle counts");
      double root_weight = layout.root_weight;
      if (layout.angle_weights.size() == joints + 1) {
        // Compatibility: serves callers that pass the planar root pitch as the last angle
        // (and so give its weight as the last angle weight).
        root_weight = layout.angle_weights[joints];
      } else if (layout.angle_weights.size() != joints) {
        throw std::logic_error("pose_distance: expected one angle weight per joint angle");
      }
      double sum = 0.0;
      for (Eigen::Index i = 0; i < joints; ++i) {
        const double d = angle_difference(a.angles[i], b.angles[i]);
        sum += layout.angle_weights[i] * d * d;
      }
      const double root_angle = rotation_angle(a.root, b.root);
      return sum + root_weight * root_angle * root_angle;
    }
    case Metric::kShape:
      break;
  }
  throw std::logic_error("pose_distance: the shape metric does not compare poses");
}

double shape_distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                      const Eigen::VectorXd& weights) {
  if (a.size() != b.size())
    throw std::logic_error("shape_distance: shapes have different link counts");
  if (weights.size() == 0) return (a - b).cwiseAbs().sum();
  if (weights.size() != a.size())
    throw std::logic_error("shape_distance: weights do not match the link count");
  return (weights.array() * (a - b).cwiseAbs().array()).sum();
}

double motion_distance(Metric metric, const MotionFeatures& a, const MotionFeatures& b,
                       const MetricLayout& layout) {
  if (metric == Metric::kShape)
    return shape_distance(a.link_lengths, b.link_lengths, layout.shape_weights);
  if (a.poses.empty() || b.poses.empty()) return 0.0;
  if (a.poses.size() != b.poses.size())
    throw std::logic_error("motion_distance: motions have different sample counts");
  double sum = 0.0;
  for (std::size_t k = 0; k < a.poses.size(); ++k)
    sum += pose_distance(metric, a.poses[k], b.poses[k], layout);
  return sum;
}

double lee2002_joint_weight(const std::string& joint_name) {
  static constexpr const char* kWeighted[] = {"shoulder", "elbow", "hip",   "knee",
                                              "pelvis",   "root",  "spine", "waist",
                                              "abdomen",  "chest", "torso", "back"};
  std::string lower = joint_name;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const char* key : kWeighted)
    if (lower.find(key) != std::string::npos) return 1.0;
  return 0.0;
}

}  // namespace diverse
