// A task's motions as a diversity problem (paper section 3 on top of sections 4 and 6).
//
// A variation is the controller's normalized parameter vector; evaluating it runs one
// rollout of the task (task/evaluate.h) and keeps what the distance metrics need: the
// pose samples at phase-normalized times of the two airborne phases (10 each), turned
// into metric poses with the whole-body centre of mass subtracted (metric/metric.h), and
// the body's link lengths. The objective's distance is the task's metric (or the one the
// user chose, possibly combined with the shape distance); the other metrics can be
// computed on the same outcomes for reporting.
//
// Shape as a free parameter (paper section 8). With vary_shape a variation is the
// controller's normalized parameters followed by the normalized shape scales of the
// character file's [shape] parameters (character/shape.h; the planar human has 10;
// every scale's range maps to [0, 1], so M0's body, scale 1, sits at
// (1 - lower) / (upper - lower)). The paper optimized 36 control parameters beside the
// 10 shape parameters; we keep all of the controller's (jump controller: 90), as for
// motion-only runs. Each sample builds its own body: the task's scene at that shape is
// compiled (about 2 ms, 5-10 % of a rollout), and the controller reads its segment
// lengths from that body. A worker keeps the last shape it built and reuses it when the
// next sample has the very same scales (M0, re-evaluated means): the scene is a pure
// function of the scales, so results do not depend on what a worker ran before.
//
// Bounds (SPEC section 10; paper section 7.2 names them as future work). Beyond the
// task's constraints a variation can be held
//   - within R times M0's control effort (`diverse run --effort-bound R`): effort is the
//     time integral of the sum of squared net joint torques over the whole rollout
//     (physics/rollout.h, RolloutStats::effort), so a variation may not strain the
//     character more than R times as much as the input motion does;
//   - within X of M0 in the problem's own distance (`diverse run --max-distance X`), for
//     subtle variations.
// A bound is a constraint like the task's: its excess adds K_c e^2 to C (K_c the task's
// constraint weight, e the relative excess, effort / (R effort(M0)) - 1 or d(M, M0) / X - 1),
// so a variation past it ranks below every one within it, and C = 0 only within every
// bound. M0 itself is within both (ratio 1, distance 0; R >= 1). The problem evaluates M0
// once when it is made (every process does, under mpirun: the same outcome bit for bit).
//
// Thread safety: one SimWorker per worker index, created up front; evaluate() with a
// given worker index is never called concurrently (DiversityProblem's contract).
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "metric/metric.h"
#include "optimize/objective.h"
#include "task/evaluate.h"

namespace diverse {

// Bounds on every variation besides the task's constraints (see above); 0 = no bound.
struct MotionBounds {
  double effort = 0;    // R >= 1: effort(M) <= R effort(M0)
  double distance = 0;  // X > 0: d(M, M0) <= X in the problem's distance
  // `diverse run --robust`: a sample meets the task only if it also holds under the
  // robustness suite's small part (robust/robustness.h, robust_sample_suite()), judged
  // where a variation would move to it (confirm()); one that does not gets
  // robust_failure_penalty(), and one that fails the half-timestep check twice that on
  // top of its own term, so that it ranks below every sample that only misses the suite.
  bool robust = false;
  bool any() const { return effort > 0 || distance > 0 || robust; }
};

// The term of a sample that meets the task but not the suite's part: K_c (0.1)^2 / 2, as
// a landing 7 cm out would cost.
double robust_failure_penalty(const Task& task);
// Ranges of the bounds (`--effort-bound`, `--max-distance`).
constexpr double kMinEffortBound = 1.0, kMaxEffortBound = 1e6;
constexpr double kMaxDistanceBound = 1e12;
// {"effort": R, "distance": X}, the bounds that are set only.
nlohmann::json to_json(const MotionBounds& bounds);
// Reads to_json()'s object (null = no bounds). Throws UserError "WHERE: FIELD: expected
// ..." for a field that is not a number in its range or an unknown field.
MotionBounds motion_bounds_from_json(const nlohmann::json& j, const std::string& where);

// A run's simulation steps as MotionProblem::tally() keeps them (summary.json "steps"):
//   {"total": S,
//    "rollouts": {"met": {"rollouts": n, "steps": s}, "failed": {...}, "fell": {...}},
//    "half_timestep": {"held": {"rollouts": n, "steps": s}, "failed": {...}},
//    "after_decided": s}
// "rollouts" are the evaluations at the task's timestep by outcome (met the task as far as
// that rollout tells, missed it, fell or blew up); "half_timestep" the checks at half the
// step by result; "after_decided" the steps of those rollouts simulated after their
// outcome was decided (Evaluation::steps_after_decided). Missing entries count 0.
// The total, and one figure of it: steps_of(ledger, "rollouts", "met").
long long steps_of(const nlohmann::json& ledger, const char* kind = nullptr, const char* outcome = nullptr);

// The outcome of one rollout.
struct MotionOutcome : Outcome {
  MotionFeatures features;   // pose samples for the metrics (empty without a flight) and
                             // the body's link lengths (none for a character without
                             // shape parameters)
  Eigen::VectorXd scales;    // the body's shape scales (all 1 unless shape varies; none
                             // for a character without shape parameters)
  bool fell = false;
  double landing_x = 0;      // m, mean foot x at rest (or at the end)
  double peak_com_z = 0;     // m
  double task_constraint = 0;  // C of the task's own constraints (constraint adds the bounds')
  double effort = 0;           // N^2 m^2 s, RolloutStats::effort
  double positive_work = 0;    // J, RolloutStats::positive_work
  double effort_ratio = 0;     // effort / effort(M0), with an effort bound (else 0)
  double distance_to_m0 = 0;   // d(M, M0) in the problem's distance, with a distance bound
  // Where the feet were at touch-down and at rest, for the half-timestep check's landing
  // comparison (task/constraints.h, half_timestep_term) made when it is confirmed.
  struct Landing {
    bool landed = false, fell = false, unstable = false;
    double touchdown_x = 0, touchdown_y = 0, rest_x = 0, rest_y = 0;  // m
  } landing;
  // What it cost (MotionProblem::tally): simulation steps of its rollout, of them those
  // after its outcome was decided (Evaluation::steps_after_decided), and of the
  // half-timestep check once confirmed (-1: no check ran), and of the robustness check of
  // a `--robust` run (-1: none ran; robust_held its verdict).
  long long steps = 0, steps_after_decided = 0, check_steps = -1, robust_steps = -1;
  bool robust_held = false;
};

class MotionProblem : public DiversityProblem {
 public:
  // `evaluator` must outlive the problem. `reference` is M0's normalized parameters
  // (parameters().normalized() of M0: with vary_shape, followed by its shape's). A
  // distance that uses the shape needs vary_shape (std::logic_error otherwise).
  MotionProblem(const TaskEvaluator& evaluator, DistanceSpec distance, Eigen::VectorXd reference,
                int workers, bool vary_shape = false, MotionBounds bounds = {});
  // A motion-only problem under one motion metric.
  MotionProblem(const TaskEvaluator& evaluator, Metric metric, Eigen::VectorXd reference,
                int workers);

  int dim() const override;
  Eigen::VectorXd reference() const override { return reference_; }
  // One rollout. When the task asks for the half-timestep check and the motion meets the
  // task, the outcome is provisional: confirm() runs the check.
  std::shared_ptr<const Outcome> evaluate(const Eigen::VectorXd& x, int worker) const override;
  // The half-timestep check of a provisional outcome of x (task/evaluate.h): the same
  // motion at half the step; the outcome's C gains the term "half_timestep", exactly as
  // TaskEvaluator::evaluate with half_timestep_check gives it.
  std::shared_ptr<const Outcome> confirm(const Eigen::VectorXd& x, const Outcome& outcome,
                                         int worker) const override;
  // evaluate() and, when that is provisional, confirm(): the final outcome at once.
  std::shared_ptr<const Outcome> evaluate_confirmed(const Eigen::VectorXd& x, int worker) const;
  // Simulation steps, by kind and by outcome (see steps_of()).
  void tally(const Outcome& outcome, nlohmann::json& ledger) const override;
  double distance(const Outcome& a, const Outcome& b) const override;

  // Distance between two outcomes under any metric, shape included (for the summary's
  // matrices), or under any spec.
  double distance(const Outcome& a, const Outcome& b, Metric metric) const;
  double distance(const Outcome& a, const Outcome& b, const DistanceSpec& spec) const;

  // The names and ranges of a variation's parameters: the controller's and, with
  // vary_shape, the shape scales after them (a template: values at the lower bounds).
  const ParameterSet& parameters() const { return parameters_; }
  // A normalized vector as named values.
  ParameterSet named(const Eigen::VectorXd& x) const;
  // Simulates x again on a worker of its own (thread-safe) with the options' recorder;
  // `model_out` receives the model it ran on (the shaped scene's with vary_shape). The
  // suite's push and friction scale (EvaluationOptions) are refused: std::logic_error.
  Evaluation simulate(const Eigen::VectorXd& x, const EvaluationOptions& options,
                      std::shared_ptr<const SharedModel>* model_out = nullptr) const;

  // A MotionOutcome as bytes and back, bit for bit (doubles travel as their bytes), for
  // outcomes computed in another process of the same build (distribute/cluster.h).
  // decode() throws std::invalid_argument on bytes that encode() did not write.
  static std::string encode(const Outcome& outcome);
  static std::shared_ptr<const Outcome> decode(const std::string& bytes);

  const MotionBounds& bounds() const { return bounds_; }
  // M0's outcome (the reference's), kept when a bound is set (else null).
  const MotionOutcome* reference_outcome() const { return reference_outcome_.get(); }

  Metric metric() const { return distance_.metric; }
  const DistanceSpec& distance_spec() const { return distance_; }
  bool vary_shape() const { return vary_shape_; }
  const MetricLayout& layout() const { return layout_; }
  const TaskEvaluator& evaluator() const { return *evaluator_; }
  int workers() const { return static_cast<int>(workers_.size()); }

  // Metric layout of the planar human: hands and feet by link name, WJA weights from
  // lee2002_joint_weight() on the joint names (root included), shape weights 1.
  static MetricLayout layout_for(const TaskEvaluator& evaluator);

 private:
  // A worker's last shape and the simulation state on it.
  struct ShapedWorker {
    std::shared_ptr<const ShapedScene> scene;
    std::unique_ptr<SimWorker> worker;
  };

  // The rollout alone, without the bounds: at the task's timestep, or (fine) at half of
  // it without pose samples.
  std::shared_ptr<MotionOutcome> simulate_outcome(const Eigen::VectorXd& x, int worker) const;
  Evaluation run(const Eigen::VectorXd& x, int worker, const EvaluationOptions& options,
                 MotionOutcome& outcome) const;
  // Adds the bounds' terms to an outcome's constraint.
  void apply_bounds(MotionOutcome& outcome) const;
  // The half-timestep check of confirm(), on `outcome` (a copy of the provisional one).
  void confirm_half_timestep(const Eigen::VectorXd& x, int worker, MotionOutcome& outcome) const;
  void add_task_term(MotionOutcome& outcome, double term) const;

  const TaskEvaluator* evaluator_;
  DistanceSpec distance_;
  MotionBounds bounds_;
  std::shared_ptr<const MotionOutcome> reference_outcome_;
  bool vary_shape_ = false;
  Eigen::VectorXd reference_;
  ParameterSet parameters_;
  MetricLayout layout_;
  Eigen::VectorXd link_mass_;
  Eigen::VectorXd base_scales_, base_link_lengths_;  // the task's body
  std::vector<std::unique_ptr<SimWorker>> workers_;
  mutable std::vector<ShapedWorker> shaped_;  // one per worker index (vary_shape)
};

}  // namespace diverse
