#include "task/evaluate.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "core/error.h"
#include "core/text_file.h"
#include "task/foot_slip.h"
#include "task/scene_check.h"
#include "task/support.h"
#include "task/walk_eval.h"

namespace diverse {
namespace {

// Drives the controller and watches the motion until its outcome is decided.
class JumpHooks : public StepHooks {
 public:
  JumpHooks(const Task& task, const Character& body, Controller& controller, JointDrive& drive,
            int obstacle_geom, bool end_when_decided, Evaluation& out)
      : task_(task), body_(body), controller_(controller), drive_(drive), obstacle_(obstacle_geom),
        end_when_decided_(end_when_decided), out_(out), rise_(controller.phase_times().rise), fall_(controller.phase_times().fall),
        land_(controller.phase_times().land), extend_(controller.phase_times().extend) {
    out_.summary.min_clearance = task.simulation.clearance_range;
  }

  void control(mjModel* m, mjData* d) override {
    contacts_ = scan_contacts(m, d, body_);
    if (first_) controller_.reset(m, d);
    controller_.control(m, d, contacts_, drive_);
  }

  // Observed steps from which the motion could no longer meet the task (-1: none yet).
  long decided_at() const { return decided_; }
  long observed() const { return index_; }

  bool observe(const mjModel* m, const mjData* d) override {
    MotionSummary& s = out_.summary;
    const double t = d->time;
    ++index_;
    const double pitch = root_pitch(m, d);
    last_pitch_ = pitch;
    const int phase = controller_.phase();
    const bool changed = controller_.phase_changed();
    if (first_) {
      pitch0_ = pitch;
      first_ = false;
      s.standing_com_z = controller_.com()[2];
      if (body_.root == RootKind::kFree) {
        // The root's standing "up" and forward axes in its own frame (from qpos0).
        const double* q0 = m->qpos0 + body_.root_qpos + 3;
        const double inv[4] = {q0[0], -q0[1], -q0[2], -q0[3]};
        const double z[3] = {0, 0, 1}, x[3] = {1, 0, 0};
        mju_rotVecQuat(up0_, z, inv);
        double fwd0[3];
        mju_rotVecQuat(fwd0, x, inv);
        // Forward pitch is measured against the standing forward axis's elevation.
        double w[3];
        mju_rotVecQuat(w, fwd0, q0);
        elevation0_ = std::atan2(w[2], std::hypot(w[0], w[1]));
        for (int i = 0; i < 3; ++i) fwd0_[i] = fwd0[i];
      }
    }
    s.max_forward_pitch = std::max(s.max_forward_pitch, forward_pitch(d, pitch));
    const double com_z = controller_.com()[2];

    // Events.
    if (phase == rise_ && changed) {
      s.took_off = true;
      pitch_takeoff_ = pitch;
    }
    const bool airborne = phase == rise_ || phase == fall_;
    if (airborne || (phase == land_ && changed && s.took_off)) {
      out_.flight_time.push_back(t);
      out_.flight_qpos.insert(out_.flight_qpos.end(), d->qpos, d->qpos + m->nq);
    }
    if (airborne) s.peak_com_z = std::max(s.peak_com_z, com_z);
    if (phase == fall_ && changed) decide_if(peak_bound(task_, s) > 0);  // the peak is behind
    if (phase == land_ && changed) {
      if (!s.took_off || controller_.gave_up()) return fall(t, "never left the ground", d);
      s.landed = true;
      s.rotation_flight = pitch - pitch_takeoff_;
      s.touchdown_feet_x = feet_mean(d, 0);
      s.touchdown_feet_y = feet_mean(d, 1);
      s.touchdown_feet_z = feet_mean(d, 2);
      decide_if(touchdown_bound(task_, s) > 0);
    }

    // Obstacle proximity (contacts in the margin gap included).
    if (obstacle_ >= 0) {
      for (int i = 0; i < d->ncon; ++i) {
        const mjContact& c = d->contact[i];
        if (c.geom1 == obstacle_ || c.geom2 == obstacle_) {
          s.min_clearance = std::min(s.min_clearance, c.dist);
        }
      }
    }

    // Constraints that can only get worse: obstacle clearance and forward pitch.
    const TaskConstraints& c = task_.constraints;
    decide_if((c.clearance && s.min_clearance < c.min_clearance) ||
              (c.pitch && s.max_forward_pitch > c.max_pitch));
    if (end_when_decided_ && decided_ >= 0 && s.landed) {
      finish(t, d);
      s.ended_decided = true;
      s.rotation_total = 2 * M_PI * c.rotation_turns;
      return true;
    }

    // A hop before the jump: off the ground in a phase before the extend.
    if (task_.simulation.hop_is_fall && extend_ >= 0 && phase < extend_) {
      if (contacts_.any) {
        off_since_ = -1;
      } else if (off_since_ < 0) {
        off_since_ = t;
      } else if (t - off_since_ >= 0.02 - 1e-9) {
        return fall(t, "left the ground before the jump", d);
      }
    }

    // Falls.
    if (contacts_.non_foot) return fall(t, "a body other than the feet touched the ground or an object", d);
    if (!airborne) {
      const double feet_z = feet_mean(d, 2);
      if (com_z - feet_z < task_.simulation.fall_com_height) {
        return fall(t, "the centre of mass dropped to the feet", d);
      }
      if (task_.simulation.fall_tilt > 0 && tilt(d, pitch) > task_.simulation.fall_tilt) {
        return fall(t, "the body tipped over", d);
      }
      // A topple: both feet down, past the landing's first topple_after seconds, and the
      // COM and its capture point both topple_distance outside the soles.
      const TaskSimulation& rules = task_.simulation;
      if (rules.topple_distance > 0 && s.landed && contacts_.foot[0] && contacts_.foot[1] &&
          t - controller_.phase_times().landing() >= rules.topple_after - 1e-9) {
        const auto& x = controller_.com();
        const auto& v = controller_.com_velocity();
        const double g = std::max(1e-9, std::fabs(m->opt.gravity[2]));
        const double tc = std::sqrt(std::max(0.0, x[2] - feet_z) / g);
        const SoleOutline soles = sole_outline(m, d, body_, contacts_);
        if (soles.margin({x[0], x[1]}) < -rules.topple_distance &&
            soles.margin({x[0] + v[0] * tc, x[1] + v[1] * tc}) < -rules.topple_distance) {
          // Ranked as the fall it would become: most topples lie on the ground a second
          // or more after touch-down, where a fall's progress is full.
          return fall(t, "toppled over the edge of the feet", d, /*landed_fully=*/true);
        }
      }
    }

    // End of the motion.
    const TaskSimulation& sim = task_.simulation;
    if (s.landed) {
      const double since = t - controller_.phase_times().landing();
      const auto& v = controller_.com_velocity();
      // At rest: slow, and (balanced_rest) slow with the capture point over the feet for
      // the last rest_hold seconds.
      const bool slow = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) < sim.settle_speed;
      bool rest = slow;
      if (sim.balanced_rest) {
        const bool still = slow && capture_point_margin(m, d, body_, controller_.com(), v) >= 0;
        if (!still) {
          still_since_ = -1;
        } else if (still_since_ < 0) {
          still_since_ = t;
        }
        rest = still && t - still_since_ >= sim.rest_hold - 0.5 * m->opt.timestep;
      }
      if (since >= sim.settle_time && rest) {
        s.settled = true;
        return finish(t, d);
      }
      if (since >= sim.settle_max) return fall(t, "did not come to rest after landing", d);
    }
    if (t + m->opt.timestep > sim.max_time) {
      return fall(t, s.took_off ? "did not land in time" : "never left the ground", d);
    }
    return false;
  }

 private:
  // How far the motion got: the phase reached, then the time at rest after landing.
  double progress(double t) const {
    const int phase = controller_.phase();
    const double phases = static_cast<double>(controller_.phase_times().begin.size());
    if (phase == land_ && out_.summary.landed) {
      const double since = t - controller_.phase_times().landing();
      return (land_ + std::min(1.0, since / task_.simulation.settle_time)) / phases;
    }
    return static_cast<double>(std::min(phase, land_)) / phases;
  }

  // The root's forward pitch from standing (rad, positive forward): the planar root's
  // hinge (positive backwards), or a free root's forward axis's elevation below standing.
  double forward_pitch(const mjData* d, double pitch) const {
    if (body_.root == RootKind::kPlanar) return -(pitch - pitch0_);
    double w[3];
    mju_mulMatVec(w, d->xmat + 9 * body_.root_body, fwd0_, 3, 3);
    return elevation0_ - std::atan2(w[2], std::hypot(w[0], w[1]));
  }

  // The root's tilt from standing upright (rad).
  double tilt(const mjData* d, double pitch) const {
    if (body_.root == RootKind::kPlanar) return std::fabs(pitch - pitch0_);
    double up[3];
    mju_mulMatVec(up, d->xmat + 9 * body_.root_body, up0_, 3, 3);
    return std::acos(std::clamp(up[2], -1.0, 1.0));
  }

  // Mean over the two feet's centres of mass of world coordinate `axis` (0 = x, 2 = z).
  double feet_mean(const mjData* d, int axis) const {
    return 0.5 * (d->xipos[3 * body_.feet[0] + axis] + d->xipos[3 * body_.feet[1] + axis]);
  }

  // The root's pitch (rad, positive backwards), unwrapped over the motion: the planar
  // root's hinge angle, or for a free root the integral of its world angular velocity
  // about -y (a full backward turn gives 2 pi).
  double root_pitch(const mjModel* m, const mjData* d) {
    if (body_.root == RootKind::kPlanar) return d->qpos[body_.root_pitch_qpos];
    if (!first_) {
      const double* w = d->qvel + body_.root_dof + 3;  // body frame
      const double* R = d->xmat + 9 * body_.root_body;
      const double wy = R[3] * w[0] + R[4] * w[1] + R[5] * w[2];
      free_pitch_ += -wy * m->opt.timestep;
    }
    return free_pitch_;
  }

  // `landed_fully`: the fall's progress is that of a fall settle_time or more after
  // touch-down, whenever it is called.
  bool fall(double t, const char* why, const mjData* d, bool landed_fully = false) {
    MotionSummary& s = out_.summary;
    s.fell = true;
    s.fall_reason = why;
    s.fall_progress = landed_fully ? (land_ + 1.0) / static_cast<double>(controller_.phase_times().begin.size())
                                   : progress(t);
    return finish(t, d);
  }

  bool finish(double t, const mjData* d) {
    MotionSummary& s = out_.summary;
    s.end_time = t;
    s.feet_x = feet_mean(d, 0);
    s.feet_y = feet_mean(d, 1);
    s.feet_z = feet_mean(d, 2);
    if (!s.landed) {  // never touched down: the end position stands for both
      s.touchdown_feet_x = s.feet_x;
      s.touchdown_feet_y = s.feet_y;
      s.touchdown_feet_z = s.feet_z;
    }
    s.rotation_total = last_pitch_ - pitch0_;
    return true;
  }

  const Task& task_;
  const Character& body_;
  Controller& controller_;
  JointDrive& drive_;
  int obstacle_;
  bool end_when_decided_;
  Evaluation& out_;
  const int rise_, fall_, land_;  // the controller's airborne phases and landing
  const int extend_;              // its push-off phase (-1: none)
  ContactState contacts_;
  double off_since_ = -1;   // before the extend: time the last contact was lost, -1 if touching
  void decide_if(bool cannot_meet) {
    if (cannot_meet && decided_ < 0) decided_ = index_;
  }

  bool first_ = true;
  double still_since_ = -1;  // s: slow and balanced since then, without a break (-1: not now)
  long index_ = 0, decided_ = -1;  // steps observed; when the outcome was decided
  double pitch0_ = 0, pitch_takeoff_ = 0, last_pitch_ = 0, free_pitch_ = 0;
  double up0_[3] = {0, 0, 1}, fwd0_[3] = {1, 0, 0};  // free root: standing axes in its frame
  double elevation0_ = 0;                            // rad, the standing forward axis's
};

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

// A rollout's hooks that also measure its foot slip (TaskConstraints::foot_slip), step by
// step as a replay of its record would (task/foot_slip.h); without a meter they only
// forward.
class MeteredHooks : public StepHooks {
 public:
  MeteredHooks(StepHooks& inner, FootSlipMeter* meter) : inner_(inner), meter_(meter) {}
  void control(mjModel* m, mjData* d) override { inner_.control(m, d); }
  bool observe(const mjModel* m, const mjData* d) override { return inner_.observe(m, d); }
  void stepped(const mjModel* m, const mjData* d) override {
    if (meter_ != nullptr) meter_->after_step(m, d);
    inner_.stepped(m, d);
  }

 private:
  StepHooks& inner_;
  FootSlipMeter* meter_;
};

// Runs a rollout with a task's hooks (under the suite's push, if any) and fills in what
// every kind of task reports of it: the rollout's stats, phases and failure, C, and when
// the outcome was decided (Hooks: JumpHooks or WalkObserver).
template <class Hooks>
void simulate(const Task& task, const Character& body, const Controller& controller, JointDrive& drive,
              Hooks& hooks, int max_steps, SimWorker& worker, const EvaluationOptions& options, Evaluation& e) {
  std::optional<FootSlipMeter> meter;
  if (task.constraints.foot_slip) meter.emplace(worker.model(), foot_geom_sides(worker.model(), body));
  MeteredHooks metered(hooks, meter ? &*meter : nullptr);
  if (options.push.time >= 0) {
    PushHooks pushed(metered, body, options.push, e);
    e.stats = run_rollout(worker, pushed, max_steps, drive, options.recorder);
  } else {
    e.stats = run_rollout(worker, metered, max_steps, drive, options.recorder);
  }
  if (meter) e.summary.foot_slip = meter->finish().largest();
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
  if (task_.constraints.clearance) {
    obstacle_geom_ = mj_name2id(model_->get(), mjOBJ_GEOM, task_.constraints.clearance_object.c_str());
  }
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
  JumpHooks hooks(task_, body, controller, drive, obstacle_geom_, options.end_when_decided, e);
  const int max_steps = static_cast<int>(std::ceil(task_.simulation.max_time / m->opt.timestep)) + 1;
  simulate(task_, body, controller, drive, hooks, max_steps, worker, options, e);
  if (!e.failed && options.samples_per_phase > 0 && e.has_flight() && e.summary.landed) {
    std::vector<double> taus;
    for (int k = 0; k < options.samples_per_phase; ++k) {
      taus.push_back((k + 0.5) / options.samples_per_phase);
    }
    for (int phase = 0; phase < 2; ++phase) {
      auto poses = sample_poses(e, phase, taus, worker);
      e.poses.insert(e.poses.end(), poses.begin(), poses.end());
    }
  }
  return e;
}

Evaluation TaskEvaluator::evaluate_walk(Controller& controller, JointDrive& drive, const Character& body,
                                        SimWorker& worker, const EvaluationOptions& options) const {
  Evaluation e;
  mjModel* m = worker.model();
  WalkObserver hooks(task_, body, m, controller, drive, options.samples_per_phase, options.end_when_decided, e);
  const int max_steps = static_cast<int>(std::ceil(task_.walk.max_time / m->opt.timestep)) + 1;
  simulate(task_, body, controller, drive, hooks, max_steps, worker, options, e);
  if (!e.failed && options.samples_per_phase > 0) e.poses = hooks.poses(worker);
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
  if (!e.has_flight() || e.flight_time.empty()) {
    throw std::logic_error("sample_poses: the evaluation has no flight");
  }
  const mjModel* m = worker.model();
  mjData* d = worker.data();
  const int nq = m->nq;
  const double a = phase == 0 ? e.phases.takeoff() : e.phases.peak();
  const double b = phase == 0 ? e.phases.peak() : e.phases.landing();
  std::vector<PoseSample> out;
  for (double tau : taus) {
    const double t = a + std::clamp(tau, 0.0, 1.0) * (b - a);
    // Bracketing recorded states; linear interpolation (hinges and slides; a free root's
    // quaternion is interpolated linearly and normalized, exact enough between two steps).
    const auto& ts = e.flight_time;
    size_t hi = std::lower_bound(ts.begin(), ts.end(), t) - ts.begin();
    hi = std::min(hi, ts.size() - 1);
    const size_t lo = hi > 0 ? hi - 1 : 0;
    const double w = (hi == lo || ts[hi] == ts[lo]) ? 1.0 : std::clamp((t - ts[lo]) / (ts[hi] - ts[lo]), 0.0, 1.0);
    for (int i = 0; i < nq; ++i) {
      d->qpos[i] = (1 - w) * e.flight_qpos[lo * nq + i] + w * e.flight_qpos[hi * nq + i];
    }
    if (body_->root == RootKind::kFree) mju_normalize4(d->qpos + body_->root_qpos + 3);
    mj_kinematics(m, d);
    PoseSample p;
    p.phase = phase;
    p.phase_time = tau;
    p.time = t;
    p.link_com.resize(3, static_cast<int>(body_->links.size()));
    for (size_t k = 0; k < body_->links.size(); ++k) {
      for (int c = 0; c < 3; ++c) p.link_com(c, static_cast<int>(k)) = d->xipos[3 * body_->links[k] + c];
    }
    p.angles.resize(static_cast<int>(body_->joints.size()));
    for (size_t k = 0; k < body_->joints.size(); ++k) p.angles[static_cast<int>(k)] = d->qpos[body_->joints[k].qpos];
    p.root = root_orientation(*body_, d->qpos);
    out.push_back(std::move(p));
  }
  return out;
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
