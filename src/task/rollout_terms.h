// What the constraints a task lists measure in one rollout (task/term.h), and what the
// jump's and the walk's rollout observers share (TaskObserver: task/jump_eval.h,
// task/walk_eval.h): both hold one RolloutTerms and call it at the same points, so a
// constraint observes a rollout the same way in both.
#pragma once

#include <mujoco/mujoco.h>

#include <memory>
#include <vector>

#include "character/character.h"
#include "control/controller.h"
#include "physics/drive.h"
#include "physics/model.h"
#include "physics/rollout.h"
#include "task/constraints.h"
#include "task/task.h"
#include "task/term.h"

namespace diverse {

struct Evaluation;
struct PoseSample;

class RolloutTerms {
 public:
  // For a rollout of `task` on model `m` (the task's scene or a shaped one) and `body`
  // bound to it.
  RolloutTerms(const Task& task, const mjModel* m, const Character& body);

  // Every observed step, after the step's events are in `s` (TermObserver::observe).
  void observe(const mjModel* m, const mjData* d, MotionSummary& s);
  // After every simulation step (TermObserver::stepped).
  void stepped(const mjModel* m, const mjData* d);
  // Once, when the rollout has ended (TermObserver::finish).
  void finish(MotionSummary& s);

  // A contact that is a fall, given that some body other than the feet touches something
  // (ContactState::non_foot): one of a body that constraints.allow_contact does not list.
  bool contact_is_fall(const mjModel* m, const mjData* d) const;

 private:
  const Character& body_;
  std::vector<std::unique_ptr<TermObserver>> observers_;
  std::vector<int> allowed_;  // body ids that may touch
};

// The rollout observer of a kind of task: drives the controller, watches the motion
// step by step into `out` (its summary, C's inputs) and ends the rollout when its outcome
// is decided. JumpObserver and WalkObserver are its two kinds, one file each.
class TaskObserver : public StepHooks {
 public:
  // With end_when_decided the rollout ends once the motion can no longer meet the task
  // (EvaluationOptions::end_when_decided; MotionSummary::ended_decided). `samples`: pose
  // samples per phase (a walk: per state).
  TaskObserver(const Task& task, const Character& body, Controller& controller, JointDrive& drive,
               RolloutTerms& terms, int samples, bool end_when_decided, Evaluation& out)
      : task_(task), body_(body), controller_(controller), drive_(drive), terms_(terms), samples_(samples),
        end_when_decided_(end_when_decided), out_(out) {}

  // Reads the contacts and drives the controller (reset at the first step).
  void control(mjModel* m, mjData* d) override {
    contacts_ = scan_contacts(m, d, body_);
    if (first_) controller_.reset(m, d);
    controller_.control(m, d, contacts_, drive_);
  }

  // The pose samples of the motion for the distance metrics, after the rollout (uses the
  // worker's mjData as scratch); empty unless the motion did what its samples need.
  virtual std::vector<PoseSample> poses(SimWorker& worker) const = 0;

  // Steps observed, and from which the motion could no longer meet the task (-1: none).
  long observed() const { return index_; }
  long decided_at() const { return decided_; }

 protected:
  const Task& task_;
  const Character& body_;
  Controller& controller_;
  JointDrive& drive_;
  RolloutTerms& terms_;
  int samples_;
  bool end_when_decided_;
  Evaluation& out_;
  ContactState contacts_;
  bool first_ = true;   // before the first observed step
  long index_ = 0;      // steps observed
  long decided_ = -1;   // index_ when the outcome was decided, or -1
};

}  // namespace diverse
