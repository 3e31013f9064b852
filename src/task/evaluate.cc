#include "task/evaluate.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "core/error.h"
#include "core/text_file.h"
#include "task/jump_eval.h"
#include "task/rollout_terms.h"
#include "task/scene_check.h"
#include "task/walk_eval.h"

namespace diverse {
namespace {

// Puts the worker's geom friction back to the shared model's when it goes out of scope.
class FrictionRestore {
 public:
  FrictionRestore(SimWorker& worker, bool active) : worker_(worker), active_(active) {}
  ~FrictionRestore() {
    if (!active_) return;
    const mjModel* src = worker_.shared().get();
    mju_copy(worker_.model()->geom_friction, src->geom_friction, 3 * src->ngeom);
  }
  FrictionRestore(const FrictionRestore&) = delete;
  FrictionRestore& operator=(const FrictionRestore&) = delete;

 private:
  SimWorker& worker_;
  bool active_;
};

// The push of EvaluationOptions::push around a rollout's own hooks: at the first step
// whose time reaches the push's, the root's linear velocity changes by dv, and what
// mj_step1 computed from the velocity (actuator and COM velocities, passive and bias
// forces, the constraints' reference) is computed again, so the step, the controller and
// the observer all see the pushed state. Nothing allocates; without a push it only forwards.
class PushHooks : public StepHooks {
 public:
  PushHooks(StepHooks& inner, const Character& body, const EvaluationOptions::Push& push, Evaluation& out)
      : inner_(inner), body_(body), push_(push), out_(out) {}

  void control(mjModel* m, mjData* d) override {
    if (push_.time >= 0 && out_.push_time < 0 && d->time >= push_.time) {
      if (body_.root == RootKind::kPlanar) {
        d->qvel[body_.root_x_dof] += push_.dv[0];
        d->qvel[body_.root_z_dof] += push_.dv[2];
      } else {
        for (int k = 0; k < 3; ++k) d->qvel[body_.root_dof + k] += push_.dv[static_cast<size_t>(k)];
      }
      mj_fwdVelocity(m, d);
      out_.push_time = d->time;
    }
    inner_.control(m, d);
  }
  bool observe(const mjModel* m, const mjData* d) override { return inner_.observe(m, d); }
  void stepped(const mjModel* m, const mjData* d) override { inner_.stepped(m, d); }

 private:
  StepHooks& inner_;
  const Character& body_;
  const EvaluationOptions::Push& push_;
  Evaluation& out_;
};

// A rollout's hooks that also tell the listed constraints' observers of every simulation
// step (RolloutTerms::stepped; a foot-slip bound's meter), as a replay of its record would.
class TermHooks : public StepHooks {
 public:
  TermHooks(StepHooks& inner, RolloutTerms& terms) : inner_(inner), terms_(terms) {}
  void control(mjModel* m, mjData* d) override { inner_.control(m, d); }
  bool observe(const mjModel* m, const mjData* d) override { return inner_.observe(m, d); }
  void stepped(const mjModel* m, const mjData* d) override {
    terms_.stepped(m, d);
    inner_.stepped(m, d);
  }

 private:
  StepHooks& inner_;
  RolloutTerms& terms_;
};

// Runs a rollout with a task's hooks (under the suite's push, if any) and fills in what
// every kind of task reports of it: the rollout's stats, phases and failure, what the
// listed constraints measured, C, when the outcome was decided, and the pose samples
// (hooks: a JumpObserver or a WalkObserver).
void simulate(const Task& task, const Character& body, const Controller& controller, JointDrive& drive,
              TaskObserver& hooks, RolloutTerms& terms, int max_steps, SimWorker& worker,
              const EvaluationOptions& options, Evaluation& e) {
  TermHooks observed(hooks, terms);
  if (options.push.time >= 0) {
    PushHooks pushed(observed, body, options.push, e);
    e.stats = run_rollout(worker, pushed, max_steps, drive, options.recorder);
  } else {
    e.stats = run_rollout(worker, observed, max_steps, drive, options.recorder);
  }
  terms.finish(e.summary);
  e.phases = controller.phase_times();
  if (e.stats.unstable) {
    e.failed = true;
    e.failure = "simulation unstable: " + e.stats.instability;
    e.summary.unstable = true;
  }
  e.report = evaluate_constraints(task, e.summary);
  e.constraint = e.report.total;
  e.fell = e.report.fell;
  e.decided_step = static_cast<int>(hooks.decided_at());
  if (hooks.decided_at() >= 0)
    e.steps_after_decided = static_cast<int>(std::max(0L, hooks.observed() - hooks.decided_at()));
  if (!e.failed && options.samples_per_phase > 0) e.poses = hooks.poses(worker);
}

}  // namespace

TaskEvaluator::TaskEvaluator(Task task) : task_(std::move(task)) {
  model_ = SharedModel::from_xml(scene_xml(task_), task_.model);
  body_ = std::make_unique<Character>(bind_character(task_.character_spec, model_->get(), task_.model));
  body_->strength = task_.strength;
  if (task_.strength != 1.0) check_strength();
  check_scene(task_, model_->get(), *body_);
  task_.controller_type->check(*body_, *task_.controller_config, task_.file);
  specs_ = task_.controller_type->parameter_specs(*body_, *task_.controller_config);
}

void TaskEvaluator::check_strength() const {
  // The scene at strength 1, compiled once, to see that every torque limit scaled: a
  // limit the text did not carry as a forcerange attribute would have stayed as it was.
  Task plain = task_;
  plain.strength = 1.0;
  const auto base = SharedModel::from_xml(scene_xml(plain), task_.model);
  const std::vector<DrivenJoint> scaled = driven_joints(model_->get());
  const std::vector<DrivenJoint> unscaled = driven_joints(base->get());
  for (std::size_t k = 0; k < scaled.size() && k < unscaled.size(); ++k) {
    const double want = task_.strength * unscaled[k].limit;
    if (std::fabs(scaled[k].limit - want) > 1e-9 * want) {
      const char* name = mj_id2name(model_->get(), mjOBJ_ACTUATOR, scaled[k].actuator);
      throw UserError(task_.model + ": actuator '" + (name ? name : "?") +
                      "': expected its torque limit in a forcerange attribute, which --strength "
                      "scales, but it stayed " + std::to_string(scaled[k].limit) + " Nm");
    }
  }
}

ParameterSet TaskEvaluator::parameters() const {
  std::vector<double> values;
  for (const ParamSpec& s : specs_) values.push_back(s.lower);
  return ParameterSet(specs_, values);
}

namespace {

// The named values of a parameter file: {"parameters": {...}} (a motion or M0 file) or
// the object itself.
nlohmann::json read_parameter_file(const std::string& path) {
  const std::string text = read_text_file(path, "parameter");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {  // parse_error, or out_of_range for 1e999
    throw UserError(path + ": expected valid JSON (" + std::string(e.what()) + ")");
  }
  if (j.is_object() && j.contains("parameters")) return j["parameters"];
  return j;
}

}  // namespace

ParameterSet TaskEvaluator::load_parameters(const std::string& path) const {
  ParameterSet p = parameters();
  p.set_from_json(read_parameter_file(path), path);
  return p;
}

std::unique_ptr<SimWorker> TaskEvaluator::make_worker() const {
  return std::make_unique<SimWorker>(model_);
}

Evaluation TaskEvaluator::evaluate_normalized(const Eigen::VectorXd& x, SimWorker& worker,
                                              const EvaluationOptions& options) const {
  ParameterSet p = parameters();
  if (x.size() != p.size()) throw std::logic_error("evaluate_normalized: wrong dimension");
  for (int i = 0; i < x.size(); ++i) {
    if (!(x[i] >= 0 && x[i] <= 1)) {
      Evaluation e;
      e.failed = true;
      e.fell = true;
      e.failure = "normalized parameter " + p.specs()[i].name + " outside [0, 1]";
      e.summary.unstable = true;
      e.report = evaluate_constraints(task_, e.summary);
      e.constraint = e.report.total;
      return e;
    }
  }
  p.set_normalized(x);
  return evaluate(p.values(), worker, options);
}

Evaluation TaskEvaluator::evaluate(const std::vector<double>& values, SimWorker& worker,
                                   const EvaluationOptions& options) const {
  if (&worker.shared() != model_.get()) {
    throw std::logic_error("TaskEvaluator::evaluate: worker belongs to another model");
  }
  return evaluate_on(values, *body_, worker, options);
}

Evaluation TaskEvaluator::evaluate_on(const std::vector<double>& values, const Character& body,
                                      SimWorker& worker, const EvaluationOptions& options) const {
  Evaluation e;
  worker.reset();
  mjModel* m = worker.model();
  if (!(options.timestep_scale > 0) || !std::isfinite(options.timestep_scale)) {
    throw std::logic_error("TaskEvaluator::evaluate: timestep_scale must be positive");
  }
  m->opt.timestep *= options.timestep_scale;
  if (!(options.friction_scale > 0) || !std::isfinite(options.friction_scale)) {
    throw std::logic_error("TaskEvaluator::evaluate: friction_scale must be positive");
  }
  const bool perturbed = options.friction_scale != 1.0 || options.push.time >= 0;
  if (perturbed && options.recorder != nullptr) {
    throw std::logic_error("TaskEvaluator::evaluate: a pushed or friction-scaled rollout cannot be recorded");
  }
  if (options.friction_scale != 1.0) {
    for (int k = 0; k < 3 * m->ngeom; ++k) m->geom_friction[k] *= options.friction_scale;
  }
  // The scaled friction lasts for this rollout only (SimWorker::reset restores it too).
  const FrictionRestore restore_friction(worker, options.friction_scale != 1.0);
  const auto controller = task_.controller_type->make(body, *task_.controller_config, values);
  JointDrive drive = make_drive(body, task_.simulation.saturated_drive, task_.simulation.damping);
  controller->start_state(m, worker.data());
  if (task_.walk.enabled) {
    e = evaluate_walk(*controller, drive, body, worker, options);
  } else {
    e = evaluate_jump(*controller, drive, body, worker, options);
  }
  if (options.half_timestep_check && task_.constraints.half_timestep && !e.failed && e.constraint == 0) {
    EvaluationOptions fine_options;
    fine_options.samples_per_phase = 0;
    fine_options.timestep_scale = 0.5 * options.timestep_scale;
    // The same world: the suite's friction and push hold at the finer timestep too.
    fine_options.friction_scale = options.friction_scale;
    fine_options.push = options.push;
    const Evaluation fine = evaluate_on(values, body, worker, fine_options);
    const ConstraintTerm term = half_timestep_term(task_, e.summary, fine.summary, fine.constraint);
    e.report.terms.push_back(term);
    e.report.total += term.penalty;
    e.constraint = e.report.total;
    e.check_steps = fine.stats.steps;
  }
  return e;
}

Evaluation TaskEvaluator::evaluate_jump(Controller& controller, JointDrive& drive, const Character& body,
                                        SimWorker& worker, const EvaluationOptions& options) const {
  Evaluation e;
  mjModel* m = worker.model();
  e.flight_time.reserve(1024);
  e.flight_qpos.reserve(1024 * static_cast<size_t>(m->nq));
  RolloutTerms terms(task_, m, body);
  JumpObserver hooks(task_, body, m, controller, drive, terms, options.samples_per_phase, options.end_when_decided, e);
  const int max_steps = static_cast<int>(std::ceil(task_.simulation.max_time / m->opt.timestep)) + 1;
  simulate(task_, body, controller, drive, hooks, terms, max_steps, worker, options, e);
  return e;
}

Evaluation TaskEvaluator::evaluate_walk(Controller& controller, JointDrive& drive, const Character& body,
                                        SimWorker& worker, const EvaluationOptions& options) const {
  Evaluation e;
  mjModel* m = worker.model();
  RolloutTerms terms(task_, m, body);
  WalkObserver hooks(task_, body, m, controller, drive, terms, options.samples_per_phase, options.end_when_decided, e);
  const int max_steps = static_cast<int>(std::ceil(task_.walk.max_time / m->opt.timestep)) + 1;
  simulate(task_, body, controller, drive, hooks, terms, max_steps, worker, options, e);
  return e;
}

bool holds_shape(const ParameterSet& params) {
  for (const ParamSpec& spec : params.specs())
    if (spec.name.rfind("shape.", 0) == 0) return true;
  return false;
}

bool TaskEvaluator::has_shape() const {
  return task_.character_spec->has_shape() && task_.character_spec->root == RootKind::kPlanar;
}

const ShapeSpace& TaskEvaluator::shapes() const {
  // A character without [shape] parameters (or not planar) cannot vary its shape: one line
  // naming its character file, before any parsing.
  require_shape(*task_.character_spec);
  std::call_once(shapes_->once, [this] {
    shapes_->space = std::make_unique<ShapeSpace>(model_->xml(), *task_.character_spec, task_.model);
  });
  return *shapes_->space;
}

ParameterSet TaskEvaluator::with_shape(const ParameterSet& control, const Eigen::VectorXd& scales) const {
  const ShapeSpace& space = shapes();
  if (scales.size() != space.size())
    throw std::logic_error("with_shape: expected " + std::to_string(space.size()) + " scales");
  std::vector<ParamSpec> specs = control.specs();
  std::vector<double> values = control.values();
  for (int p = 0; p < space.size(); ++p) {
    specs.push_back(space.specs()[static_cast<size_t>(p)]);
    values.push_back(scales[p]);
  }
  return ParameterSet(std::move(specs), std::move(values));
}

std::vector<double> TaskEvaluator::control_values(const ParameterSet& params) const {
  const std::vector<ParamSpec>& specs = specs_;
  std::vector<double> values;
  values.reserve(specs.size());
  for (const ParamSpec& s : specs) values.push_back(params.get(s.name));
  return values;
}

ParameterSet TaskEvaluator::load_shaped_parameters(const std::string& path) const {
  const nlohmann::json all = read_parameter_file(path);
  ParameterSet p = parameters();
  if (!all.is_object()) {
    p.set_from_json(all, path);  // reports the file's shape
    return p;
  }
  // Shape scales apart: they are checked against the shape's own ranges.
  nlohmann::json control = nlohmann::json::object(), shape = nlohmann::json::object();
  for (const auto& [name, value] : all.items()) (name.rfind("shape.", 0) == 0 ? shape : control)[name] = value;
  p.set_from_json(control, path);
  if (shape.empty()) return p;
  const ShapeSpace& space = shapes();
  Eigen::VectorXd scales = space.identity();
  for (const auto& [name, value] : shape.items()) {
    int index = -1;
    for (int k = 0; k < space.size(); ++k)
      if (space.specs()[static_cast<size_t>(k)].name == name) index = k;
    if (index < 0) {
      const auto& specs = space.specs();
      const std::string known = specs.size() == 1   ? specs.front().name
                                : specs.size() == 2 ? specs.front().name + ", " + specs.back().name
                                                    : specs.front().name + ", ..., " + specs.back().name;
      throw_field_error(path, name, "expected a known shape parameter (" + known + ")");
    }
    const ParamSpec& s = space.specs()[static_cast<size_t>(index)];
    if (!value.is_number()) {
      std::ostringstream range;
      range << "expected a scale in [" << s.lower << ", " << s.upper << "], got " << value.dump();
      throw_field_error(path, name, range.str());
    }
    scales[index] = value.get<double>();
  }
  space.validate(scales, path);
  return with_shape(p, scales);
}

std::shared_ptr<const ShapedScene> TaskEvaluator::shaped_scene(const Eigen::VectorXd& scales,
                                                               const std::string& origin) const {
  const ShapeSpace& space = shapes();
  auto scene = std::make_shared<ShapedScene>();
  scene->scales = scales;
  scene->model = space.compile(scales, origin);  // validates
  scene->link_lengths = space.link_lengths(scales);
  scene->standing = space.standing(scales);
  Character body = bind_character(task_.character_spec, scene->model->get(), origin);
  body.strength = task_.strength;
  scene->body = std::make_shared<const Character>(std::move(body));
  return scene;
}

Evaluation TaskEvaluator::evaluate(const std::vector<double>& values, const ShapedScene& scene,
                                   SimWorker& worker, const EvaluationOptions& options) const {
  if (&worker.shared() != scene.model.get()) {
    throw std::logic_error("TaskEvaluator::evaluate: worker does not run the shaped scene");
  }
  Evaluation e = evaluate_on(values, *scene.body, worker, options);
  if (scene.below_floor()) {
    // The contact is seen at the first step already; stating it here keeps the outcome
    // (the earliest fall, with its reason) independent of how the contact plays out.
    std::ostringstream why;
    why.precision(3);
    why << "the shape starts with a hand or arm " << scene.standing.feet_z - scene.standing.lowest_other_z
        << " m below the floor";
    e.summary.fell = true;
    e.summary.fall_reason = why.str();
    e.summary.fall_progress = 0;
    e.poses.clear();
    e.report = evaluate_constraints(task_, e.summary);
    e.constraint = e.report.total;
    e.fell = true;
  }
  return e;
}

Evaluation TaskEvaluator::evaluate_named(const ParameterSet& params, const EvaluationOptions& options,
                                         std::shared_ptr<const SharedModel>* model_out) const {
  const std::vector<double> control = control_values(params);
  if (!holds_shape(params)) {
    const auto worker = make_worker();
    if (model_out) *model_out = model_;
    return evaluate(control, *worker, options);
  }
  const auto scene = shaped_scene(shapes().scales_from(params));
  SimWorker worker(scene->model);
  if (model_out) *model_out = scene->model;
  return evaluate(control, *scene, worker, options);
}

std::vector<PoseSample> TaskEvaluator::sample_poses(const Evaluation& e, int phase,
                                                    const std::vector<double>& taus,
                                                    SimWorker& worker) const {
  return flight_poses(*body_, e, phase, taus, worker);
}

Eigen::VectorXd TaskEvaluator::link_masses() const {
  Eigen::VectorXd masses(static_cast<int>(body_->links.size()));
  for (size_t k = 0; k < body_->links.size(); ++k) masses[static_cast<int>(k)] = model_->get()->body_mass[body_->links[k]];
  return masses;
}

std::vector<std::string> TaskEvaluator::link_names() const {
  std::vector<std::string> names;
  for (int b : body_->links) names.push_back(mj_id2name(model_->get(), mjOBJ_BODY, b));
  return names;
}

std::vector<std::string> TaskEvaluator::angle_names() const {
  std::vector<std::string> names;
  for (const CharacterJoint& j : body_->joints) names.push_back(j.name);
  return names;
}

Eigen::Quaterniond root_orientation(const Character& body, const double* qpos) {
  if (body.root == RootKind::kPlanar) {
    // Every planar hinge turns about -y.
    return Eigen::Quaterniond(Eigen::AngleAxisd(qpos[body.root_pitch_qpos], -Eigen::Vector3d::UnitY()));
  }
  const double* q = qpos + body.root_qpos + 3;  // w x y z
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized();
}

}  // namespace diverse
