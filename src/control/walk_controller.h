// "walk3d": SIMBICON walking (Yin, Loken, van de Panne 2007) for characters with a free
// root (the 3D human, the bird robot), registered in control/builtin_controllers.cc.
//
// A stride is four states: for each leg in turn a timed state ("lift", lift.duration s)
// and then a state that ends when the swing foot touches something ("strike"). States 0
// and 1 swing the left leg, states 2 and 3 the right one; the right-leg states use the
// same parameters as the left-leg ones, mirrored (left/right pairs share targets, and the
// character file's coronal hinges of a pair are mirrored, so equal angles are mirror
// images).
//
// The heading frame: z up, x the root's forward axis turned about z only (the twist of the
// root orientation about world up, relative to its standing orientation), y = z x x.
//
// Targets per state. One value per joint but the neck (which holds its standing angle):
//   pelvis.pitch/.roll     the root's orientation in the heading frame, relative to
//                          standing; held by the stance hip (below)
//   torso.<waist group>    the torso (child of the waist hinges) in the heading frame,
//                          relative to standing, held by the waist hinges
//   swing.<hip group>      the swing femur in the heading frame, relative to standing,
//                          plus the balance feedback (below), held by the swing hip
//   swing.<foot group>     the swing foot in the heading frame, relative to standing, held
//                          by the hinges of the foot body (the human's ankle, the robot's
//                          toe joint)
//   swing.<group>, stance.<group>
//                          the other leg joints (knee; the robot's ankle; the stance foot's
//                          hinges): joint angles
//   swing_side.<group>, stance_side.<group>
//                          the other left/right joints (arms) on the swing leg's or the
//                          stance leg's side: joint angles
//   <group>                any other centre joint: a joint angle
// A heading-frame target of a link with hinges (pitch, roll) is the rotation
// Rot(a_pitch, pitch) Rot(a_roll, roll) applied to the link's standing orientation, with
// a_pitch, a_roll the hinges' world axes at the standing pose, in the heading frame: the
// orientation the link would have with its parent at its standing orientation and the two
// hinges turned by (pitch, roll) from standing. Rolls of centre links (pelvis, torso) are
// mirrored with the swing side: positive raises the swing-side hip / leans the torso
// toward the stance side.
//
// Balance feedback (SIMBICON): the swing femur's targets are
//   pitch = swing.hip + sagittal.cd d_x + sagittal.cv v_x,
//   roll  = swing.hip_roll + coronal.cd d_y + coronal.cv v_y,
// with d the COM minus the stance foot's origin (the human's ankle, the robot's toe joint)
// and v the COM velocity, in the heading frame, y measured toward the swing side.
//
// Torques. Tracked links (femur, foot, torso) use the rotation error e (world rotation
// vector from the link's orientation to its target) projected on each hinge's world axis
// a_j: tau_j = kp a_j . e - kd a_j . w_link, the derivative part split into the joint's
// own rate (implicit in the drive, physics/drive.h) and a_j . w_parent. Joint targets use
// kp (target - q) - kd qdot. The gains are the character file's group gains. Every joint
// off the stance leg adds gravity compensation for the links it carries. The stance hip
// makes the root track its target: the root needs T = root_kp e_root - root_kd w_root, and
// the stance hip supplies it together with what the other hinges on the root (swing hip,
// waist, neck) take away, tau_stance = -a . (T + sum_o tau_o a_o) on each of its hinges
// (SIMBICON's tau_stance = -tau_torso - tau_swing, as in Coros et al.'s Cartwheel; a
// universal hip cannot turn the root about its missing axis, so the yaw part is lost).
// Nothing but joint torques moves the character; the drive keeps each net joint torque
// within its limit.
//
// The start state (start_pose): static, in the first state's pose with the heading frame
// the world's: the root at its pelvis target, the joints at their targets, the swing femur
// and foot and the torso at their heading-frame targets (without feedback), the stance
// femur and foot at their standing orientations, the stance sole on the floor.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "character/character.h"
#include "control/controller.h"
#include "control/parameters.h"

namespace diverse {

enum WalkState : int { kLeftLift = 0, kLeftStrike, kRightLift, kRightStrike, kNumWalkStates };
const char* walk_state_name(int state);  // "left_lift", "left_strike", ...
// The leg that swings in a state: 0 left, 1 right.
inline int swing_leg(int state) { return state < kRightLift ? 0 : 1; }

// Constants that are not optimized (documented defaults; the task file may override).
struct WalkControllerConfig : ControllerConfig {
  double root_kp = 0;        // Nm/rad, the root's PD; 0: 2 M g h (M the mass, h the standing COM height)
  double root_kd = 0;        // Nm s/rad; 0: root_kp / 5 s
  double strike_timeout = 2; // s; a strike state whose foot never touches down ends here
  bool gravity_compensation = true;  // on every joint off the stance leg
  double stance_support = 1;  // the stance knee (and joints down to the foot) carry this much of M g

  std::shared_ptr<const ControllerConfig> with_landing_height(double height) const override;
  double landing_height() const override { return 0; }
};

class WalkControllerType : public ControllerType {
 public:
  const char* name() const override { return "walk3d"; }
  const char* skill(const ControllerConfig&) const override { return "walk"; }
  const char* description() const override {
    return "SIMBICON walk of a character with a free root (per leg a timed state, then until touch-down)";
  }
  std::shared_ptr<const ControllerConfig> read_config(const TomlReader& r) const override;
  void check(const Character& body, const std::string& task_file) const override;
  std::vector<ParamSpec> parameter_specs(const Character& body,
                                         const ControllerConfig& config) const override;
  std::unique_ptr<Controller> make(const Character& body, const ControllerConfig& config,
                                   const std::vector<double>& values) const override;
};

class WalkController : public Controller {
 public:
  // Standing orientations and axes are read from the model `body` is bound to (at its
  // qpos0) at the first start_state() or reset().
  WalkController(const Character& body, const WalkControllerConfig& config);

  // The free parameters for `body`: per state ("lift", "strike") one target per joint but
  // the neck (the stance hip's two are the pelvis's), then lift.duration and the four
  // feedback gains (49 for the 3D human, 29 for the bird robot).
  static std::vector<ParamSpec> parameter_specs(const Character& body);
  void set_parameters(const std::vector<double>& values);  // parameter_specs() order

  bool start_state(const mjModel* m, mjData* d) override;
  void reset(const mjModel* m, const mjData* d) override;
  void control(const mjModel* m, mjData* d, const ContactState& contacts,
               JointDrive& drive) override;

  int phase() const override { return state_; }
  bool phase_changed() const override { return changed_; }
  const PhaseTimes& phase_times() const override { return times_; }
  bool gave_up() const override { return false; }
  const std::array<double, 3>& com() const override { return com_; }
  const std::array<double, 3>& com_velocity() const override { return com_vel_; }

  // The heading (rad, about world z) of the last control() step, and the swing femur's
  // feedback-adjusted (pitch, roll) targets.
  double heading() const { return heading_; }
  const std::array<double, 2>& swing_femur_target() const { return femur_target_; }
  // Strikes so far: swing-foot touch-downs that ended a strike state.
  int strikes() const { return strikes_; }

 private:
  // What a joint does, for one swing leg.
  enum class Kind { kStanceHip, kSwingHip, kSwingFoot, kTorso, kJoint, kHold };
  struct Slot {
    Kind kind = Kind::kJoint;
    int param = -1;  // index into a state's targets; -1 for kStanceHip and kHold
  };
  // A link tracked in the heading frame: its body, its hinges (Character::joints indices,
  // proximal first) and their world axes at the standing pose.
  struct Tracked {
    int body = -1;
    std::vector<int> joints;
    std::vector<std::array<double, 3>> axes;
    std::array<double, 4> standing{1, 0, 0, 0};  // world orientation at qpos0
  };

  void prepare(const mjModel* m);
  void measure(const mjModel* m, const mjData* d);
  void enter(int state, double time);
  // The world orientation target of a tracked link: heading, then the hinges' rotations
  // by `angles` (one per hinge), then the standing orientation.
  void link_target(const Tracked& link, const double* angles, double* quat) const;
  void root_target(int state, double* quat) const;
  // The target of each hinge of `link` for the current swing leg (into angles).
  void tracked_angles(const Tracked& link, int state, int swing, double* angles) const;

  const Character& body_;
  WalkControllerConfig config_;
  std::array<std::vector<Slot>, 2> slots_;  // per swing leg (0 left, 1 right), per joint
  std::array<Tracked, 2> femur_, foot_;     // per leg
  Tracked torso_;                           // body -1 when there is no waist
  std::vector<int> root_children_;          // joints whose body's parent is the root body
  std::vector<int> leg_of_;                 // per joint: 0, 1 or -1
  std::array<std::vector<int>, 2> middle_;  // per leg: joints between the hip and the foot
  std::array<double, 4> root_standing_{1, 0, 0, 0};
  double root_standing_heading_ = 0;
  std::vector<double> qpos0_;               // per joint: standing angle
  double mass_ = 0, gravity_ = 9.81, root_kp_ = 0, root_kd_ = 0;
  int pelvis_pitch_ = -1, pelvis_roll_ = -1;  // indices into a state's targets
  int per_state_ = 0;                          // targets per state

  // Parameters unpacked.
  std::array<std::vector<double>, 2> targets_;  // lift, strike
  double lift_duration_ = 0.3;
  double cd_sag_ = 0.5, cv_sag_ = 0.2, cd_cor_ = 0.5, cv_cor_ = 0.2;

  // State.
  bool prepared_ = false;
  int state_ = kLeftLift;
  bool changed_ = false;
  double state_begin_ = 0;
  int strikes_ = 0;
  PhaseTimes times_;
  double heading_ = 0;
  std::array<double, 2> femur_target_{};
  std::array<double, 3> com_{}, com_vel_{};
  std::vector<double> u_, kd_;
};

}  // namespace diverse
