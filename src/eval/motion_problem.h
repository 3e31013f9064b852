// A task's motions as a diversity problem (paper section 3 on top of sections 4 and 6).
//
// A variation is the controller's normalized parameter vector; evaluating it runs one
// rollout of the task (task/evaluate.h) and keeps what the distance metrics need: the
// pose samples at phase-normalized times of the two airborne phases (10 each), turned
// into metric poses with the whole-body centre of mass subtracted (metric/metric.h).
// The objective's distance is the task's metric (or the one the user chose); the other
// motion metrics can be computed on the same outcomes for reporting.
//
// Thread safety: one SimWorker per worker index, created up front; evaluate() with a
// given worker index is never called concurrently (DiversityProblem's contract).
#pragma once

#include <memory>
#include <vector>

#include "metric/metric.h"
#include "optimize/objective.h"
#include "task/evaluate.h"

namespace diverse {

// The outcome of one rollout.
struct MotionOutcome : Outcome {
  MotionFeatures features;   // pose samples for the metrics (empty without a flight)
  bool fell = false;
  double landing_x = 0;      // m, mean foot x at rest (or at the end)
  double peak_com_z = 0;     // m
};

class MotionProblem : public DiversityProblem {
 public:
  // `evaluator` must outlive the problem. `reference` is M0's normalized parameters.
  MotionProblem(const TaskEvaluator& evaluator, Metric metric, Eigen::VectorXd reference,
                int workers);

  int dim() const override;
  Eigen::VectorXd reference() const override { return reference_; }
  std::shared_ptr<const Outcome> evaluate(const Eigen::VectorXd& x, int worker) const override;
  double distance(const Outcome& a, const Outcome& b) const override;

  // Distance between two outcomes under any motion metric (for the summary's matrices).
  double distance(const Outcome& a, const Outcome& b, Metric metric) const;

  Metric metric() const { return metric_; }
  const MetricLayout& layout() const { return layout_; }
  const TaskEvaluator& evaluator() const { return *evaluator_; }
  int workers() const { return static_cast<int>(workers_.size()); }

  // Metric layout of the planar human: hands and feet by link name, WJA weights from
  // lee2002_joint_weight() on the joint names (root included).
  static MetricLayout layout_for(const TaskEvaluator& evaluator);

 private:
  const TaskEvaluator* evaluator_;
  Metric metric_;
  Eigen::VectorXd reference_;
  MetricLayout layout_;
  Eigen::VectorXd link_mass_;
  std::vector<std::unique_ptr<SimWorker>> workers_;
};

}  // namespace diverse
