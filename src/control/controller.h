// The controller seam: controllers are plug-ins chosen by name in the task file.
//
//   [controller]
//   type = "skill"                    # a registered ControllerType (the default with `skill`)
//   skill = "../skills/jump2d.toml"   # ...and that type's own keys
//
// Every skill is a file run by one type, the skill engine (control/skill_controller.h);
// the seam stays for a controller that cannot be written as one.
//
// A ControllerType parses its own keys, names and ranges its free parameters for a given
// character (params/parameters.h), and makes one Controller per rollout. The task,
// evaluation, run and render layers only see these interfaces: a new controller is a new
// ControllerType in its own files under control/ plus one line in
// control/builtin_controllers.cc, and touches nothing else.
//
// A Controller is a phase-based state machine (paper section 6, figure 4). Each step it
// reads the state, decides transitions, and asks the joint drive (physics/drive.h) for a
// torque per joint of the character (k = index into Character::joints); it never writes
// d->ctrl or the model. The phases it reports give the motion its events: a jump takes off
// (the first airborne phase begins), peaks (the second begins) and lands; the pose
// samples of the distance metrics are taken at phase-normalized times of the airborne
// phases (SPEC 2.3).
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "character/character.h"
#include "params/parameters.h"
#include "physics/drive.h"

namespace diverse {

class TomlReader;

// Contact between the character and the environment in the current state.
struct ContactState {
  bool any = false;                        // any body of the character touches anything
  std::array<bool, 2> foot{false, false};  // left, right foot (or a body below it) touches
  bool non_foot = false;                   // a body other than the feet touches something
};
ContactState scan_contacts(const mjModel* m, const mjData* d, const Character& body);

// Times at which phases began (s, simulation time); negative if never reached.
struct PhaseTimes {
  std::vector<std::string> names;  // phase names, in order
  std::vector<double> begin;       // one per phase
  // The airborne phases of a jump: [takeoff, peak) and [peak, landing). -1 if none.
  int rise = -1, fall = -1, land = -1;
  // The phase that pushes off the ground (a jump's extend); the phases before it stand.
  int extend = -1;
  double at(int phase) const { return phase >= 0 ? begin[static_cast<size_t>(phase)] : -1; }
  double takeoff() const { return at(rise); }
  double peak() const { return at(fall); }
  double landing() const { return at(land); }
};

class Controller {
 public:
  virtual ~Controller() = default;
  // Sets the rollout's initial state in d (qpos, qvel; the model's qpos0 at rest before),
  // for controllers that start from a pose of their own (a walk starts in its first
  // state's pose). Returns false, leaving d alone, when the task's start stands.
  virtual bool start_state(const mjModel* m, mjData* d) {
    (void)m;
    (void)d;
    return false;
  }
  // Starts the state machine from the state in d (after mj_step1).
  virtual void reset(const mjModel* m, const mjData* d) = 0;
  // One control step (after mj_step1): transitions, targets, torques into `drive`.
  virtual void control(const mjModel* m, mjData* d, const ContactState& contacts,
                       JointDrive& drive) = 0;

  virtual int phase() const = 0;
  virtual bool phase_changed() const = 0;  // in the last control()
  virtual const PhaseTimes& phase_times() const = 0;
  // The leg that swings in `phase` (0 left, 1 right), or -1: a walk's steps (task/walk_eval.h).
  virtual int swing_leg(int phase) const {
    (void)phase;
    return -1;
  }
  // The motion gave up before leaving the ground (a push that never took off).
  virtual bool gave_up() const = 0;
  // Whole-body COM (m) and its velocity (m/s) seen by the last control() step.
  virtual const std::array<double, 3>& com() const = 0;
  virtual const std::array<double, 3>& com_velocity() const = 0;
};

// A controller's constants that are not optimized, parsed from the task file.
class ControllerConfig {
 public:
  virtual ~ControllerConfig() = default;
  // The height (m) of the surface the character lands on, for controllers that predict
  // where the COM comes down; continuation over box heights (task/seed_motion.h) sets it.
  virtual std::shared_ptr<const ControllerConfig> with_landing_height(double height) const = 0;
  virtual double landing_height() const = 0;
  // The skill's name when the controller runs a skill file ("" otherwise), for messages.
  virtual std::string skill_name() const { return ""; }
};

class ControllerType {
 public:
  virtual ~ControllerType() = default;
  virtual const char* name() const = 0;         // the task file's [controller] type
  virtual const char* description() const = 0;  // one line, for messages and docs
  // The kind of skill `config` makes: "jump" (the default) or "walk"; a walk task
  // (task/walk_task.h) needs a walk controller and the other way round.
  virtual const char* skill(const ControllerConfig& config) const {
    (void)config;
    return "jump";
  }
  // Parses the [controller] table's own keys ("type" is read already; reject unknown
  // keys with r.only()). Throws UserError naming the file and field.
  virtual std::shared_ptr<const ControllerConfig> read_config(const TomlReader& r) const = 0;
  // Checks the character can be driven by this controller (roles, root kind); throws
  // UserError "FILE: controller.type: expected ..." naming what is missing.
  virtual void check(const Character& body, const std::string& task_file) const = 0;
  // The same with the task's configuration, for a controller whose fit to the character
  // depends on it (a skill file's groups, bodies and root); by default the check above.
  virtual void check(const Character& body, const ControllerConfig& config, const std::string& task_file) const {
    (void)config;
    check(body, task_file);
  }
  // The free parameters for this character, named and ranged.
  virtual std::vector<ParamSpec> parameter_specs(const Character& body,
                                                 const ControllerConfig& config) const = 0;
  // One controller for one rollout; `values` in parameter_specs() order.
  virtual std::unique_ptr<Controller> make(const Character& body, const ControllerConfig& config,
                                           const std::vector<double>& values) const = 0;
};

// The registry: the built-in controllers (control/builtin_controllers.cc). find_controller
// throws UserError "WHERE: expected one of ..., got NAME".
const ControllerType& find_controller(const std::string& name, const std::string& where);
std::vector<std::string> controller_names();

// The joint drive of a character: one driven joint per Character::joints entry, in order.
JointDrive make_drive(const Character& body, SaturatedDrive saturated = SaturatedDrive::kExplicit,
                      Damping damping = Damping::kMujoco);

}  // namespace diverse
