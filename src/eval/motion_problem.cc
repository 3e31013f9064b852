#include "eval/motion_problem.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace diverse {

MetricLayout MotionProblem::layout_for(const TaskEvaluator& evaluator) {
  MetricLayout layout;
  const std::vector<std::string> links = evaluator.link_names();
  for (int i = 0; i < static_cast<int>(links.size()); ++i)
    if (links[i].rfind("hand", 0) == 0 || links[i].rfind("foot", 0) == 0)
      layout.hand_foot_links.push_back(i);
  if (layout.hand_foot_links.size() != 4)
    throw std::logic_error("MotionProblem: expected two hands and two feet among the links");
  const std::vector<std::string> angles = evaluator.angle_names();
  layout.angle_weights.resize(static_cast<Eigen::Index>(angles.size()));
  for (std::size_t i = 0; i < angles.size(); ++i)
    layout.angle_weights[static_cast<Eigen::Index>(i)] = lee2002_joint_weight(angles[i]);
  return layout;
}

MotionProblem::MotionProblem(const TaskEvaluator& evaluator, Metric metric,
                             Eigen::VectorXd reference, int workers)
    : evaluator_(&evaluator),
      metric_(metric),
      reference_(std::move(reference)),
      layout_(layout_for(evaluator)),
      link_mass_(evaluator.link_masses()) {
  if (metric == Metric::kShape)
    throw std::logic_error("MotionProblem: the shape metric needs shape parameters");
  if (reference_.size() != evaluator.dim())
    throw std::logic_error("MotionProblem: reference has the wrong dimension");
  if (workers < 1) throw std::logic_error("MotionProblem: at least one worker");
  for (int w = 0; w < workers; ++w) workers_.push_back(evaluator.make_worker());
}

int MotionProblem::dim() const { return static_cast<int>(reference_.size()); }

std::shared_ptr<const Outcome> MotionProblem::evaluate(const Eigen::VectorXd& x,
                                                      int worker) const {
  const Evaluation e = evaluator_->evaluate_normalized(x, *workers_.at(static_cast<std::size_t>(worker)));
  auto outcome = std::make_shared<MotionOutcome>();
  outcome->constraint = e.constraint;
  outcome->failed = e.failed || !std::isfinite(e.constraint);
  outcome->fell = e.fell;
  outcome->landing_x = e.summary.feet_x;
  outcome->peak_com_z = e.summary.peak_com_z;
  if (!outcome->failed) {
    outcome->features.poses.reserve(e.poses.size());
    for (const PoseSample& sample : e.poses)
      outcome->features.poses.push_back(make_pose(sample.link_com, link_mass_, sample.angles));
  }
  return outcome;
}

double MotionProblem::distance(const Outcome& a, const Outcome& b) const {
  return distance(a, b, metric_);
}

double MotionProblem::distance(const Outcome& a, const Outcome& b, Metric metric) const {
  const auto& ma = static_cast<const MotionOutcome&>(a);
  const auto& mb = static_cast<const MotionOutcome&>(b);
  // Motions that took off but never reached a second phase have fewer samples than the
  // others; they carry a constraint penalty and sit at distance 0 (see metric.h).
  if (ma.features.poses.size() != mb.features.poses.size()) return 0.0;
  return motion_distance(metric, ma.features, mb.features, layout_);
}

}  // namespace diverse
