// Evaluating a task: one controller parameter vector in, one simulated motion out.
//
// TaskEvaluator holds what every evaluation of a task shares, read-only: the compiled
// scene (character plus objects), the character bound to it (character/character.h), the
// task and its controller plug-in (control/controller.h). Each thread owns a
// SimWorker (private model copy + mjData, from make_worker()) and passes it in, so
// evaluate() is thread-safe and a pure function of the parameters: the same vector gives
// the same result bit for bit on any worker.
//
// The rollout stops as soon as the outcome is decided: a fall (any contact of a body
// other than the feet, and those constraints.allow_contact lists, with the ground or an
// object, or the COM within fall_com_height of the feet), the character at rest
// settle_time after landing, or a time cap. A rollout that blows up is a failed
// evaluation with a large penalty, never an exception. A jump's rollout is watched by
// JumpObserver (task/jump_eval.h), a walk's by its twin WalkObserver (task/walk_eval.h);
// both give the listed constraints what they measure through task/rollout_terms.h.
//
// Pose samples for the distance metrics (paper section 4, SPEC 2.3): the airborne
// states are recorded every step from take-off to landing, so poses can be sampled at any
// phase-normalized time of the two airborne phases (take-off to peak, peak to landing).
#pragma once

#include <Eigen/Dense>
#include <array>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "character/character.h"
#include "character/shape.h"
#include "control/controller.h"
#include "params/parameters.h"
#include "physics/model.h"
#include "physics/rollout.h"
#include "task/constraints.h"
#include "task/task.h"

namespace diverse {

// One pose of the character.
struct PoseSample {
  int phase = 0;            // 0: take-off to peak, 1: peak to landing
  double phase_time = 0;    // phase-normalized time in [0, 1]
  double time = 0;          // s
  Eigen::Matrix3Xd link_com;  // world COM of each link (m), Character::links order
  Eigen::VectorXd angles;     // the joint angles (Character::joints order, rad)
  Eigen::Quaterniond root = Eigen::Quaterniond::Identity();  // root orientation in the world
};

struct EvaluationOptions {
  int samples_per_phase = 10;        // poses per airborne phase (a walk: per state) at (k + 0.5) / n; 0 = none
  StepRecorder* recorder = nullptr;  // exact-replay record (off in the optimizer)
  // The rollout runs at the model's timestep times this (the worker's model copy is
  // changed for the rollout only; SimWorker::reset restores it).
  double timestep_scale = 1.0;
  // When the task asks for the half-timestep check ([constraints] half_timestep) and the
  // motion meets the task, simulate it again on the same worker with the timestep halved
  // and add the term "half_timestep" (task/constraints.h) to its report and C. Off by
  // default: `diverse simulate` and the motion files of a run ask for it; the optimizer
  // asks for it only where it decides something (eval/motion_problem.h, confirm()); the
  // input-motion search checks both timesteps itself.
  bool half_timestep_check = false;
  // End the rollout as soon as its outcome is decided (see Evaluation::steps_after_decided;
  // MotionSummary::ended_decided): a jump once it has landed where it can no longer meet
  // the task, counted as a fall at the end of the motion (most such landings do fall
  // later); a walk at the step that first breaks the rules, its steps' excesses
  // extrapolated to all its evaluated steps. A motion that meets the task is never ended,
  // so it is simulated exactly as without the option. The optimizer's walk rollouts use
  // it; its jumps do not (whether an ended landing would stand decides its C, and
  // every constant in its place lowered D: docs/notes/2026-12-04-where-a-runs-steps-go.md).
  // Motion files, the robustness suite and the input-motion search simulate every
  // rollout to its end.
  bool end_when_decided = false;
  // Perturbations of the robustness suite (robust/robustness.h): disturbances from the
  // world, never applied by a controller, never set by the optimizer or a run, and set by
  // the input-motion search only to rank its candidates (task/seed_motion.h, "Pushes").
  // A perturbed rollout cannot be recorded (its record would not replay on the saved
  // model): asking for both is a std::logic_error.
  //
  // Every geom's friction coefficients (sliding, torsional, rolling) times this, on the
  // worker's model copy for the rollout only (SimWorker::reset restores them). MuJoCo
  // gives a contact the larger of its two geoms' coefficients, so every contact of the
  // character with the floor or a scene object has its friction times this.
  double friction_scale = 1.0;
  // A push: once, at the first step whose time is at least `time` (s), the root's
  // linear velocity changes by `dv` (m/s, world frame; a planar root takes x and z,
  // its plane, and ignores y), then the velocity-dependent quantities of that step are
  // recomputed (mj_fwdVelocity) before the controller sees the state. time < 0: none.
  struct Push {
    double time = -1;                           // s
    std::array<double, 3> dv{0.0, 0.0, 0.0};   // m/s, world frame
  };
  Push push;
};

struct Evaluation {
  double constraint = 0;     // C >= 0
  bool failed = false;       // simulation blew up, or invalid parameters
  bool fell = false;
  std::string failure;       // why it failed
  ConstraintReport report;
  MotionSummary summary;
  PhaseTimes phases;         // phase start times (s)
  RolloutStats stats;
  // The steps simulated after the outcome was decided: after the moment from which the
  // motion could no longer meet the task (a landing outside the box at touch-down, an
  // obstacle touched, a walk step out of its range; task/constraints.h,
  // touchdown_bound()), up to the end of the rollout; decided_step is that moment in
  // steps observed (-1: never, and so 0 steps after it). A motion that meets the task is
  // never decided before its end.
  int decided_step = -1;
  int steps_after_decided = 0;
  // The half-timestep check's rollout, when one ran (half_timestep_check): its steps.
  int check_steps = 0;
  // Airborne states, take-off to landing inclusive: time (s) and qpos (nq per entry).
  std::vector<double> flight_time, flight_qpos;
  std::vector<PoseSample> poses;  // 2 * samples_per_phase when the jump took off and landed
  double push_time = -1;     // s, when EvaluationOptions::push was applied; -1 if never
  bool has_flight() const { return phases.takeoff() >= 0 && phases.peak() >= 0 && phases.landing() >= 0; }
};

// The task's scene with the character at one body shape (character/shape.h). Immutable:
// threads share it, each with its own SimWorker on `model`.
struct ShapedScene {
  Eigen::VectorXd scales;                    // the shape scales, ShapeSpace order
  Eigen::VectorXd link_lengths;              // m, one per link, ShapeSpace::link_names() order
  StandingShape standing;                    // start height and ground clearance
  std::shared_ptr<const SharedModel> model;  // the shaped scene; model->xml() is its exact text
  std::shared_ptr<const Character> body;     // the character bound to `model`
  // A hand or arm starts below the lowest point of the feet: the body cannot stand.
  bool below_floor() const { return standing.lowest_other_z < standing.feet_z; }
};

// The root's orientation in the world for a state: a planar root's pitch about -y, or a
// free root's quaternion.
Eigen::Quaterniond root_orientation(const Character& body, const double* qpos);

// True when a parameter set holds shape scales ("shape.*" names, ShapeSpace::specs()).
bool holds_shape(const ParameterSet& params);

class TaskEvaluator {
 public:
  // Compiles the task's scene at the task's strength (Task::strength: torque limits in
  // the model, PD gains through Character::strength).
  explicit TaskEvaluator(Task task);

  const Task& task() const { return task_; }
  const SharedModel& model() const { return *model_; }
  const std::shared_ptr<const SharedModel>& model_ptr() const { return model_; }
  const Character& body() const { return *body_; }

  // The controller's parameters (names, ranges) with all values at their lower bound.
  ParameterSet parameters() const;
  // Reads named parameters from a JSON file: either {"parameters": {...}} or {...}.
  ParameterSet load_parameters(const std::string& path) const;
  int dim() const { return parameters().size(); }

  std::unique_ptr<SimWorker> make_worker() const;

  Evaluation evaluate(const std::vector<double>& values, SimWorker& worker,
                      const EvaluationOptions& options = {}) const;
  // x normalized as ParameterSet::normalized(); any coordinate outside [0, 1] or not
  // finite gives a failed evaluation (the optimizer keeps its samples inside the box).
  Evaluation evaluate_normalized(const Eigen::VectorXd& x, SimWorker& worker,
                                 const EvaluationOptions& options = {}) const;

  // Poses at phase-normalized times `taus` of airborne phase `phase` (0 or 1) of an
  // evaluation with a flight. Uses the worker's mjData as scratch.
  std::vector<PoseSample> sample_poses(const Evaluation& e, int phase,
                                       const std::vector<double>& taus, SimWorker& worker) const;

  // Body shape (character/shape.h, docs/guide/shapes.md). Masses, joint ranges and torque
  // limits never change with the shape; link lengths, inertias and the start height do.
  //
  // True when the character can vary its shape: its character file has [shape]
  // parameters and its root is planar (require_shape passes).
  bool has_shape() const;
  // The shape space of the task's scene, parsed on first use (thread-safe). Throws
  // UserError if the character cannot vary its shape (require_shape: no [shape]
  // parameters in its character file, or not planar) or its model is outside the shape
  // rules.
  const ShapeSpace& shapes() const;
  // `control` (the controller's parameters) followed by the shape scales.
  ParameterSet with_shape(const ParameterSet& control, const Eigen::VectorXd& scales) const;
  // The controller's values (parameters() order) of a set that may also hold shape scales.
  std::vector<double> control_values(const ParameterSet& params) const;
  // Like load_parameters(), but the file may also hold shape scales "shape.NAME": then the
  // result is with_shape() of them, a scale the file leaves out being 1 (as written). A
  // scale out of its range is a UserError "PATH: shape.NAME: expected a scale in [LOWER,
  // UPPER], got V"; an unknown "shape.*" name or a non-number one names it likewise.
  ParameterSet load_shaped_parameters(const std::string& path) const;
  // The scene of one shape, validated (UserError "ORIGIN: shape.NAME: expected a scale in
  // ...") and compiled. Thread-safe; about 2 ms (the MuJoCo compile).
  std::shared_ptr<const ShapedScene> shaped_scene(const Eigen::VectorXd& scales,
                                                  const std::string& origin = "shape") const;
  // evaluate() on a body of another shape; `worker` must run scene.model. A shape whose
  // hand or arm starts below the floor (scene.below_floor()) cannot stand: it is simulated
  // as usual (its first step sees the contact) and always counts as a fall at the very
  // start, with that reason, so its constraint value is the largest fall penalty.
  Evaluation evaluate(const std::vector<double>& values, const ShapedScene& scene,
                      SimWorker& worker, const EvaluationOptions& options = {}) const;
  // Evaluates a named set, the controller's parameters and possibly shape scales (on that
  // shape's scene), on a worker of its own: thread-safe. `model_out` receives the model
  // it ran on (the task's, or the shaped scene's).
  Evaluation evaluate_named(const ParameterSet& params, const EvaluationOptions& options = {},
                            std::shared_ptr<const SharedModel>* model_out = nullptr) const;

  // Link masses (kg) and joint names in PoseSample order.
  Eigen::VectorXd link_masses() const;
  std::vector<std::string> link_names() const;
  std::vector<std::string> angle_names() const;  // the joints (Character::joints order)

 private:
  Task task_;
  std::shared_ptr<const SharedModel> model_;
  std::unique_ptr<Character> body_;
  std::vector<ParamSpec> specs_;  // the controller's parameters for body_, named once

  // With a strength other than 1: every driven joint's limit is the strength times its
  // limit at strength 1; throws UserError naming an actuator whose limit did not scale.
  void check_strength() const;

  // The rollout of a jump task, from the controller's start state.
  Evaluation evaluate_jump(Controller& controller, JointDrive& drive, const Character& body,
                           SimWorker& worker, const EvaluationOptions& options) const;
  // The rollout of a walk task (task/walk_eval.h), from the controller's start state.
  Evaluation evaluate_walk(Controller& controller, JointDrive& drive, const Character& body,
                           SimWorker& worker, const EvaluationOptions& options) const;
  // The rollout of evaluate(), on `body` (the task's, or a shaped scene's).
  Evaluation evaluate_on(const std::vector<double>& values, const Character& body,
                         SimWorker& worker, const EvaluationOptions& options) const;
  struct Shapes {
    std::once_flag once;
    std::unique_ptr<ShapeSpace> space;
  };
  std::unique_ptr<Shapes> shapes_ = std::make_unique<Shapes>();
};

}  // namespace diverse
