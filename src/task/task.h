// Task files: what a skill must achieve, with which character and controller.
//
// A task is a TOML file (tasks/<name>.toml) naming the character (its character file, or
// an MJCF with its character file beside it), the controller (a plug-in, control/controller.h)
// and its constants, scene objects, the constraints of paper section 7.1 (SPEC 5) with
// their parameters and penalties (SPEC 2.4), the paper's distance metric, the default
// number of variations N, where the input motion M0's parameters are, and how
// `diverse seed-motion` finds that M0. Paths in a task file are relative to the file.
//
// Parsing is strict: a missing field, an unknown key, a wrong type, an out-of-range
// value, a model or parameter path that does not exist, or malformed TOML is a UserError
// of one line, "FILE: FIELD: expected ...". docs/reference/task-file.md lists every
// field.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <memory>

#include "character/character.h"
#include "control/controller.h"
#include "task/term.h"
#include "task/walk_task.h"

namespace diverse {

// A box standing on the floor, spanning x in [x_min, x_max] and z in [0, height] (m);
// it is as deep as the floor in y. Kinds: "box" (something to land on) and "obstacle"
// (something to clear: its near-contacts within `clearance_range` are reported, so the
// clearance constraint sees how close the body came).
struct SceneObject {
  std::string name;
  std::string kind;      // "box" or "obstacle"
  double x_min = 0, x_max = 0, height = 0;  // m
};

struct TaskConstraints {
  double weight = 5000;           // K_c in C = K_c |d|^2 (SPEC 2.4), of every term that names none
  double fall_penalty = 100000;   // constant for a fall (doubles for the earliest falls)
  // Bodies of the character whose contact with the ground or an object is not a fall (a
  // handspring's or a cartwheel's hands): body names of its model, or "hands", the
  // character file's [hands] bodies. Any other body that is not a foot touching
  // something is still a fall.
  std::vector<std::string> allow_contact;
  std::string allow_contact_field;  // where the task file gives it, for messages
  // Every motion that meets the task is simulated again with the timestep halved and
  // meets it only if it still does there, its feet landing within kTimestepAgreement of
  // the same spot (task/constraints.h): a motion may not hinge on integration error.
  bool half_timestep = false;
  // The constraints the task lists (task/term.h), in the order their terms add to C.
  std::vector<std::shared_ptr<const Constraint>> terms;

  // The first listed constraint of type T (task/term_*.h), or nullptr.
  template <class T>
  const T* find() const {
    for (const auto& term : terms)
      if (const T* t = dynamic_cast<const T*>(term.get())) return t;
    return nullptr;
  }
  // Replaces the first listed constraint of type T by a copy changed by `how(T&)` (the
  // input-motion search's continuation over the landing distance); false if none.
  template <class T, class Change>
  bool change(Change&& how) {
    for (auto& term : terms) {
      if (const T* t = dynamic_cast<const T*>(term.get())) {
        auto changed = std::make_shared<T>(*t);
        how(*changed);
        term = std::move(changed);
        return true;
      }
    }
    return false;
  }
};

struct TaskSimulation {
  double settle_time = 1.0;       // s the character must stand after landing
  double settle_speed = 0.25;     // m/s: COM speed below which it is at rest
  double settle_max = 2.5;        // s after landing by which it must be at rest
  // At rest also needs the capture point over the feet's support (task/support.h), and
  // both, slow and balanced, for the last rest_hold seconds without a break: a landing
  // that is slow but toppling is not at rest; it goes on until it is, falls, or reaches
  // settle_max.
  bool balanced_rest = true;
  double rest_hold = 0.5;         // s
  double max_time = 6.0;          // s, hard cap of a rollout
  double fall_com_height = 0.3;   // m: COM closer than this to the feet's height = fall
  // rad: on the ground (not in flight), the root tilting farther than this from its
  // standing "up" is a fall; 0 = not checked (the planar tasks, whose falls show as
  // contacts).
  double fall_tilt = 0;
  double clearance_range = 0.3;   // m: distance up to which obstacle proximity is seen
  double timestep = 0;            // s; > 0 overrides the model's timestep
  // A jump whose character is off the ground for 20 ms or more before its extend phase
  // (a hop before the jump) falls.
  bool hop_is_fall = false;
  // m; > 0: from topple_after seconds after touch-down, with both feet on the ground,
  // the COM and its capture point (task/support.h) both more than this outside the soles
  // (sole_outline(), the feet's whole outline) is a fall ("toppled over the edge of the
  // feet"), ranked as a fall a second or more after touch-down: with no foot left to
  // step with, a body seldom brings back a COM that has left its soles that far and is
  // still moving away; without the rule it is simulated until it lies on the ground,
  // about a second later. The landing's first topple_after seconds are left out: a
  // landing's impact and the swing of the upper body that catches it can carry both
  // points out and back (jump_over's landings do even later, and the backflip's within
  // 0.4 s: docs/guide/running-at-scale.md, "Where a rollout ends"). 0: not checked (every committed
  // task; docs/notes/2026-12-04-where-a-runs-steps-go.md).
  double topple_distance = 0;
  double topple_after = 0.2;  // s
  // How the joint drive applies a request at the torque limit or with its spring part
  // beyond it (physics/drive.h): `saturated_drive = "explicit"` (the default; the damper
  // on the step's start velocity, which chatters at a jump's flight gains) or "stable_pd"
  // (the damper on the predicted end-of-step velocity).
  SaturatedDrive saturated_drive = SaturatedDrive::kExplicit;
  // How the dampers are integrated (physics/drive.h): `damping = "mujoco"` (the default:
  // MuJoCo's implicit joint damping on each joint's own inertia, a saturated joint as
  // saturated_drive says) or "constrained" (every joint's PD torque solved together, each
  // damper on the velocity it will have at the step's end with the step's contacts held;
  // a motion then converges as the step shrinks: docs/notes/2026-12-05-drive-that-converges.md).
  // saturated_drive has no say under "constrained".
  Damping damping = Damping::kMujoco;
  // The friction cone of every contact, MuJoCo's <option cone>: "" (the default: the
  // model's own), "elliptic" or "pyramidal". The planar human's model has the elliptic
  // one; under the pyramidal cone a change of friction that makes nothing slide still
  // changes a push-off (docs/notes/2026-12-06-friction-cones.md).
  std::string friction_cone;
};

struct TaskSeed {
  std::string base;               // resolved path of the hand-authored start parameters
  std::string object;             // continuation object ("" = none)
  std::vector<double> heights;    // continuation heights (m), last = the task's height
  // Continuation over where the character lands (m, the landing constraint's centre),
  // last = the task's; instead of an object's heights.
  std::vector<double> distances;
  int generations = 100;          // CMA-ES generations per continuation stage (max)
  double sigma = 0.08;            // initial CMA-ES step (normalized units)
  int popsize = 16;
  std::uint64_t seed = 1;
  double robustness = 0;          // weight of the margin tie-breaker (0 = penalty alone)
};

// How `diverse run` explores around M0 unless told otherwise.
struct TaskDiversity {
  // Initial CMA-ES step (normalized units). A task whose feasible region around M0 is
  // thin (the backflip) needs a smaller one, or no sample of the first generations
  // meets the task.
  double sigma0 = 0.1;
  // Generations of `diverse run` unless `--generations` says otherwise.
  long long generations = 500;
};

struct Task {
  std::string file;         // the task file as given
  std::string name;
  std::string description;
  std::string character;    // resolved character file (character/character.h)
  std::shared_ptr<const CharacterSpec> character_spec;  // that file, parsed
  std::string model;        // resolved MJCF path of the character (character_spec->model)
  std::string controller = "skill";                    // [controller] type
  const ControllerType* controller_type = nullptr;     // its plug-in
  std::shared_ptr<const ControllerConfig> controller_config;  // its own keys
  std::vector<SceneObject> objects;
  TaskConstraints constraints;
  TaskSimulation simulation;
  std::string metric;       // "hf", "md" or "wja"
  int variations = 4;       // N
  std::string m0;           // resolved path of M0's parameters (need not exist yet)
  TaskSeed seed;
  TaskDiversity diversity;
  TaskWalk walk;            // [walk]: a walk task (task/walk_task.h)
  // The character's strength model (paper section 7.2, `diverse run --strength`; not a
  // task-file field): every joint's torque limit (the motors' forcerange in the scene,
  // scene_xml) and PD gains (Character::strength, applied by the controllers) times this.
  double strength = 1.0;

  const SceneObject* find_object(const std::string& name) const;
};

// Parses and validates a task file. Throws UserError.
Task load_task(const std::string& path);

// A task argument: a path to a .toml file, or a name looked up as tasks/<name>.toml in
// the current directory and then in the source tree. Throws UserError if none exists.
std::string resolve_task_path(const std::string& name_or_path);

// The task's MJCF: the character model with the scene objects added to its worldbody,
// and, for a strength other than 1, every forcerange attribute (actuators and their
// defaults) scaled by it, so a saved model carries the scaled torque limits. Throws
// UserError if the character file cannot be read.
std::string scene_xml(const Task& task);

// The range of Task::strength (`--strength`): [kMinStrength, kMaxStrength].
constexpr double kMinStrength = 0.1;
constexpr double kMaxStrength = 10.0;

}  // namespace diverse
