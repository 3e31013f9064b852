#include "eval/motion_problem.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

#include "core/error.h"
#include "robust/robustness.h"

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

nlohmann::json to_json(const MotionBounds& bounds) {
  nlohmann::json j = nlohmann::json::object();
  if (bounds.effort > 0) j["effort"] = bounds.effort;
  if (bounds.distance > 0) j["distance"] = bounds.distance;
  if (bounds.robust) j["robust"] = true;
  return j;
}

MotionBounds motion_bounds_from_json(const nlohmann::json& j, const std::string& where) {
  MotionBounds bounds;
  if (j.is_null()) return bounds;
  if (!j.is_object()) throw_field_error(where, "bounds", "expected an object");
  for (const auto& item : j.items())
    if (item.key() != "effort" && item.key() != "distance" && item.key() != "robust")
      throw_field_error(where, "bounds." + item.key(), "expected only the keys effort, distance and robust");
  auto number = [&](const char* key, bool open_low, double lo, double hi, const char* range) {
    if (!j.contains(key)) return 0.0;
    const nlohmann::json& v = j.at(key);
    const double x = v.is_number() ? v.get<double>() : std::nan("");
    if (!((open_low ? x > lo : x >= lo) && x <= hi))
      throw_field_error(where, std::string("bounds.") + key, std::string("expected a number in ") + range);
    return x;
  };
  bounds.effort = number("effort", false, kMinEffortBound, kMaxEffortBound, "[1, 1e6]");
  bounds.distance = number("distance", true, 0, kMaxDistanceBound, "(0, 1e12]");
  if (j.contains("robust")) {
    if (!j.at("robust").is_boolean()) throw_field_error(where, "bounds.robust", "expected true or false");
    bounds.robust = j.at("robust").get<bool>();
  }
  return bounds;
}

MotionProblem::MotionProblem(const TaskEvaluator& evaluator, DistanceSpec distance,
                             Eigen::VectorXd reference, int workers, bool vary_shape,
                             MotionBounds bounds)
    : evaluator_(&evaluator),
      distance_(distance),
      bounds_(bounds),
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
  if (bounds_.any()) {
    reference_outcome_ = simulate_outcome(reference_, 0);
    if (reference_outcome_->failed)
      throw UserError(evaluator.task().file + ": the input motion fails (" +
                      (bounds_.effort > 0 ? std::string("--effort-bound") : std::string("--max-distance")) +
                      " needs it as the reference)");
    if (bounds_.effort > 0 && !(reference_outcome_->effort > 0))
      throw UserError("--effort-bound: the input motion's effort is 0; nothing to bound by");
  }
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
  auto outcome = simulate_outcome(x, worker);
  outcome->provisional = (evaluator_->task().constraints.half_timestep || bounds_.robust) &&
                         !outcome->failed && outcome->task_constraint == 0;
  if (bounds_.any()) apply_bounds(*outcome);
  return outcome;
}

double robust_failure_penalty(const Task& task) { return task.constraints.weight * 0.005; }

std::shared_ptr<const Outcome> MotionProblem::confirm(const Eigen::VectorXd& x, const Outcome& outcome,
                                                      int worker) const {
  const auto& coarse = dynamic_cast<const MotionOutcome&>(outcome);
  if (!coarse.provisional) throw std::logic_error("MotionProblem::confirm: the outcome is not provisional");
  auto confirmed = std::make_shared<MotionOutcome>(coarse);
  confirmed->provisional = false;
  if (evaluator_->task().constraints.half_timestep) confirm_half_timestep(x, worker, *confirmed);
  if (bounds_.robust && confirmed->task_constraint == 0 && !confirmed->failed) {
    const SuiteVerdict verdict = check_suite(*evaluator_, named(x), robust_sample_suite());
    confirmed->robust_steps = verdict.steps;
    confirmed->robust_held = verdict.holds;
    if (!verdict.holds) {
      add_task_term(*confirmed, robust_failure_penalty(evaluator_->task()));
    }
  }
  return confirmed;
}

// A confirmation's term added to the task's C, then the bounds' terms on top, in the order
// evaluate() adds them.
void MotionProblem::add_task_term(MotionOutcome& out, double term) const {
  out.task_constraint += term;
  out.constraint = out.task_constraint;
  out.failed = !std::isfinite(out.constraint);
  if (bounds_.effort > 0 || bounds_.distance > 0) apply_bounds(out);
}

void MotionProblem::confirm_half_timestep(const Eigen::VectorXd& x, int worker, MotionOutcome& out) const {
  const MotionOutcome::Landing& coarse = out.landing;
  EvaluationOptions fine_options;
  fine_options.samples_per_phase = 0;
  fine_options.timestep_scale = 0.5;
  fine_options.end_when_decided = evaluator_->task().walk.enabled;
  MotionOutcome scratch;
  const Evaluation fine = run(x, worker, fine_options, scratch);
  MotionSummary landed;
  landed.landed = coarse.landed;
  landed.fell = coarse.fell;
  landed.unstable = coarse.unstable;
  landed.touchdown_feet_x = coarse.touchdown_x;
  landed.touchdown_feet_y = coarse.touchdown_y;
  landed.feet_x = coarse.rest_x;
  landed.feet_y = coarse.rest_y;
  double penalty = half_timestep_term(evaluator_->task(), landed, fine.summary, fine.constraint).penalty;
  // A --robust run ranks a motion that fails at half the step below one that only fails
  // the suite's part: the task itself is not met there.
  if (bounds_.robust && penalty > 0) penalty += 2 * robust_failure_penalty(evaluator_->task());
  // In the order TaskEvaluator::evaluate adds it (0 + penalty), then the bounds' terms.
  add_task_term(out, penalty);
  out.check_steps = fine.stats.steps;
}

std::shared_ptr<const Outcome> MotionProblem::evaluate_confirmed(const Eigen::VectorXd& x,
                                                                int worker) const {
  auto outcome = evaluate(x, worker);
  return outcome->provisional ? confirm(x, *outcome, worker) : outcome;
}

namespace {

// Adds to an integer entry of a JSON object (made an object if it is null).
void add(nlohmann::json& object, const char* name, long long amount) {
  nlohmann::json& entry = object[name];
  entry = (entry.is_number_integer() ? entry.get<long long>() : 0LL) + amount;
}

void add_steps(nlohmann::json& ledger, const char* kind, const char* outcome, long long steps) {
  nlohmann::json& entry = ledger[kind][outcome];
  add(entry, "rollouts", 1);
  add(entry, "steps", steps);
  add(ledger, "total", steps);
}

}  // namespace

void MotionProblem::tally(const Outcome& outcome, nlohmann::json& ledger) const {
  const auto& m = dynamic_cast<const MotionOutcome&>(outcome);
  if (m.check_steps >= 0 || m.robust_steps >= 0) {  // a confirmation: only its checks are new
    if (m.check_steps >= 0) {
      const bool held = m.robust_steps >= 0 || m.constraint == 0;  // robustness is checked after
      add_steps(ledger, "half_timestep", held ? "held" : "failed", m.check_steps);
    }
    if (m.robust_steps >= 0) add_steps(ledger, "robustness", m.robust_held ? "held" : "failed", m.robust_steps);
    return;
  }
  const char* result = m.fell || m.failed ? "fell" : m.task_constraint > 0 ? "failed" : "met";
  add_steps(ledger, "rollouts", result, m.steps);
  add(ledger, "after_decided", m.steps_after_decided);
}

long long steps_of(const nlohmann::json& ledger, const char* kind, const char* outcome) {
  if (!ledger.is_object()) return 0;
  if (!kind) return ledger.value("total", 0LL);
  const auto k = ledger.find(kind);
  if (k == ledger.end()) return 0;
  if (k->is_number_integer()) return k->get<long long>();  // "after_decided"
  long long sum = 0;
  for (const auto& [name, entry] : k->items())
    if (!outcome || name == outcome) sum += entry.value("steps", 0LL);
  return sum;
}

void MotionProblem::apply_bounds(MotionOutcome& outcome) const {
  if (outcome.failed) return;  // already as bad as it gets
  const double weight = evaluator_->task().constraints.weight;
  const MotionOutcome& m0 = *reference_outcome_;
  if (bounds_.effort > 0) {
    outcome.effort_ratio = outcome.effort / m0.effort;
    const double e = std::max(0.0, outcome.effort_ratio / bounds_.effort - 1.0);
    outcome.constraint += weight * e * e;
  }
  if (bounds_.distance > 0) {
    outcome.distance_to_m0 = distance(outcome, m0);
    const double e = std::max(0.0, outcome.distance_to_m0 / bounds_.distance - 1.0);
    outcome.constraint += weight * e * e;
  }
  if (!std::isfinite(outcome.constraint)) outcome.failed = true;
}

std::shared_ptr<MotionOutcome> MotionProblem::simulate_outcome(const Eigen::VectorXd& x,
                                                               int worker) const {
  auto outcome = std::make_shared<MotionOutcome>();
  // A walk ends at the step that breaks its rules (its C extrapolated from the steps so
  // far, task/walk_task.h). A jump runs to its end: whether a landing that misses the task
  // stands or falls decides its C, and only the rest of the rollout tells
  // (docs/notes/2026-12-04-where-a-runs-steps-go.md).
  EvaluationOptions options;
  options.end_when_decided = evaluator_->task().walk.enabled;
  const Evaluation e = run(x, worker, options, *outcome);
  outcome->constraint = e.constraint;
  outcome->task_constraint = e.constraint;
  outcome->effort = e.stats.effort;
  outcome->positive_work = e.stats.positive_work;
  outcome->failed = e.failed || !std::isfinite(e.constraint);
  outcome->fell = e.fell;
  outcome->landing_x = e.summary.feet_x;
  outcome->peak_com_z = e.summary.peak_com_z;
  outcome->landing = {e.summary.landed, e.summary.fell, e.summary.unstable, e.summary.touchdown_feet_x,
                      e.summary.touchdown_feet_y, e.summary.feet_x, e.summary.feet_y};
  outcome->steps = e.stats.steps;
  outcome->steps_after_decided = e.steps_after_decided;
  if (!outcome->failed) {
    outcome->features.poses.reserve(e.poses.size());
    for (const PoseSample& sample : e.poses)
      outcome->features.poses.push_back(make_pose(sample.link_com, link_mass_, sample.angles, sample.root));
  }
  return outcome;
}

Evaluation MotionProblem::run(const Eigen::VectorXd& x, int worker, const EvaluationOptions& options,
                              MotionOutcome& out) const {
  const auto w = static_cast<std::size_t>(worker);
  MotionOutcome* outcome = &out;
  Evaluation e;
  if (!vary_shape_) {
    e = evaluator_->evaluate_normalized(x, *workers_.at(w), options);
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
      e = evaluator_->evaluate(control, *slot.scene, *slot.worker, options);
    }
  }
  return e;
}

Evaluation MotionProblem::simulate(const Eigen::VectorXd& x, const EvaluationOptions& options,
                                   std::shared_ptr<const SharedModel>* model_out) const {
  // The robustness suite's disturbances (robust/robustness.h) are never the optimizer's.
  if (options.push.time >= 0 || options.friction_scale != 1.0)
    throw std::logic_error("MotionProblem::simulate: a push or a friction scale is the robustness suite's only");
  return evaluator_->evaluate_named(named(x), options, model_out);
}

namespace {

// Little helpers for encode()/decode(): plain bytes of trivially copyable values.
class Writer {
 public:
  template <class T>
  void put(const T& value) {
    const auto* p = reinterpret_cast<const char*>(&value);
    out_.append(p, sizeof(T));
  }
  void put_doubles(const double* data, Eigen::Index count) {
    put(static_cast<std::uint64_t>(count));
    out_.append(reinterpret_cast<const char*>(data), static_cast<std::size_t>(count) * sizeof(double));
  }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
};

class Reader {
 public:
  explicit Reader(const std::string& in) : in_(in) {}
  template <class T>
  T get() {
    T value;
    need(sizeof(T));
    std::memcpy(&value, in_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  // A count of doubles; `rows` divides it when given (matrices of `rows` rows).
  Eigen::Index count(Eigen::Index rows = 1) {
    const auto n = get<std::uint64_t>();
    if (n > (in_.size() - at_) / sizeof(double) || n % static_cast<std::uint64_t>(rows) != 0)
      throw std::invalid_argument("outcome bytes: bad array length");
    return static_cast<Eigen::Index>(n);
  }
  void doubles(double* data, Eigen::Index n) {
    need(static_cast<std::size_t>(n) * sizeof(double));
    std::memcpy(data, in_.data() + at_, static_cast<std::size_t>(n) * sizeof(double));
    at_ += static_cast<std::size_t>(n) * sizeof(double);
  }
  Eigen::VectorXd vector() {
    Eigen::VectorXd v(count());
    doubles(v.data(), v.size());
    return v;
  }
  bool done() const { return at_ == in_.size(); }

 private:
  void need(std::size_t bytes) const {
    if (in_.size() - at_ < bytes) throw std::invalid_argument("outcome bytes: truncated");
  }
  const std::string& in_;
  std::size_t at_ = 0;
};

constexpr std::uint32_t kOutcomeMagic = 0x4d4f5432;  // "MOT2"

}  // namespace

std::string MotionProblem::encode(const Outcome& outcome) {
  const auto& m = dynamic_cast<const MotionOutcome&>(outcome);
  Writer w;
  w.put(kOutcomeMagic);
  w.put(m.constraint);
  w.put(static_cast<std::uint8_t>(m.failed));
  w.put(static_cast<std::uint8_t>(m.fell));
  w.put(m.landing_x);
  w.put(m.peak_com_z);
  w.put(m.task_constraint);
  w.put(m.effort);
  w.put(m.positive_work);
  w.put(m.effort_ratio);
  w.put(m.distance_to_m0);
  w.put(static_cast<std::uint8_t>(m.provisional));
  w.put(static_cast<std::uint8_t>(m.landing.landed));
  w.put(static_cast<std::uint8_t>(m.landing.fell));
  w.put(static_cast<std::uint8_t>(m.landing.unstable));
  w.put(m.landing.touchdown_x);
  w.put(m.landing.touchdown_y);
  w.put(m.landing.rest_x);
  w.put(m.landing.rest_y);
  w.put(m.steps);
  w.put(m.steps_after_decided);
  w.put(m.check_steps);
  w.put(m.robust_steps);
  w.put(static_cast<std::uint8_t>(m.robust_held));
  w.put_doubles(m.scales.data(), m.scales.size());
  w.put_doubles(m.features.link_lengths.data(), m.features.link_lengths.size());
  w.put(static_cast<std::uint64_t>(m.features.poses.size()));
  for (const Pose& pose : m.features.poses) {
    w.put_doubles(pose.link_com.data(), pose.link_com.size());
    w.put_doubles(pose.link_mass.data(), pose.link_mass.size());
    w.put_doubles(pose.angles.data(), pose.angles.size());
    w.put_doubles(pose.root.coeffs().data(), 4);
  }
  return w.take();
}

std::shared_ptr<const Outcome> MotionProblem::decode(const std::string& bytes) {
  Reader r(bytes);
  if (r.get<std::uint32_t>() != kOutcomeMagic) throw std::invalid_argument("outcome bytes: not an outcome");
  auto m = std::make_shared<MotionOutcome>();
  m->constraint = r.get<double>();
  m->failed = r.get<std::uint8_t>() != 0;
  m->fell = r.get<std::uint8_t>() != 0;
  m->landing_x = r.get<double>();
  m->peak_com_z = r.get<double>();
  m->task_constraint = r.get<double>();
  m->effort = r.get<double>();
  m->positive_work = r.get<double>();
  m->effort_ratio = r.get<double>();
  m->distance_to_m0 = r.get<double>();
  m->provisional = r.get<std::uint8_t>() != 0;
  m->landing.landed = r.get<std::uint8_t>() != 0;
  m->landing.fell = r.get<std::uint8_t>() != 0;
  m->landing.unstable = r.get<std::uint8_t>() != 0;
  m->landing.touchdown_x = r.get<double>();
  m->landing.touchdown_y = r.get<double>();
  m->landing.rest_x = r.get<double>();
  m->landing.rest_y = r.get<double>();
  m->steps = r.get<long long>();
  m->steps_after_decided = r.get<long long>();
  m->check_steps = r.get<long long>();
  m->robust_steps = r.get<long long>();
  m->robust_held = r.get<std::uint8_t>() != 0;
  m->scales = r.vector();
  m->features.link_lengths = r.vector();
  const auto poses = r.get<std::uint64_t>();
  if (poses > bytes.size()) throw std::invalid_argument("outcome bytes: bad pose count");
  m->features.poses.resize(static_cast<std::size_t>(poses));
  for (Pose& pose : m->features.poses) {
    const Eigen::Index com = r.count(3);
    pose.link_com.resize(3, com / 3);
    r.doubles(pose.link_com.data(), com);
    pose.link_mass = r.vector();
    pose.angles = r.vector();
    if (r.count() != 4) throw std::invalid_argument("outcome bytes: bad root quaternion");
    r.doubles(pose.root.coeffs().data(), 4);
  }
  if (!r.done()) throw std::invalid_argument("outcome bytes: trailing bytes");
  return m;
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
