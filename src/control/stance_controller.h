// Stance control for a character with a free root (the 3D human, the bird robot) or a
// planar one (the land phase of skills/jump_forward.toml, control/module_stance.h): balance
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
//       F_xy = M (com_kp (s + offset - c) - com_kd (v - v_d)),
//       F_z  = M (g + height_kp (h0 - c_z) - height_kd v_z),
//   with s the centre of the stance soles, c and v the COM and its velocity, v_d a
//   horizontal COM velocity to reach (0 to stand; a push-off's speed), h0 the COM height
//   at reset(). F_xy is limited so that the centre of pressure it implies,
//   p = c_xy - h F_xy / F_z (h the COM height above the soles), stays cop_margin inside
//   the support polygon (the convex hull of the stance soles): a larger ankle torque would
//   only tip the feet.
// - Sharing F between the legs. Where p lies on the line between the two soles' centres
//   gives each foot its share alpha_s of the load; each foot's own centre of pressure cop_s
//   is its sole's centre moved by what lies off that line (so sum alpha_s cop_s = p), and
//   each leg pushes alpha_s F from cop_s. The legs' forces add up to F, their moment about
//   the COM is (p - c) x F = 0, and they do not squeeze the feet apart (the feet would
//   creep on MuJoCo's soft friction). A push (ComForce::kPush) with two stance legs
//   shares F equally, each leg pushing from its sole's centre moved only along the
//   heading: with its F_z held at a tenth of the weight while the COM rises, p lies ten
//   times further from the COM than in balance, and a load split by it, or feet pushing
//   from points moved sideways by it, made a push-off chaotic (a 1e-6 change of a jump's
//   parameters parted its left and right threefold per step at the human's take-off).
// - Root (pelvis) and torso. The root tracks an upright orientation with the heading it had
//   at reset(): a world torque T = root_kp e_root - root_kd w_root (e the rotation vector to
//   the target, w the angular velocity). The root is unactuated, so the stance legs supply
//   T plus what the other hinges on the root (waist, swing hips) take away, sum tau_o a_o
//   (SIMBICON's tau_stance = -tau_torso - tau_swing, Coros et al. 2010), shared by load
//   (each stance leg at least a tenth); a universal hip cannot turn the root about its
//   missing axis, so the yaw part is lost. The torso (the child of the deepest waist hinge,
//   if any) tracks its standing orientation relative to the root's target with the waist
//   hinges: tau_w = a_w . (kp e_torso) - kd (a_w . w_torso), the waist group's gains.
// - Stance legs: J^T. Each stance leg realizes its force and its share of the root torque,
//   tau = J^T (F_leg, T_leg), J the Jacobian of the point cop_s and of the root's
//   orientation with the foot as the base; for every hinge j between the foot and the root
//       tau_j = -a_j . ((cop_s - p_j) x F_leg) - a_j . T_leg
//   (a_j its world axis d->xaxis, p_j its anchor; the minus because MuJoCo's tree runs from
//   the root down, the hinge turning the foot side). Driving the whole leg this way (not
//   just the hip) leaves the legs' sideways sway, which does not turn the root, to the COM
//   force alone. The hips get only these torques; the knees (and the bird's ankles) add
//   them to their PD toward the targets.
// - Yaw (StanceGains::yaw_kp, yaw_kd; off by default). A universal hip cannot turn the
//   root about its missing axis, but two stance legs can, by pushing unequally along the
//   line at right angles to the one between their centres of pressure: with d = cop_l -
//   cop_r (horizontal) and n = z x d / |d|, the left leg adds D n and the right -D n, a
//   moment |d| D about the vertical and no net force, so the COM force and its centre of
//   pressure stay as they were. D = (yaw_kp e_z - yaw_kd w_z) / |d| (e_z the vertical part
//   of the root's rotation error, w_z its angular velocity about the vertical), at most a
//   quarter of F_z, which leaves each foot's horizontal force well inside the friction
//   cone. Like the COM force it becomes joint torques of the stance legs, tau = J^T.
//   Without it a jump's take-off and landing keep whatever spin the legs' unequal pushes
//   give the body: a bird-robot jump whose left and right parameters differ by 0.5 % of
//   their ranges turned up to 1 rad about the vertical before it landed.
// - Feet. The hinges of each foot body keep the sole flat: they track the rotation that
//   turns the foot's standing "up" to world up, tau = a . (kp e_foot) - kd (a . w_foot),
//   with the foot group's gains, plus the J^T terms in stance.
// - Everything else (arms, neck, swing legs) is PD toward the targets,
//   kp (target - q) - kd qdot with the character file's group gains, plus gravity
//   compensation tau_j = a_j . ((c_sub - p_j) x m_sub g z) for the links the hinge carries
//   (c_sub, m_sub the subtree's COM and mass).
//
// Damping. A term's derivative part on a link's world rate, -kd (a . w_child), is split into
// the joint's own rate, -kd qdot (which the drive integrates implicitly), and
// -kd (a . w_parent) in u (a . w_child = a . w_parent + qdot for the orthogonal hinges of a
// universal joint), so large gains stay stable at a 2 ms step. Under constrained damping
// (physics/drive.h, Damping::kConstrained) the whole derivative part is a row of the
// drive's solve instead: joint k's damped velocity is qdot_k plus a_k . w of each body it
// damps (w = J_rot qvel, mj_jacBody), including the root's damping the stance legs share,
// so the dampers act on the end-of-step velocities the contacts allow; the torque at the
// step's velocities is the same either way.
//
// The start pose: standing_pose() leans the legs of qpos0 about the feet until the COM is
// over the middle of the soles (a human's COM at qpos0 is over its ankles, 7 cm from the
// heels, too close to the edge to catch a 0.3 m/s push backward).
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <vector>

#include "character/character.h"
#include "physics/drive.h"

namespace diverse {

struct StanceGains {
  double com_kp = 40;                // 1/s^2: F_xy = M (com_kp e - com_kd v)
  double com_kd = 12;                // 1/s
  double height_kp = 100;            // 1/s^2, vertical COM servo around the reset height
  double height_kd = 20;             // 1/s
  double root_kp = 0;                // Nm/rad; 0: 2 M g h0 (M the mass, h0 the standing COM height)
  double root_kd = 0;                // Nm s/rad; 0: root_kp / 10 s
  double cop_margin = 0.02;          // m, the centre of pressure stays this far inside the support
  bool gravity_compensation = true;  // on the joints off the stance legs
  // The root's yaw with two stance legs (Nm/rad, Nm s/rad; 0 and 0: not held, the default).
  // See "Yaw" above.
  double yaw_kp = 0;
  double yaw_kd = 0;
};

class StanceController {
 public:
  // `m` is the model `body` was bound to (a free root, or a planar one: x, z, pitch).
  // Targets start at the model's standing pose (qpos0 of every joint of the character).
  StanceController(const Character& body, const mjModel* m, StanceGains gains = {});

  // The joint targets (rad), one per Character::joints entry. Joints whose body is a foot,
  // the stance hips and the tracked waist use world-frame targets instead (see above).
  void set_targets(std::vector<double> targets);
  const std::vector<double>& targets() const { return targets_; }
  // Where the COM is held relative to the centre of the stance soles (m, world x, y).
  void set_com_offset(double x, double y) { offset_ = {x, y}; }
  // The horizontal COM velocity the virtual force's damping drives towards (m/s, world x,
  // y): 0 holds the COM still; a push-off sets the speed it leaves the ground with.
  void set_com_velocity(double x, double y) { velocity_ = {x, y}; }

  // Adjustments for a controller that runs stance control as phases of a larger state
  // machine (control/module_stance3d.h, a skill's stance phases).
  //
  // Pitches (rad) turn the root, the torso and the feet from their standing orientation
  // about the lateral axis of the heading taken at reset() (positive backwards, as the
  // joints about -y turn): the root's target becomes pitch(root) * heading * standing, and
  // likewise the torso's target and the feet's "up". All 0 (the default) is standing.
  // The second form gives each foot its own pitch (left, right).
  void set_pitches(double root, double torso, double foot) { set_pitches(root, torso, {foot, foot}); }
  void set_pitches(double root, double torso, const std::array<double, 2>& feet);
  // PD gains of joint k (its group's by default). For a foot joint they are the gains of
  // the foot's world tracking, for the tracked waist those of the torso's; a stance hip
  // takes none (the root's gains act through it).
  void set_joint_gains(int k, double kp, double kd);
  // The root's orientation gains (Nm/rad, Nm s/rad; by default StanceGains').
  void set_root_gains(double kp, double kd);
  // What the virtual force on the COM does. kBalance: both servos (the default). kSupport:
  // F_xy as usual and F_z = M (g - height_kd v_z), no height servo, so the joint targets
  // decide how low the body goes. kPush: as kSupport, but F_xy is not held to the support
  // polygon: the legs push the COM toward its goal even if that tips the feet (a jump's
  // take-off; the joint drive still limits every torque). kNone: no virtual force; the
  // stance legs only hold the root's orientation and the feet track theirs.
  enum class ComForce { kBalance, kSupport, kPush, kNone };
  void set_com_force(ComForce mode) { com_force_ = mode; }
  // The heading (rad, yaw of the root's x axis about world z) taken at reset().
  double heading() const { return heading_; }
  // The pitches set_pitches() takes, as they are in the state d (after mj_kinematics): of
  // the root's and the torso's forward axes and of the feet's "up" (their mean), each
  // relative to standing, about the heading's lateral axis. The torso's is the root's when
  // there is no waist.
  struct Pitches {
    double root = 0, torso = 0, foot = 0;
  };
  Pitches measured_pitches(const mjData* d) const;

  // A start pose for standing: the model's qpos0 with each leg leaned about its foot (the
  // sagittal hinges of the hips turned by -theta and of the feet by +theta, so the root
  // stays upright and the soles flat, the root moved so the soles stay where they were)
  // until the COM is over the centre of the soles plus the COM offset (x only). qpos (nq).
  std::vector<double> standing_pose(const mjModel* m) const;

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
  // The yaw push D of the last control() (N; 0 when yaw is not held or one leg stands).
  double yaw_push() const { return yaw_force_; }
  // Each stance foot's share of the vertical force (sums to 1 in stance).
  const std::array<double, 2>& load() const { return load_; }
  double mass() const { return mass_; }

 private:
  struct Leg {
    std::vector<int> joints;  // Character::joints indices from the foot up to the hip
    std::vector<int> hips;    // those whose body's parent is the root body
    std::vector<int> foot;    // those on the foot body
  };
  void measure(const mjModel* m, const mjData* d);
  bool foot_contact(const mjData* d, int side) const;

  const Character& body_;
  StanceGains gains_;
  std::vector<double> targets_;
  std::array<double, 2> offset_{0, 0};
  std::array<double, 2> velocity_{0, 0};
  ComForce com_force_ = ComForce::kBalance;
  double pitch_root_ = 0, pitch_torso_ = 0;
  std::array<double, 2> pitch_foot_{0, 0};  // rad, left and right
  std::vector<double> kp_, kd_gain_;  // per joint: PD gains

  // Structure, found once.
  std::array<Leg, 2> legs_;
  std::vector<int> leg_of_;         // per joint: 0, 1 (in a leg chain) or -1
  std::vector<char> is_hip_;        // per joint: a stance-leg hinge on a child of the root
  std::vector<int> waist_;          // joints tracking the torso orientation
  int torso_body_ = -1;             // MuJoCo body id, or -1 when there is no waist
  std::vector<int> root_children_;  // joints whose body's parent is the root body
  std::vector<int> geom_side_;      // per geom: 0, 1 (a foot or a body below it) or -1
  std::array<std::array<double, 3>, 2> foot_up_{};   // standing "up" in each foot's frame
  std::array<double, 4> torso_in_root_{1, 0, 0, 0};  // standing torso orientation in root
  std::array<double, 4> root_standing_{1, 0, 0, 0};  // root orientation at qpos0
  double mass_ = 0, gravity_ = 9.81;
  double root_kp_ = 0, root_kd_ = 0;

  // Targets taken at reset() (and set_pitches()).
  void update_targets();
  double heading_ = 0;
  std::array<double, 4> heading_quat_{1, 0, 0, 0};  // yaw of the heading relative to standing
  std::array<double, 4> root_target_{1, 0, 0, 0};
  std::array<double, 4> torso_target_{1, 0, 0, 0};
  std::array<std::array<double, 3>, 2> foot_up_target_{{{0, 0, 1}, {0, 0, 1}}};  // left, right
  double height_target_ = 0;

  // Per step.
  std::array<double, 3> com_{}, com_vel_{}, force_{};
  std::array<double, 2> support_{};
  std::array<bool, 2> stance_{false, false};
  std::array<double, 2> load_{0, 0};
  std::array<std::array<double, 3>, 2> leg_force_{};  // N, the virtual force of each leg
  std::array<std::array<double, 3>, 2> leg_cop_{};    // m, where it acts (on the ground)
  double yaw_force_ = 0;                               // N, the yaw push D (left +, right -)
  std::vector<double> u_, kd_;
  // Under Damping::kConstrained the world-frame dampers are rows of the drive's solve
  // (physics/drive.h): per joint, its damped velocity's weights over the dofs (its own
  // qdot plus the world angular velocities it damps about its axis); `row_used_` marks the
  // joints that have one this step.
  bool rows_ = false;
  std::vector<std::vector<double>> row_;
  std::vector<char> row_used_;
  std::vector<int> jacobian_bodies_;              // bodies whose J_rot this step holds
  std::vector<std::vector<mjtNum>> jacobians_;   // their 3 x nv J_rot, the same order
  std::vector<DampedDof> damped_;
  // Adds weight * (a_k . w_body) to joint k's damped velocity (a_k its world axis).
  void add_body_damping(const mjModel* m, const mjData* d, int k, int body, double weight);
  // Joint k's damped velocity now: qdot_k, or its row times qvel.
  double damped_velocity_now(const mjData* d, int k) const;
};

}  // namespace diverse
