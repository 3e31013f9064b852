// Characters as data: an MJCF model plus a character file beside it.
//
//   CharacterSpec spec = load_character_file("assets/characters/human2d.toml");
//   Character body = bind_character(spec, model);   // indices into one compiled model
//
// The character file (TOML, docs/reference/character-file.md has every field) says what
// controllers,
// constraints and metrics need and the MJCF does not: the root (planar x/z/pitch slides
// and hinge, or one free joint), the joint groups (each joint's role, the plane it turns
// in, the left/right pairs that share targets), the feet and hands, the WJA weight of
// each group and of the root, default PD gains, and the shape parameters if the body has
// any. Nothing about a particular character is compiled in: the planar human, the 3D
// human, the bird robot and a user's own biped load the same way.
//
// Torque limits are MuJoCo's own: every non-root joint is driven by exactly one `motor`
// actuator with gear 1 and `forcelimited` with a symmetric `forcerange` [-L, L]; L is the
// limit on the net joint torque (motor plus damping, physics/drive.h). A saved model
// therefore carries its limits for any MuJoCo program.
//
// bind_character() validates the model against the file and throws one-line UserErrors
// "FILE: FIELD: expected ..." naming the character file (or the model) and what is wrong:
// a joint or body the model lacks, an actuator on a root joint, a gear other than 1, an
// actuated joint without a torque limit, a non-root joint no group lists, a left/right
// pair whose joints differ in type or range, a link of zero mass.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace diverse {

// What a joint does in the body; controllers look joints up by role (and plane).
// kTail and kOther are for joints no controller treats specially (a tail, a fin, ...).
enum class JointRole { kHip, kKnee, kAnkle, kToe, kShoulder, kElbow, kWrist, kWaist, kNeck, kTail, kOther };
// The plane a hinge turns in, in the character's own frame at its standing pose:
// sagittal (pitch, about the lateral axis), coronal (roll, about the forward axis),
// transverse (yaw, about the vertical axis).
enum class JointPlane { kSagittal, kCoronal, kTransverse };
enum class RootKind { kPlanar, kFree };
enum class Side { kLeft = 0, kRight = 1, kCenter = 2 };

const char* to_string(JointRole role);   // "hip", "knee", ...
const char* to_string(JointPlane plane); // "sagittal", "coronal", "transverse"
const char* to_string(RootKind kind);    // "planar", "free"

// ---------------------------------------------------------------------------------------
// The character file, as parsed (independent of any compiled model).

struct JointGroupSpec {
  std::string name;                 // e.g. "hip", "hip_roll", "waist_upper"
  JointRole role = JointRole::kHip;
  JointPlane plane = JointPlane::kSagittal;
  std::vector<std::string> joints;  // one (centre) or two (left, right) MJCF joint names
  double wja = 0;                   // WJA weight of each joint of the group
  double kp = 0, kd = 0;            // default PD gains (Nm/rad, Nm s/rad)
};

// One shape parameter: a scale r in [min, max] applied to the length of every listed link.
struct ShapeGroupSpec {
  std::string name;                 // parameter "shape.<name>"
  std::vector<std::string> links;   // MJCF body names
  double min = 0.4, max = 2.5;
};

struct CharacterSpec {
  std::string file;         // the character file as given
  std::string name;
  std::string description;
  std::string model;        // resolved path of the MJCF
  RootKind root = RootKind::kPlanar;
  std::string root_body;    // the body that holds the root joint(s)
  // Planar: the slide along x, the slide along z and the pitch hinge. Free: `free` only.
  std::string root_x, root_z, root_pitch, root_free;
  double root_wja = 1;      // WJA weight of the root orientation
  std::vector<JointGroupSpec> groups;
  std::array<std::string, 2> feet;            // left, right foot bodies
  std::vector<std::string> hands;             // left, right hand bodies; may be empty
  std::vector<ShapeGroupSpec> shape;          // empty: control-only diversity
  double shape_min_link_length = 0.03;        // m (paper section 5)
  bool has_shape() const { return !shape.empty(); }
};

// Parses and validates a character file (not yet the model). Throws UserError.
CharacterSpec load_character_file(const std::string& path);

// A task's `character` argument: a character file (.toml), or an MJCF whose character file
// is the .toml of the same name beside it. Throws UserError if neither exists.
std::string resolve_character_file(const std::string& path);

// ---------------------------------------------------------------------------------------
// The character bound to one compiled model: every index a control loop needs, looked up
// once so that no rollout ever searches names.

struct CharacterJoint {
  std::string name;
  int group = -1;          // index into Character::groups
  Side side = Side::kCenter;
  int joint = -1;          // MuJoCo joint id
  int qpos = -1, dof = -1; // addresses
  int body = -1;           // the child body the joint moves
  int actuator = -1;       // its motor
  double lower = 0, upper = 0;  // range (rad); -inf/inf when unlimited
  double torque_limit = 0;      // Nm, the motor's forcerange
  std::array<double, 3> anchor0{};  // world position of the joint at the model's qpos0 (m)
  std::array<double, 3> axis0{};    // world axis of the joint at the model's qpos0
  double standing = 0;              // the joint's angle at the model's qpos0 (rad)
};

struct JointGroup {
  std::string name;
  JointRole role = JointRole::kHip;
  JointPlane plane = JointPlane::kSagittal;
  std::vector<int> joints;  // indices into Character::joints: [centre] or [left, right]
  double wja = 0, kp = 0, kd = 0;
};

struct Character {
  std::shared_ptr<const CharacterSpec> spec;
  RootKind root = RootKind::kPlanar;
  int root_body = -1;
  // Planar root: qpos/dof addresses of the x slide, z slide and pitch hinge.
  int root_x_qpos = -1, root_z_qpos = -1, root_pitch_qpos = -1;
  int root_x_dof = -1, root_z_dof = -1, root_pitch_dof = -1;
  // Free root: qpos address (position 3, then quaternion w x y z) and dof address (6).
  int root_qpos = -1, root_dof = -1;
  std::vector<int> root_joints;  // MuJoCo joint ids of the root

  std::vector<CharacterJoint> joints;  // every non-root joint, group by group
  std::vector<JointGroup> groups;      // character-file order
  std::array<int, 2> feet{-1, -1};     // foot body ids, left and right
  std::vector<int> hands;              // hand body ids (0 or 2)
  std::vector<int> links;              // every body of the character, model order
  double total_mass = 0;               // kg
  double height = 0;                   // m, standing: lowest to highest geom point at qpos0
  // The strength model (Task::strength, `diverse run --strength`): controllers multiply
  // every joint PD gain (kp, kd) by it. The torque limits need nothing here: the model's
  // forceranges carry the same factor (torque_limit above is read from them).
  double strength = 1.0;

  // Index of a group by name, or -1.
  int find_group(const std::string& name) const;
  // The first group with this role and plane, or -1.
  int find_group(JointRole role, JointPlane plane = JointPlane::kSagittal) const;
  // Internal degrees of freedom (non-root joints).
  int dof() const { return static_cast<int>(joints.size()); }
  // True when `geom` belongs to a foot body or to a body below one (toes). `foot` gets
  // 0 (left) or 1 (right).
  bool is_foot_geom(const mjModel* m, int geom, int* foot = nullptr) const;
  // True when `body` is one of the character's links.
  bool is_link(const mjModel* m, int body) const;

  // Planar characters only: the world pitch (rad) of joint `j`'s child link, root pitch
  // plus the joint angles along the chain from the root, and its rate (rad/s).
  double child_pitch(const double* qpos, int j) const;
  double child_pitch_rate(const double* qvel, int j) const;
  // Joints on the path from the root to joint j's child, inclusive (indices into joints).
  const std::vector<int>& chain(int j) const { return chain_[static_cast<size_t>(j)]; }

  std::vector<std::vector<int>> chain_;
  std::vector<int> foot_of_body_;  // per MuJoCo body: -1, 0 (left foot chain), 1 (right)
};

// Binds a character file to a compiled model (the bare character or a scene built on it).
// `origin` names the model in errors. Throws UserError.
Character bind_character(std::shared_ptr<const CharacterSpec> spec, const mjModel* m,
                         const std::string& origin);

}  // namespace diverse
