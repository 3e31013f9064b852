#include "eval/motion_problem.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace diverse {

MetricLayout MotionProblem::layout_for(const TaskEvaluator& evaluator) {
  // Hands, feet and WJA weights come from the character file (character/character.h).
  const Character& body = evaluator.body();
  MetricLayout layout;
  for (std::size_t i = 0; i < body.links.size(); ++i) {
    const int link = body.links[i];
    const bool hand = std::find(body.hands.begin(), body.hands.end(), link) != body.hands.end();
    if (hand || link == body.feet[0] || link == body.feet[1]) layout.hand_foot_links.push_back(static_cast<int>(i));
  }
  layout.angle_weights.resize(static_cast<Eigen::Index>(body.joints.size()));
  for (std::size_t i = 0; i < body.joints.size(); ++i)
    layout.angle_weights[static_cast<Eigen::Index>(i)] = body.groups[static_cast<std::size_t>(body.joints[i].group)].wja;
  layout.root_weight = body.spec->root_wja;
  return layout;  // shape_weights empty: w_i = 1 (paper section 4.2)
}

MotionProblem::MotionProblem(const TaskEvaluator& evaluator, DistanceSpec distance,
                             Eigen::VectorXd reference, int workers, bool vary_shape)
    : evaluator_(&evaluator),
      distance_(distance),
      vary_shape_(vary_shape),
      reference_(std::move(reference)),
      layout_(layout_for(evaluator)),
      link_mass_(evaluator.link_masses()) {
  if (distance_.uses_shape() && !vary_shape_)
    throw std::logic_error("MotionProblem: a distance on the shape needs vary_shape");
  if (distance_.combined() && distance_.metric == Metric::kShape)
    throw std::logic_error("MotionProblem: a combined distance needs a motion metric");
  // A character without shape parameters has no scales and no link lengths (its shape
  // distance is 0); vary_shape needs them (TaskEvaluator::shapes() says so).
  if (vary_shape_ || evaluator.has_shape()) {
    const ShapeSpace& shapes = evaluator.shapes();
    base_scales_ = shapes.identity();
    base_link_lengths_ = shapes.base_link_lengths();
  }
  parameters_ = evaluator.parameters();
  if (vary_shape_) {
    const ShapeSpace& shapes = evaluator.shapes();
    Eigen::VectorXd lower(shapes.size());
    for (int p = 0; p < shapes.size(); ++p) lower[p] = shapes.specs()[static_cast<std::size_t>(p)].lower;
    parameters_ = evaluator.with_shape(parameters_, lower);
  }
  if (reference_.size() != parameters_.size())
    throw std::logic_error("MotionProblem: reference has the wrong dimension");
  if (workers < 1) throw std::logic_error("MotionProblem: at least one worker");
  for (int w = 0; w < workers; ++w) workers_.push_back(evaluator.make_worker());
  if (vary_shape_) shaped_.resize(static_cast<std::size_t>(workers));
}

MotionProblem::MotionProblem(const TaskEvaluator& evaluator, Metric metric, Eigen::VectorXd reference,
                             int workers)
    : MotionProblem(evaluator, DistanceSpec{metric, 0.0}, std::move(reference), workers, false) {}

int MotionProblem::dim() const { return static_cast<int>(reference_.size()); }

ParameterSet MotionProblem::named(const Eigen::VectorXd& x) const {
  ParameterSet p = parameters_;
  p.set_normalized(x);
  if (vary_shape_) {
    // lower + x (upper - lower) can round past a bound for x inside [0, 1]; a shape scale
    // past its bound would be refused, so such values go back on the bound.
    auto& values = p.values();
    for (int i = p.size() - static_cast<int>(base_scales_.size()); i < p.size(); ++i) {
      const ParamSpec& s = p.specs()[static_cast<std::size_t>(i)];
      if (x[i] >= 0.0 && x[i] <= 1.0)
        values[static_cast<std::size_t>(i)] = std::clamp(values[static_cast<std::size_t>(i)], s.lower, s.upper);
    }
  }
  return p;
}

std::shared_ptr<const Outcome> MotionProblem::evaluate(const Eigen::VectorXd& x,
                                                      int worker) const {
  const auto w = static_cast<std::size_t>(worker);
  auto outcome = std::make_shared<MotionOutcome>();
  Evaluation e;
  if (!vary_shape_) {
    e = evaluator_->evaluate_normalized(x, *workers_.at(w));
    outcome->scales = base_scales_;
    outcome->features.link_lengths = base_link_lengths_;
  } else {
    if (x.size() != dim()) throw std::logic_error("MotionProblem::evaluate: wrong dimension");
    const ParameterSet p = named(x);
    const int num_scales = static_cast<int>(base_scales_.size());
    const auto n = static_cast<std::size_t>(p.size() - num_scales);
    const std::vector<double> control(p.values().begin(), p.values().begin() + static_cast<long>(n));
    Eigen::VectorXd scales(num_scales);
    for (int k = 0; k < num_scales; ++k) scales[k] = p.values()[n + static_cast<std::size_t>(k)];
    outcome->scales = scales;
    outcome->features.link_lengths = evaluator_->shapes().link_lengths(scales);
    int outside = -1;
    for (int i = 0; i < x.size() && outside < 0; ++i)
      if (!(x[i] >= 0.0 && x[i] <= 1.0)) outside = i;
    if (outside >= 0) {
      // As TaskEvaluator::evaluate_normalized: the optimizer keeps samples in the box.
      e.failed = true;
      e.fell = true;
      e.failure = "normalized parameter " + p.specs()[static_cast<std::size_t>(outside)].name + " outside [0, 1]";
      e.summary.unstable = true;
      e.report = evaluate_constraints(evaluator_->task(), e.summary);
      e.constraint = e.report.total;
    } else {
      ShapedWorker& slot = shaped_.at(w);
      if (!slot.scene || slot.scene->scales != scales) {
        slot.scene = evaluator_->shaped_scene(scales);
        slot.worker = std::make_unique<SimWorker>(slot.scene->model);
      }
      e = evaluator_->evaluate(control, *slot.scene, *slot.worker);
    }
  }
  outcome->constraint = e.constraint;
  outcome->failed = e.failed || !std::isfinite(e.constraint);
  outcome->fell = e.fell;
  outcome->landing_x = e.summary.feet_x;
  outcome->peak_com_z = e.summary.peak_com_z;
  if (!outcome->failed) {
    outcome->features.poses.reserve(e.poses.size());
    for (const PoseSample& sample : e.poses)
      outcome->features.poses.push_back(make_pose(sample.link_com, link_mass_, sample.angles, sample.root));
  }
  return outcome;
}

Evaluation MotionProblem::simulate(const Eigen::VectorXd& x, const EvaluationOptions& options,
                                   std::shared_ptr<const SharedModel>* model_out) const {
  return evaluator_->evaluate_named(named(x), options, model_out);
}

double MotionProblem::distance(const Outcome& a, const Outcome& b) const {
  return distance(a, b, distance_);
}

double MotionProblem::distance(const Outcome& a, const Outcome& b, const DistanceSpec& spec) const {
  double d = distance(a, b, spec.metric);
  if (spec.combined()) d += spec.shape_weight * distance(a, b, Metric::kShape);
  return d;
}

double MotionProblem::distance(const Outcome& a, const Outcome& b, Metric metric) const {
  const auto& ma = static_cast<const MotionOutcome&>(a);
  const auto& mb = static_cast<const MotionOutcome&>(b);
  if (metric == Metric::kShape) return motion_distance(metric, ma.features, mb.features, layout_);
  // Motions that took off but never reached a second phase have fewer samples than the
  // others; they carry a constraint penalty and sit at distance 0 (see metric.h).
  if (ma.features.poses.size() != mb.features.poses.size()) return 0.0;
  return motion_distance(metric, ma.features, mb.features, layout_);
}

}  // namespace diverse
