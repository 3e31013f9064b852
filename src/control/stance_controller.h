// Stance control for a character with a free root (the 3D human, the bird robot): balance
// on the feet in contact, body upright, feet flat, every other joint toward a pose.
//
//   StanceController stance(body, m);        // targets: the model's standing pose qpos0
//   stance.reset(m, d);                       // after mj_step1 (or mj_forward)
//   each step, after mj_step1: stance.control(m, d, drive);
//
// It works on a bound Character (character/character.h: roles, sides, addresses) and asks
// the joint drive (physics/drive.h) for one torque per Character::joints entry; it never
// writes d->ctrl or the model, and it never applies an external force: the root is
// unactuated and all the balance comes from joint torques, which the drive keeps within
// each joint's limit on the net torque.
//
// Per step, with the stance legs those whose foot (or a body below it) touches something:
//
// - Centre of mass. A virtual force on the COM (Pratt et al. 2001),
//       F_xy = M (com_kp (s + offset - c) - com_kd v),  F_z = M (g + height_kp (h0 - c_z)
//              - height_kd v_z),
//   with s the centre of the stance feet's soles, c and v the COM and its velocity, h0 the
//   COM height at reset(). F_xy is limited so that the centre of pressure it implies,
//   c_xy - h F_xy / F_z (h the COM height above the soles), stays cop_margin inside the
//   support polygon (the convex hull of the stance soles): a larger ankle torque would only
//   tip the feet. F is split equally over the stance legs and realized as joint torques
//   tau = J^T F: for every hinge j between a stance foot and the root,
//       tau_j = -a_j . ((c - p_j) x F_leg)
//   (a_j its world axis d->xaxis, p_j its anchor; the minus because MuJoCo's tree runs from
//   the root down and the hinge turns the foot side, while J is the COM's Jacobian with the
//   foot as the base).
// - Root and torso. The root (pelvis) tracks an upright orientation with the heading it had
//   at reset(): a world torque T = root_kp e_root - root_kd w_root (e the rotation vector to
//   the target, w the angular velocity). The root is unactuated, so the torque comes from
//   the stance hips: the hinges under the root body that are not in a stance leg (waist,
//   swing hips) act on it too, and the stance hips make up the rest (SIMBICON's
//   tau_stance = -tau_torso - tau_swing; Coros et al. 2010):
//       sum over stance hips of tau_h a_h = -T - sum over other root hinges of tau_o a_o,
//   shared equally by the stance legs and projected on each hip hinge's axis
//   (tau_h = a_h . H_leg; a universal hip loses the yaw part). The J^T F part of the hips
//   is added to it. The torso (the child of the deepest waist hinge, if any) tracks its
//   standing orientation relative to the root's target with the waist hinges:
//   tau_w = a_w . (kp e_torso) - kd (a_w . w_torso), gains of the waist group.
// - Feet. The hinges of each foot body keep the sole flat: they track the rotation that
//   turns the foot's standing "up" to world up, tau = a . (kp e_foot) - kd (a . w_foot),
//   with the foot group's gains, plus their J^T F share in stance.
// - Everything else (knees, the bird's ankles, arms, neck, swing legs) is PD toward the
//   targets, kp (target - q) - kd qdot with the character file's group gains, plus, off the
//   stance legs, gravity compensation tau_j = a_j . ((c_sub - p_j) x m_sub g z) for the
//   links the hinge carries (c_sub, m_sub the subtree's COM and mass).
//
// Damping. Every term's derivative part -kd (a . w_child) is split into the joint's own rate,
// -kd qdot (which the drive integrates implicitly), and -kd (a . w_parent) in u, so large
// gains stay stable at a 2 ms step.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <vector>

#include "character/character.h"
#include "physics/drive.h"

namespace diverse {

struct StanceGains {
  double com_kp = 40;        // 1/s^2: F_xy = M (com_kp e - com_kd v)
  double com_kd = 12;        // 1/s
  double height_kp = 100;    // 1/s^2, vertical COM servo around the reset height
  double height_kd = 20;     // 1/s
  double root_kp = 0;        // Nm/rad; 0: 2 M g h0 (M the mass, h0 the standing COM height)
  double root_kd = 0;        // Nm s/rad; 0: root_kp / 10 s
  double cop_margin = 0.02;  // m, the centre of pressure stays this far inside the support
  bool gravity_compensation = true;  // on the joints off the stance legs
};

class StanceController {
 public:
  // `m` is the model `body` was bound to. Targets start at the model's standing pose
  // (qpos0 of every joint of the character).
  StanceController(const Character& body, const mjModel* m, StanceGains gains = {});

  // The joint targets (rad), one per Character::joints entry. Joints whose body is a foot,
  // the stance hips and the tracked waist use world-frame targets instead (see above).
  void set_targets(std::vector<double> targets);
  const std::vector<double>& targets() const { return targets_; }
  // Where the COM is held relative to the centre of the stance soles (m, world x, y).
  void set_com_offset(double x, double y) { offset_ = {x, y}; }

  // Takes the world targets from the state in d (after mj_step1 or mj_forward): the
  // heading of the root, the COM height.
  void reset(const mjModel* m, const mjData* d);
  // One step (after mj_step1): torques for every joint into `drive`
  // (k = index into Character::joints).
  void control(const mjModel* m, const mjData* d, JointDrive& drive);

  // What the last control() saw and asked for.
  const std::array<double, 3>& com() const { return com_; }
  const std::array<double, 3>& com_velocity() const { return com_vel_; }
  const std::array<double, 3>& virtual_force() const { return force_; }
  const std::array<double, 2>& support_centre() const { return support_; }
  const std::array<bool, 2>& stance() const { return stance_; }
  double mass() const { return mass_; }

 private:
  struct Leg {
    std::vector<int> joints;  // Character::joints indices from the foot up to the hip
    std::vector<int> hips;    // those whose body's parent is the root body
    std::vector<int> foot;    // those on the foot body
  };
  void measure(const mjModel* m, const mjData* d);
  bool foot_contact(const mjModel* m, const mjData* d, int side) const;

  const Character& body_;
  StanceGains gains_;
  std::vector<double> targets_;
  std::array<double, 2> offset_{0, 0};

  // Structure, found once.
  std::array<Leg, 2> legs_;
  std::vector<int> leg_of_;        // per joint: 0, 1 (in a leg chain) or -1
  std::vector<char> is_hip_, is_foot_;
  std::vector<int> waist_;         // joints tracking the torso orientation
  int torso_body_ = -1;            // MuJoCo body id, or -1 when there is no waist
  std::vector<int> root_children_; // joints whose body's parent is the root body
  std::vector<int> geom_side_;     // per geom: 0, 1 (a foot or a body below it) or -1
  std::array<std::array<double, 3>, 2> foot_up_{};  // standing "up" in each foot's frame
  std::array<double, 4> torso_in_root_{1, 0, 0, 0};  // standing torso orientation in root
  std::array<double, 4> root_standing_{1, 0, 0, 0};  // root orientation at qpos0
  double mass_ = 0, gravity_ = 9.81;
  double root_kp_ = 0, root_kd_ = 0;

  // Targets taken at reset().
  std::array<double, 4> root_target_{1, 0, 0, 0};
  double height_target_ = 0;

  // Per step.
  std::array<double, 3> com_{}, com_vel_{}, force_{};
  std::array<double, 2> support_{};
  std::array<bool, 2> stance_{false, false};
  std::vector<double> u_, kd_;
};

}  // namespace diverse
