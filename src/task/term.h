// Constraint terms: the constraints a task lists, each a small component of its own.
//
// A constraint kind (landing, on_box, clearance, min_length, peak_height, rotation, pitch,
// foot_slip; and fall and half_timestep, which set the task-wide rules of those names)
// reads its own keys, strictly, from a task file's [[constraints]] entry or from its
// table of the same name under [constraints] (docs/reference/task-file.md). What it reads
// is a Constraint: it says what it needs measured in the rollout (a TermObserver, called
// by the jump's and the walk's rollout observers at the same points, task/jump_eval.h and
// task/walk_eval.h), when the motion so far has broken it for good (which decides a
// rollout's outcome early), its terms of C (K_c d^2, SPEC 2.4) and its slack for the
// input-motion search (constraint_margin, task/constraints.h).
//
// The kinds are listed in task/builtin_terms.cc; a new kind is one file (term_<kind>.h
// and .cc beside this one) and one line there.
#pragma once

#include <mujoco/mujoco.h>

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace diverse {

class TomlReader;
struct Task;
struct TaskConstraints;
struct MotionSummary;
struct ConstraintReport;
struct Character;

// What one constraint measures in a rollout, beyond what the rollout's observer records
// in the MotionSummary for every task.
class TermObserver {
 public:
  virtual ~TermObserver() = default;
  // Every observed step, after the step's events (take-off, touch-down) are in `s` and
  // before the outcome is judged.
  virtual void observe(const mjModel* m, const mjData* d, MotionSummary& s) {
    (void)m, (void)d, (void)s;
  }
  // After every simulation step (mj_step), as a replay of the motion's record sees it.
  virtual void stepped(const mjModel* m, const mjData* d) { (void)m, (void)d; }
  // Once, when the rollout has ended.
  virtual void finish(MotionSummary& s) { (void)s; }
};

// The moments of a jump at which a constraint may be found broken for good.
enum class Moment {
  kStep,      // any observed step: what can only get worse (clearance, forward pitch)
  kPastPeak,  // the first step past the peak: the peak height
};

class Constraint {
 public:
  // `field`: where the task file gives it ("constraints.landing", "constraints[2]"), for
  // messages.
  explicit Constraint(std::string field) : field_(std::move(field)) {}
  virtual ~Constraint() = default;
  Constraint(const Constraint&) = default;
  Constraint& operator=(const Constraint&) = default;

  virtual const char* kind() const = 0;
  const std::string& field() const { return field_; }

  // Adds its terms of C (name, violation d, penalty) to `report`.
  virtual void penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const = 0;
  // Its slack (m; rotations count 0.2 m per rad), negative when violated; INFINITY when
  // it sets no bound the input-motion search can keep away from.
  virtual double margin(const Task& task, const MotionSummary& motion) const = 0;
  // True when the motion so far (`so_far`, observed up to `moment`) breaks it whatever
  // follows.
  virtual bool broken(const Task& task, const MotionSummary& so_far, Moment moment) const {
    (void)task, (void)so_far, (void)moment;
    return false;
  }
  // Sets what the summary knows only at rest to a value that meets it (a jump ended at
  // touch-down, TaskEvaluator's end_when_decided and touchdown_bound()).
  virtual void assume_met_at_rest(MotionSummary& s) const { (void)s; }
  // What it measures in a rollout on model `m`; nullptr: nothing beyond the summary.
  virtual std::unique_ptr<TermObserver> observer(const mjModel* m, const Character& body) const {
    (void)m, (void)body;
    return nullptr;
  }
  // Where the feet may end along x, for a constraint on where the character lands: the
  // scene check (task/scene_check.h) asks that some x meets every such range.
  virtual std::optional<std::pair<double, double>> feet_x_range(const Task& task) const {
    (void)task;
    return std::nullopt;
  }
  // Checks it against the whole task once it is read (the scene, the simulation rules);
  // throws UserError "FILE: FIELD: expected ...".
  virtual void check(const Task& task) const { (void)task; }

 private:
  std::string field_;
};

// A kind of constraint, by the name a task file gives it.
struct ConstraintKind {
  const char* name;
  const char* description;  // one line, for messages and docs
  bool walks;               // a walk task may list it
  bool repeats;             // may be listed more than once (its reader checks the repeats)
  // Reads the kind's own keys from `r` (never "kind": it is taken out) into `c`: adds its
  // Constraint to c.terms, or sets c's task-wide rules. `task` holds everything read
  // before the constraints (character, objects, simulation). Throws UserError.
  void (*read)(const TomlReader& r, const Task& task, TaskConstraints& c);
};

// Every kind this build knows (task/builtin_terms.cc).
std::vector<ConstraintKind> builtin_constraint_kinds();
// The kind of this name; throws UserError "WHERE: expected one of ..., got \"NAME\"".
const ConstraintKind& find_constraint_kind(const std::string& name, const std::string& where);

// The K_c of a term: the entry's `weight` when it gives one, else the task's.
double term_weight(const TomlReader& r, const TaskConstraints& c);

}  // namespace diverse
