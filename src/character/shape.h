// Body shape of the planar human: 10 link-length scales and the shaped MJCF model.
//
// Paper section 5, "Shape parameterization" (SPEC 3): every link length varies from the
// default as L'_i = r L_i with 0.4 <= r <= 2.5, no link shorter than 0.03 m, and every
// link keeps its mass (a longer link is less dense). Left and right limbs share their
// scale, which leaves 11 kinds of link; the neck and the head share one scale, "head",
// as Winter's anthropometric tables treat "head and neck" as one segment (D. A. Winter,
// "Biomechanics and Motor Control of Human Movement", table 4.1). That gives the paper's
// 10 shape parameters (its section 8: 36 control + 10 shape parameters).
//
// What a scale r of a link changes, in the sagittal plane (x forward, z up) of the
// link's own frame: the offsets (x and z) of its child links, its capsules' end points
// (fromto), the centre and radius of a sphere (the head is a ball whose diameter is its
// length), and the position of any joint or site. Capsule radii, lateral (y) offsets,
// masses and everything else stay as written; inertias follow from the geometry
// (inertiafromgeom). The root link's start height is set so that the character stands
// with the lowest point of its feet exactly where the base model has it (z = 0 for
// human2d), all joints at 0. docs/shapes.md has the table of parameters and lengths.
//
// A link's length L_i (m), the quantity that scales exactly by r: for a link with child
// links, the largest sagittal distance from its origin (proximal joint) to a child's
// origin (hip to knee, upper waist to neck); for an end link, the length of its capsule's
// axis (heel to toe, wrist to fingertip capsule centre) or, for a sphere, the distance
// from its origin to the far side of the ball (head joint to the top of the head).
//
// ShapeSpace parses the base MJCF once (a small purpose-built XML reader: we own the
// model) and afterwards only substitutes numbers, so building a shaped model costs the
// MuJoCo compile. It is immutable after construction: every method is const and
// thread-safe, meant to be called per sample from worker threads.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

#include "control/parameters.h"
#include "physics/model.h"

namespace diverse {

// The shape parameters, in ShapeSpace order.
enum ShapeParam : int {
  kShapePelvis = 0,  // hip joints to lower waist
  kShapeAbdomen,     // lower to upper waist
  kShapeChest,       // upper waist to neck base; the shoulders move with it
  kShapeHead,        // neck and head together
  kShapeThigh,       // hip to knee, both legs
  kShapeShin,        // knee to ankle
  kShapeFoot,        // heel to toe and ankle height
  kShapeUpperarm,    // shoulder to elbow, both arms
  kShapeForearm,     // elbow to wrist
  kShapeHand,        // wrist to fingertips
  kNumShapeParams
};
const char* shape_param_name(int param);  // "pelvis", "thigh", ...

inline constexpr double kShapeScaleMin = 0.4;  // paper section 5
inline constexpr double kShapeScaleMax = 2.5;
inline constexpr double kShapeMinLinkLength = 0.03;  // m

// The standing start of a shape: all joints at 0, root slides at 0.
struct StandingShape {
  double pelvis_z = 0;        // m, the root body's start height (its pos z)
  double height = 0;          // m, lowest foot point to the top of the highest geom
  double feet_z = 0;          // m, lowest point of the feet (the base model's value)
  double lowest_other_z = 0;  // m, lowest point of any geom that is not a foot; below
                              //   feet_z means a long arm reaches through the floor
};

class ShapeSpace {
 public:
  // Reads the character from MJCF text: the character file, or a scene built on it
  // (task/task.h scene_xml) whose extra geoms are copied through untouched. `origin`
  // names the text in errors. Throws UserError when the planar human's links are not
  // all there, or a link holds something the shape rules do not cover (a rotated frame,
  // an explicit <inertial>, a geom without a mass attribute or that is neither a fromto
  // capsule/cylinder nor a sphere, a default class).
  explicit ShapeSpace(std::string base_xml, std::string origin = "model");

  // The 10 parameters, "shape.pelvis", ..., unit "scale", range [lower, 2.5] where
  // lower = max(0.4, 0.03 m / the shortest link of the group) rounded up to 0.001
  // (0.429 for "shape.head": the 0.07 m neck; 0.4 for the others).
  const std::vector<ParamSpec>& specs() const { return specs_; }
  static int size() { return kNumShapeParams; }
  static Eigen::VectorXd identity() { return Eigen::VectorXd::Ones(kNumShapeParams); }
  // The scales of a parameter set holding the "shape.*" parameters (any order, beside
  // other parameters). Throws std::out_of_range if one is missing.
  Eigen::VectorXd scales_from(const ParameterSet& params) const;

  // The links (body names) in model order: the 17 bodies of PlanarHuman::links, left and
  // right counted separately, as the paper's shape distance sums over links.
  const std::vector<std::string>& link_names() const { return link_names_; }
  // The parameter (ShapeParam) that scales each link.
  const std::vector<int>& link_params() const { return link_params_; }
  const Eigen::VectorXd& base_link_lengths() const { return base_lengths_; }  // m
  // L'_i = r_group(i) L_i (m), link_names() order: the shape s of metric/metric.h
  // (MotionFeatures::link_lengths). Does not validate.
  Eigen::VectorXd link_lengths(const Eigen::VectorXd& scales) const;

  // Throws UserError "ORIGIN: shape.NAME: expected a scale in [LOWER, UPPER], got V" for
  // the first scale out of its range or not finite. `scales` must have size() entries
  // (std::invalid_argument otherwise).
  void validate(const Eigen::VectorXd& scales, const std::string& origin) const;

  // Start height, standing height and ground clearance of a shape. Does not validate.
  StandingShape standing(const Eigen::VectorXd& scales) const;

  // The shaped MJCF text (validated first; `origin` names the scales in errors). Only the
  // rescaled numbers change; all other text is copied, so identity() gives the base text
  // byte for byte.
  std::string xml(const Eigen::VectorXd& scales, const std::string& origin = "shape") const;
  // xml() compiled by MuJoCo (SharedModel::from_xml; compiles are serialized process-wide).
  std::shared_ptr<const SharedModel> compile(const Eigen::VectorXd& scales,
                                             const std::string& origin = "shape") const;

  const std::string& base_xml() const { return xml_; }

 private:
  // A collision shape of a link, in the link's frame at scale 1 (x, z; m).
  struct Primitive {
    bool sphere = false;
    Eigen::Vector2d a = Eigen::Vector2d::Zero();  // capsule start, or sphere centre
    Eigen::Vector2d b = Eigen::Vector2d::Zero();  // capsule end
    double radius = 0;
  };
  struct Link {
    std::string name;
    int param = 0;
    int parent = -1;                                   // link index, -1 for the root
    Eigen::Vector2d offset = Eigen::Vector2d::Zero();  // x, z of its pos in the parent (m)
    std::vector<Primitive> primitives;
  };
  // A numeric attribute value rewritten per shape: its span in the base text and values.
  enum class EditKind { kSagittal, kUniform, kRootHeight };
  struct Edit {
    size_t begin = 0, end = 0;
    std::vector<double> values;
    int link = 0;  // whose scale applies
    EditKind kind = EditKind::kSagittal;
  };
  struct Extent {
    double feet_low, other_low, top;  // m, relative to the root's origin
  };
  Extent extent(const Eigen::VectorXd& scales) const;

  std::string xml_;
  std::string origin_;
  std::vector<ParamSpec> specs_;
  std::vector<std::string> link_names_;
  std::vector<int> link_params_;
  Eigen::VectorXd base_lengths_;
  std::vector<Link> links_;   // model order; links_[0] is the root (pelvis)
  std::vector<Edit> edits_;   // sorted by position in xml_
  double root_z_ = 0;         // m, the root's start height in the base text
  double base_feet_low_ = 0;  // m, lowest foot point relative to the root at scale 1
};

// One-call form: ShapeSpace(base_xml).xml(scales).
std::string shaped_model_xml(const std::string& base_xml, const Eigen::VectorXd& scales);

}  // namespace diverse
