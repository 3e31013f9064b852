// The heading frame of a character with a free root, for skills that track links in it
// (SIMBICON, Yin, Loken, van de Panne 2007, section 3; Coros, Beaudoin, van de Panne 2010's
// Cartwheel-3D): z up, x the root's forward axis turned about z only (the twist of the
// root's orientation about world up, relative to its standing orientation), y = z x x.
//
//   StandingFrames s = standing_frames(m, body.root_body);     // once per model
//   double h = root_heading(d, body.root_body, s);              // each step
//   HeadingLink femur = heading_link(body, s, femur_body, m);
//   heading_link_target(femur, h, angles, quat);                 // where it should be
//
// A heading-frame target of a link with hinges (pitch, roll) is the rotation
// Rot(a_1, q_1) Rot(a_2, q_2) ... applied to the link's standing orientation, a_i the
// hinges' world axes at the standing pose, in the heading frame: the orientation the link
// would have with its parent at its standing orientation and its hinges turned by q_i from
// standing. The root's is Rot(-y, pitch) Rot(x, roll) in the heading frame applied to its
// standing orientation without its heading.
//
// Also here, because the skill engine and its modules for free roots share them: the legs'
// structure (LegLayout) and the gravity compensation of one hinge.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <vector>

#include "character/character.h"

namespace diverse {

// The model's standing pose (qpos0) by forward kinematics, where every hinge adds no
// rotation (MuJoCo turns a hinge by qpos - qpos0) and the free root sits at its body frame.
struct StandingFrames {
  std::vector<std::array<double, 4>> quat;  // per MuJoCo body: world orientation
  std::array<double, 4> root{1, 0, 0, 0};  // the root's
  double root_heading = 0;                  // rad, of the root's standing orientation
  double mass = 0;                          // kg, the root's subtree
  double com_height = 0;                    // m, the standing COM above the root's origin frame
};
StandingFrames standing_frames(const mjModel* m, int root_body);

// Heading (rad) of orientation q: its forward (x) axis turned onto the ground plane.
double heading_of(const double* q);
// The root's heading in state d (after mj_kinematics), relative to standing.
double root_heading(const mjData* d, int root_body, const StandingFrames& s);
// Rotation vector (world) of the rotation that takes orientation q to `target`.
void rotation_error(const double* target, const double* q, double* e);

// A link tracked in the heading frame: its body, its hinges (Character::joints indices in
// order, proximal first) and their world axes at the standing pose.
struct HeadingLink {
  int body = -1;
  std::vector<int> joints;
  std::vector<std::array<double, 3>> axes;
  std::array<double, 4> standing{1, 0, 0, 0};
};
HeadingLink heading_link(const Character& body, const mjModel* m, const StandingFrames& s, int link_body);
// The world orientation target of `link`: heading, the hinges' rotations by `angles` (one
// per hinge), the standing orientation.
void heading_link_target(const HeadingLink& link, double heading, const double* angles, double* quat);
// The root's world orientation target for (pitch, roll) in the heading frame.
void heading_root_target(const StandingFrames& s, double heading, double pitch, double roll, double* quat);

// The legs of a character, found from its structure alone.
struct LegLayout {
  std::vector<int> leg_of;                 // per joint: 0, 1 (in the chain from the root to a foot) or -1
  std::vector<char> hip;                   // per joint: a leg joint whose body's parent is the root body
  std::vector<char> foot;                  // per joint: a leg joint on the foot body (or below it)
  std::array<std::vector<int>, 2> middle;  // per leg: joints between the hip and the foot
  std::vector<int> root_children;          // joints on a body whose parent is the root body
};
LegLayout leg_layout(const Character& body);

// Gravity compensation of one hinge: a . ((c_sub - p) x m_sub g z), the torque that holds
// the links it carries against gravity (c_sub, m_sub their COM and mass).
double gravity_torque(const mjModel* m, const mjData* d, const CharacterJoint& j, double gravity);

}  // namespace diverse
