// Evaluating a task: one controller parameter vector in, one simulated motion out.
//
// TaskEvaluator holds what every evaluation of a task shares, read-only: the compiled
// scene (character plus objects), the character map and the task. Each thread owns a
// SimWorker (private model copy + mjData, from make_worker()) and passes it in, so
// evaluate() is thread-safe and a pure function of the parameters: the same vector gives
// the same result bit for bit on any worker.
//
// The rollout stops as soon as the outcome is decided: a fall (any contact of a body
// other than the feet with the ground or an object, or the COM within fall_com_height of
// the feet), the character at rest settle_time after landing, or a time cap. A rollout
// that blows up is a failed evaluation with a large penalty, never an exception.
//
// Pose samples for the distance metrics (paper section 4, SPEC 2.3): the airborne
// states are recorded every step from take-off to landing, so poses can be sampled at any
// phase-normalized time of the two airborne phases (take-off to peak, peak to landing).
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

#include "character/planar_human.h"
#include "control/jump_controller.h"
#include "control/parameters.h"
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
  Eigen::Matrix3Xd link_com;  // world COM of each link (m), PlanarHuman::links order
  Eigen::VectorXd angles;     // the 16 joint angles (PlanarHuman::joints order), then root pitch (rad)
};

struct EvaluationOptions {
  int samples_per_phase = 10;        // poses per airborne phase at (k + 0.5) / n; 0 = none
  StepRecorder* recorder = nullptr;  // exact-replay record (off in the optimizer)
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
  // Airborne states, take-off to landing inclusive: time (s) and qpos (nq per entry).
  std::vector<double> flight_time, flight_qpos;
  std::vector<PoseSample> poses;  // 2 * samples_per_phase when the jump took off and landed
  bool has_flight() const { return phases.takeoff() >= 0 && phases.peak() >= 0 && phases.landing() >= 0; }
};

class TaskEvaluator {
 public:
  explicit TaskEvaluator(Task task);

  const Task& task() const { return task_; }
  const SharedModel& model() const { return *model_; }
  const std::shared_ptr<const SharedModel>& model_ptr() const { return model_; }
  const PlanarHuman& body() const { return *body_; }

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

  // Link masses (kg) and joint names in PoseSample order.
  Eigen::VectorXd link_masses() const;
  std::vector<std::string> link_names() const;
  std::vector<std::string> angle_names() const;  // 16 joints, then "root"

 private:
  Task task_;
  std::shared_ptr<const SharedModel> model_;
  std::unique_ptr<PlanarHuman> body_;
  int obstacle_geom_ = -1;
};

}  // namespace diverse
