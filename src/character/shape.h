// Body shape of a planar character: link-length scales and the shaped MJCF model.
//
// Paper section 5, "Shape parameterization" (SPEC 3): every link length varies from the
// default as L'_i = r L_i with r in a parameter's range (the paper: 0.4 <= r <= 2.5), no
// link shorter than a minimum (0.03 m), and every link keeps its mass (a longer link is
// less dense). The parameters come from the character file's [shape] section
// (character/character.h, ShapeGroupSpec): each names the links it scales, so left and
// right limbs can share one scale; a link no parameter lists keeps its length.
//
// What a scale r of a link changes, in the sagittal plane (x forward, z up) of the
// link's own frame: the offsets (x and z) of its child links, its capsules' end points
// (fromto), the centre and radius of a sphere (a ball whose diameter is its length), and
// the position of any joint or site. Capsule radii, lateral (y) offsets, masses and
// everything else stay as written; inertias follow from the geometry (inertiafromgeom).
// The root link's start height is set so that the character stands with the lowest point
// of its feet (the character file's feet and every body below them) exactly where the
// base model has it, all joints at 0. docs/guide/shapes.md has the rules and the planar human's
// parameters.
//
// A link's length L_i (m), the quantity that scales exactly by r: for a link with child
// links, the largest sagittal distance from its origin (proximal joint) to a child's
// origin (hip to knee, upper waist to neck); for an end link, the length of its capsule's
// axis (heel to toe) or, for a sphere, the distance from its origin to the far side of
// the ball.
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

#include "character/character.h"
#include "params/parameters.h"
#include "physics/model.h"

namespace diverse {

// Throws the UserError of a character whose shape cannot vary: without [shape]
// parameters, "FILE: shape: expected [shape] parameters in the character file for --vary
// shape (this character has none)"; with a root that is not planar, "FILE: shape:
// expected a planar character (the shape rules scale the sagittal plane)". FILE is the
// character file (CharacterSpec::file).
void require_shape(const CharacterSpec& spec);

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
  // Reads the character `spec` describes from MJCF text: its model, or a scene built on
  // it (task/task.h scene_xml) whose extra geoms are copied through untouched. `origin`
  // names the text in errors. The root link is spec.root_body, directly in <worldbody>;
  // every body inside it is a link. Throws UserError when the character cannot vary its
  // shape (require_shape), a link the [shape] section or the feet name is not in the
  // character ("FILE: shape.parameters[i].links: ..."), or a link holds something the
  // shape rules do not cover (a rotated frame, an explicit <inertial>, a geom without a
  // mass attribute or that is neither a fromto capsule/cylinder nor a sphere, a default
  // class).
  ShapeSpace(std::string base_xml, const CharacterSpec& spec, std::string origin = "model");

  // One parameter per [[shape.parameters]] entry, in file order: "shape.NAME", unit
  // "scale", range [lower, max] where lower = max(min, min_link_length / the shortest
  // link of the group) rounded up to 0.001 (the planar human: 0.429 for "shape.head",
  // whose 0.07 m neck needs it; 0.4 for the others).
  const std::vector<ParamSpec>& specs() const { return specs_; }
  int size() const { return static_cast<int>(specs_.size()); }
  Eigen::VectorXd identity() const { return Eigen::VectorXd::Ones(size()); }
  // The scales of a parameter set holding the "shape.*" parameters (any order, beside
  // other parameters). Throws std::out_of_range if one is missing.
  Eigen::VectorXd scales_from(const ParameterSet& params) const;

  // The links (body names) in model order, Character::links: every body of the
  // character, left and right counted separately, as the paper's shape distance sums over
  // links.
  const std::vector<std::string>& link_names() const { return link_names_; }
  // The parameter (specs() index) that scales each link; -1 for a link no parameter
  // lists, which keeps scale 1.
  const std::vector<int>& link_params() const { return link_params_; }
  const Eigen::VectorXd& base_link_lengths() const { return base_lengths_; }  // m
  // L'_i = r_group(i) L_i (m; L_i for a link in no group), link_names() order: the shape
  // s of metric/metric.h (MotionFeatures::link_lengths). Does not validate.
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
    int param = -1;                                    // -1: in no parameter, scale 1
    bool foot = false;                                 // a foot or a body below one
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
  // The scale of link i: its parameter's, or 1.
  double scale(const Eigen::VectorXd& scales, int link) const {
    const int p = links_[static_cast<size_t>(link)].param;
    return p < 0 ? 1.0 : scales[p];
  }

  std::string xml_;
  std::string origin_;
  std::vector<ParamSpec> specs_;
  std::vector<std::string> link_names_;
  std::vector<int> link_params_;
  Eigen::VectorXd base_lengths_;
  std::vector<Link> links_;   // model order; links_[0] is the root
  std::vector<Edit> edits_;   // sorted by position in xml_
  double root_z_ = 0;         // m, the root's start height in the base text
  double base_feet_low_ = 0;  // m, lowest foot point relative to the root at scale 1
};

// One-call form: ShapeSpace(base_xml, spec).xml(scales).
std::string shaped_model_xml(const std::string& base_xml, const CharacterSpec& spec,
                             const Eigen::VectorXd& scales);

}  // namespace diverse
