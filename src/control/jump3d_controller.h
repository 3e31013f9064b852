// "jump3d": the phase-based jump controller for characters with a free root (the 3D human,
// the bird robot), the 3D counterpart of "jump2d" (control/jump_controller.h) with the same
// phases and events, registered in control/builtin_controllers.cc.
//
//   start   stance: balance, the COM held `crouch.lean` ahead of the soles' centre,
//           targets interpolated over start.duration
//   crouch  stance, the same, over crouch.duration
//   extend  stance, the targets applied at once with the phase's gains, the COM driven
//           toward `extend.lean` from the soles' centre and to the horizontal speed
//           `extend.speed` along the heading (the force not held to the support
//           polygon: the feet may tip): the legs push; ends when the
//           character is airborne (no contact for airborne_time, COM rising), or gives
//           up after extend_timeout
//   rise    flight, ends at peak height; duration predicted as v_z / g at take-off
//   fall    flight, ends at the first contact; duration predicted ballistically; the
//           landing controller places the feet (below)
//   land    stance: balance over the feet, targets interpolated over land.duration
//
// Stance phases run stance control (control/stance_controller.h): Jacobian-transpose
// virtual forces on the COM in both horizontal directions (and F_z = M g, without a height
// servo, so the joint targets decide how low the body goes), realized as joint torques of
// the stance legs, which also hold the root's world orientation; the torso and the feet
// track world orientations, everything else is PD. The free parameters of a stance phase
// are, per sagittal group, a world pitch about the heading's lateral axis (rad, positive
// backwards, 0 = standing) for the three tracked links:
//   ROOT (the root body's name: "pelvis", "torso")  the hip group's value,
//   "foot"   the value of the sagittal group on the foot bodies (ankle, or the bird's toe),
//   "chest"  the topmost sagittal waist group's value (the torso),
// and a joint angle for every other sagittal group (knee, the bird's ankle, shoulder,
// elbow). In flight every value is a joint angle. The sagittal groups of role neck and
// wrist are not parameters (they hold the standing pose), and neither are the coronal
// hinges: in stance the stance legs' J^T and the feet's world tracking keep the feet
// under the body, in flight they hold the standing pose, and in fall the landing
// controller sets the hips' roll.
//
// Gains. Each phase has kp, kd for the hips, the knees and the ankles (the sagittal groups
// of these roles): PD gains of those joints in flight and for the knees and ankles in
// stance (for a foot joint, the gains of the foot's world tracking); in stance the hips
// act through the root's orientation servo, whose gains are twice the hips' (two legs).
// Every other joint uses the character file's default gains.
//
// Landing controller (fall, while the root is within 60 degrees of upright). Each foot is
// placed at x_c + landing.offset f + landing.velocity_gain v + w_s l, with x_c where the
// COM is predicted to come down ballistically to its take-off height (plus the landing
// surface's height), v the COM's horizontal
// velocity, f and l the heading's forward and lateral axes and w_s the foot's standing
// lateral offset. The hip's pitch and roll angles that point the leg there come from the
// leg's geometry at the model's standing pose with the knee at its phase target, solved
// exactly for a universal hip with orthogonal axes.
//
// Asymmetry (`[controller] asymmetric = true`; SPEC 12: "the 3D jumps may break left-right
// symmetry"). By default left and right of every left/right pair share their parameters,
// as the paper's 3D jumps do, and every motion is mirror-symmetric up to the character and
// the simulation. With the option, every parameter of a pair is two, PARAM_left and
// PARAM_right with the shared parameter's range (e.g. "rise.knee_left", "crouch.foot_right"
// for the feet's world pitch in stance, "fall.kp_hip_left", "landing.offset_right"): the
// joint targets of each pair in every phase, the feet's world pitches in stance, the phase
// gains of the hips, knees and ankles, and the landing controller's offset and velocity
// gain of each foot. What the body has one of stays one: the root's and the torso's world
// pitches in stance (their gains, twice the hips', become the sum of the two hips'), the
// waist, the durations, the leans, the push-off speed and the landing balance offset. Each
// side given the shared parameter's value gives the symmetric controller's rollout bit for
// bit (a stance phase's feet start from their mean measured pitch either way).
//
// Feedback options (`[controller]` keys, all off by default;
// docs/notes/2026-12-05-robot-landing-feedback.md):
//   yaw_kp, yaw_kd (Nm/rad, Nm s/rad; 0 to 5000, 0 to 1000)  every stance phase holds the
//           root's yaw with two stance legs: equal and opposite pushes of the legs across
//           the line between their feet, a moment about the vertical and no net force,
//           as joint torques tau = J^T F (control/stance_controller.h, "Yaw"). A universal
//           hip has no yaw hinge; without it an uneven push-off leaves the body spinning.
//   neck_attitude_kp, neck_attitude_kd (rad/rad, s; 0 to 10, 0 to 2)  in flight the
//           sagittal neck turns back from its standing angle by kp times the root's
//           backward pitch beyond the land phase's root target plus kd times its backward
//           pitch rate (clamped to the joint's range): the head as a reaction mass, which
//           turns the body toward the pitch it lands with.
//   land_swing_placement (true/false)  in land, a leg whose foot is off the ground is
//           pointed again (the landing controller's hip geometry) instead of holding its
//           hip angles of the touch-down, which the body's turn toward its landing pitch
//           would swing back and up: beside the foot still on the ground, moved along the
//           heading toward the COM's capture point x + v sqrt(z / g) by at most 0.2 m; with
//           both feet off, under the capture point.
//   joint_space_extend (true/false)  the extend is joint-space PD, as the flight phases
//           are, instead of stance control: every joint toward a target with the extend's
//           gains (the foot's joints with the ankles'; groups without a parameter toward
//           the standing pose), the hip, foot and chest values of the extend read as joint
//           angles relative to the standing pose (qpos0) and every other value as a joint
//           angle. Stance control's torques switch with the contacts (a leg is a stance
//           leg, pushing by J^T, only while its foot touches the ground, and the feet track
//           world pitches), so a push-off on the feet's front corners branched on which
//           corner touched at which step; PD torques depend on the joints' state alone
//           (docs/notes/2026-12-07-joint-space-push-off.md).
//   extend_root_kd (Nm s/rad; 0 to 5000; with joint_space_extend)  in that extend the hips
//           also damp the root's rotation: each hip hinge adds kd / 2 times the root's
//           angular velocity about the hinge's axis, so the root feels -kd w about the
//           hips' pitch and roll axes, as SIMBICON's stance hip holds the torso. It acts on
//           the body's state alone, whichever feet touch, and takes out most of the spread
//           of the angular momentum a perturbed push-off leaves the flight with
//           (docs/notes/2026-12-07-joint-space-push-off.md).
//
// No external force is ever applied: the root is unactuated and every torque goes through
// the joint drive (physics/drive.h), which keeps it within the joint's limit on the net
// torque.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "character/character.h"
#include "control/controller.h"
#include "control/jump_controller.h"
#include "control/module_aim_legs.h"
#include "control/parameters.h"
#include "control/stance_controller.h"
#include "physics/com_velocity.h"

namespace diverse {

// Constants that are not optimized (documented defaults; the task file may override).
struct Jump3dControllerConfig : ControllerConfig {
  bool landing_control = true;   // place the feet during fall
  double landing_height_m = 0;   // m, height of the surface the COM prediction uses
  double extend_timeout = 0.8;   // s; an extend that never leaves the ground ends here
  double airborne_time = 0.01;   // s without contact (COM rising) that counts as take-off
  double com_kp = 40, com_kd = 12;  // 1/s^2, 1/s: the stance phases' horizontal COM servo
  bool asymmetric = false;       // left and right of every pair have their own parameters
  // Nm/rad, Nm s/rad: the stance phases hold the root's yaw with two stance legs (0, 0: not
  // held; StanceGains::yaw_kp, yaw_kd)
  double yaw_kp = 0, yaw_kd = 0;
  // rad/rad, s: in flight the sagittal neck turns back by kp times the root's backward
  // pitch beyond the land phase's target plus kd times its backward pitch rate (0, 0: the
  // neck holds its standing pose)
  double neck_attitude_kp = 0, neck_attitude_kd = 0;
  // in land, a leg whose foot is off the ground points at the COM's capture point
  bool land_swing_placement = false;
  // the extend drives every joint by PD toward joint-space targets (no stance control)
  bool joint_space_extend = false;
  // Nm s/rad: with joint_space_extend, the hips damp the root's rotation in the extend
  // (0: not damped)
  double extend_root_kd = 0;

  std::shared_ptr<const ControllerConfig> with_landing_height(double height) const override;
  double landing_height() const override { return landing_height_m; }
};

class Jump3dControllerType : public ControllerType {
 public:
  const char* name() const override { return "jump3d"; }
  const char* description() const override {
    return "phase-based jump of a character with a free root (start, crouch, extend, rise, fall, land)";
  }
  std::shared_ptr<const ControllerConfig> read_config(const TomlReader& r) const override;
  void check(const Character& body, const std::string& task_file) const override;
  std::vector<ParamSpec> parameter_specs(const Character& body,
                                         const ControllerConfig& config) const override;
  std::unique_ptr<Controller> make(const Character& body, const ControllerConfig& config,
                                   const std::vector<double>& values) const override;
};

class Jump3dController : public Controller {
 public:
  Jump3dController(const Character& body, const Jump3dControllerConfig& config);

  // The free parameters for `body`: per phase a value per parameterized group and kp, kd
  // of hips, knees and ankles; then the durations, the leans of crouch and extend, the
  // push-off speed, the landing balance offset and the landing controller's offset and
  // velocity gain (81 for the 3D human, 69 for the bird robot). `asymmetric`: every
  // parameter of a left/right pair split in two, _left and _right (145 and 127).
  static std::vector<ParamSpec> parameter_specs(const Character& body, bool asymmetric = false);
  void set_parameters(const std::vector<double>& values);

  void reset(const mjModel* m, const mjData* d) override;
  void control(const mjModel* m, mjData* d, const ContactState& contacts,
               JointDrive& drive) override;

  int phase() const override { return phase_; }
  bool phase_changed() const override { return phase_changed_; }
  const PhaseTimes& phase_times() const override { return times_; }
  bool gave_up() const override { return extend_timed_out_; }
  const std::array<double, 3>& com() const override { return com_; }
  const std::array<double, 3>& com_velocity() const override { return com_vel_; }

 private:
  // What a stance phase interpolates: the three world pitches, then one joint target per
  // Character::joints entry.
  struct StanceTargets {
    double root = 0, torso = 0;
    std::array<double, 2> foot{0, 0};  // left, right
    std::vector<double> joints;
  };
  // A leg at the model's qpos0, in the root's frame: the hip, then the joints between the
  // hip and the foot (the knee; the bird's ankle), top down, and the foot's joint.
  struct LegGeometry {
    int hip_pitch = -1, hip_roll = -1;            // Character::joints indices (-1: none)
    double pitch0 = 0, roll0 = 0;                 // their qpos0 values (rad)
    std::array<double, 3> pitch_axis{}, roll_axis{};
    std::vector<int> middle;                      // joints between hip and foot, top down
    std::vector<double> middle0;                  // their qpos0 values
    std::vector<std::array<double, 3>> axes;      // their axes
    std::vector<std::array<double, 3>> segments;  // hip -> first, ..., last -> foot joint
    double lateral = 0;  // m, the foot's standing offset along the root's y from the feet's middle
  };

  void enter(int phase, const mjModel* m, const mjData* d);
  void measure_pitches(const mjData* d, StanceTargets& out) const;
  void landing_hips(const mjData* d, std::vector<double>& targets) const;
  // Sets the hip targets of the legs in `which` so that each points at its goal (world x, y
  // on the ground), with the joints between hip and foot at their targets.
  void point_legs(const mjData* d, const std::array<std::array<double, 2>, 2>& goals,
                  const std::array<bool, 2>& which, std::vector<double>& targets) const;
  // land_swing_placement: points every leg whose foot is off the ground (target_'s hips).
  void place_lifted_legs(const mjData* d, const ContactState& contacts);
  // neck_attitude_kp, kd: the sagittal neck's flight target from the root's pitch (target_).
  void turn_head_toward_landing(const mjData* d);
  // PD toward target_ with the phase's gains (the character's for groups without any);
  // `foot_with_ankle_gains`: the foot group's joints take the ankles' (joint_space_extend).
  void drive_toward_targets(const mjData* d, JointDrive& drive, bool foot_with_ankle_gains) const;
  // extend_root_kd: adds to each hip hinge's request (after drive_toward_targets) the
  // damping of the root's rotation about the hinge's axis.
  void damp_root_with_hips(const mjData* d, JointDrive& drive) const;

  const Character& body_;
  Jump3dControllerConfig config_;
  int hip_ = -1, knee_ = -1, ankle_ = -1, foot_group_ = -1, chest_ = -1;  // group indices
  int neck_ = -1;  // the sagittal neck group, or -1
  std::vector<int> posed_;       // parameterized groups, in parameter order
  std::vector<int> pose_slot_;   // per group: index into posed_, or -1
  std::vector<int> gain_slot_;   // per group: 0 hip, 1 knee, 2 ankle, -1 default gains
  std::vector<int> side_;        // per joint: 0 left (or centre), 1 right
  size_t param_count_ = 0;       // parameter_specs(body, config.asymmetric).size()
  std::array<std::vector<char>, kNumJumpPhases> split_{};  // per phase, per posed_: _left and _right

  // Parameters unpacked, per side (left, right; the same twice where they are shared).
  using Sides = std::array<double, 2>;
  std::array<std::vector<Sides>, kNumJumpPhases> pose_{};  // per posed_ entry
  std::array<std::array<Sides, 3>, kNumJumpPhases> kp_{}, kd_{};
  double start_duration_ = 0.2, crouch_duration_ = 0.4, land_duration_ = 0.3;
  double lean_ = 0, extend_lean_ = 0, extend_speed_ = 0, land_offset_ = 0;
  Sides landing_offset_{0, 0}, landing_velocity_gain_{0, 0};

  // Set at reset() from the model.
  std::unique_ptr<StanceController> stance_;
  std::array<LegGeometry, 2> legs_{};
  std::array<double, 4> root0_inv_{1, 0, 0, 0};  // inverse of the root's qpos0 orientation
  std::vector<double> qpos0_;                     // per joint: its qpos0 value
  double gravity_ = 9.81;

  int phase_ = kStart;
  bool phase_changed_ = false;
  bool extend_timed_out_ = false;
  double phase_begin_ = 0, phase_duration_ = 1;
  double takeoff_com_z_ = 0;
  double free_since_ = -1;
  double heading_ = 0;  // rad, the jump's heading (the root's yaw at reset)
  PhaseTimes times_;
  StanceTargets from_, goal_;     // stance phases: interpolation ends
  std::vector<double> target_;    // per joint: last commanded joint target (flight)
  std::vector<double> flight_from_;
  std::array<double, 3> com_{}, com_vel_{};
  SubtreeComVelocity com_velocity_;  // of the character's subtree, set by reset()
};

}  // namespace diverse
