// The planar human's joint and link map (assets/characters/human2d.xml).
//
// Looks up, by name, the 16 hinge joints grouped into the 10 joint types that left and
// right limbs share (paper section 5), the root joints, the links the controllers and
// constraints need, and precomputes the qpos/dof/actuator indices so the control loop
// never searches names. Construction validates the model and throws UserError naming
// what is missing, so a hand-edited model fails at load rather than mid-rollout.
//
// Angles follow the model's convention: every hinge turns about -y, so angles are
// counter-clockwise positive in the x-z plane (x forward, z up), and a link's world pitch
// is the root pitch plus the joint angles along its chain.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <string>
#include <vector>

namespace diverse {

enum JointType : int {
  kHip = 0,
  kKnee,
  kAnkle,
  kWaistLower,
  kWaistUpper,
  kShoulder,
  kElbow,
  kWrist,
  kNeck,
  kHead,
  kNumJointTypes
};
const char* joint_type_name(int type);  // "hip", "knee", ...

struct PlanarJoint {
  std::string name;
  int type = 0;
  int joint = -1;       // joint id
  int qpos = -1;        // qpos address
  int dof = -1;         // dof address
  int actuator = -1;    // motor id (ctrl = torque)
  double lower = 0, upper = 0;  // range (rad)
  double torque_limit = 0;      // Nm (jnt_user[0])
};

struct PlanarHuman {
  explicit PlanarHuman(const mjModel* m, const std::string& origin = "model");

  // Root: slide x, slide z, hinge pitch.
  int root_x_qpos = -1, root_z_qpos = -1, root_pitch_qpos = -1;
  int root_x_dof = -1, root_z_dof = -1, root_pitch_dof = -1;
  int root_body = -1;  // pelvis

  std::vector<PlanarJoint> joints;                      // the 16 hinges
  std::array<std::vector<int>, kNumJointTypes> by_type;  // indices into joints

  // Links used by control and constraints (body ids).
  int pelvis = -1, abdomen = -1, chest = -1;
  std::array<int, 2> thigh{}, shin{}, foot{}, hand{};  // [left, right]
  std::array<int, 2> foot_geom{};
  // Every link (body id) of the character, in model order (17).
  std::vector<int> links;
  double total_mass = 0;  // kg

  // Leg segment lengths (m): hip to knee, knee to ankle (from the model's body offsets).
  double thigh_length = 0, shin_length = 0;

  // World pitch (rad) of a joint's child link: root pitch plus the joint angles from the
  // root to that joint, for the state in qpos.
  double child_pitch(const double* qpos, int joint_index) const;
  // Its world pitch rate (rad/s) for the velocities in qvel.
  double child_pitch_rate(const double* qvel, int joint_index) const;

 private:
  // For each joint, the joint indices on the path from the root (inclusive of itself).
  std::vector<std::vector<int>> chain_;
};

}  // namespace diverse
