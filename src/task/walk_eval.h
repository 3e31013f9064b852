// The rollout observer of a walk task (task/walk_task.h): drives the walk controller,
// counts steps, measures each step's length in the heading frame and the pelvis and torso
// tilt, detects falls, and ends the rollout as soon as the outcome is decided (a fall, or
// the last step's touch-down). Steps are found from the feet's contacts, by the rule of
// the walk audit (task/walk_audit.h), so the task and the audit count the same steps.
// TaskEvaluator (task/evaluate.h) uses it for every task with a [walk] table;
// task/jump_eval.h is its twin for jumps. The constraints the task lists (a foot-slip
// bound) measure through task/rollout_terms.h, as a jump's do.
//
// Pose samples (paper section 4.1): in every evaluated stride (the controller's strides
// after its first settle_steps strike states; a stride is the four states left lift, left strike, right
// lift, right strike) each state gives `samples` poses at its state-normalized times
// (k + 0.5) / samples, interpolated between the bracketing simulation steps:
// 4 * samples * (steps - settle_steps) / 2 poses for a walk that takes all its steps, none
// otherwise. PoseSample::phase is the state (0 to 3). The poses are in the stride's heading
// frame: link positions and the root orientation are turned about the vertical by minus
// the root's heading (from standing) at the touch-down that began the stride, so a gait
// walked in another direction gives the same poses, while the root's sway within a stride
// stays in them.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <vector>

#include "character/character.h"
#include "control/controller.h"
#include "physics/drive.h"
#include "physics/model.h"
#include "physics/rollout.h"
#include "task/evaluate.h"
#include "task/rollout_terms.h"
#include "task/task.h"

namespace diverse {

class WalkObserver : public TaskObserver {
 public:
  // `m` is the model the rollout runs (standing orientations are read from it); `out`
  // receives the summary (out.summary: fell, walk steps). With end_when_decided the walk
  // ends at the step that first breaks the task's rules.
  WalkObserver(const Task& task, const Character& body, const mjModel* m, Controller& controller,
               JointDrive& drive, RolloutTerms& terms, int samples, bool end_when_decided, Evaluation& out);

  bool observe(const mjModel* m, const mjData* d) override;

  // The pose samples of the evaluated strides. Empty unless the walk took all its steps.
  std::vector<PoseSample> poses(SimWorker& worker) const override;

 private:
  bool fall(const mjData* d, const char* why);
  double heading(const mjData* d) const;  // rad, of the root, relative to standing
  double tilt(const mjData* d, int body, const std::array<double, 3>& up) const;
  void close_state(int state);           // samples of the state that just ended

  int torso_ = -1;                     // body tracked for uprightness besides the root, or -1
  std::array<double, 3> root_up_{0, 0, 1}, torso_up_{0, 0, 1};  // standing "up" in each body's frame
  double standing_heading_ = 0;
  double heading_ = 0, last_raw_heading_ = 0;  // unwrapped
  double tilt_ = 0;                     // rad, largest since the last step
  double flight_start_ = -1;            // s, when both feet last left the ground; -1 if one is down
  // Steps from contacts.
  std::array<bool, 2> ground_{true, true};  // each foot on something not the character
  std::array<std::array<double, 2>, 2> footprint_{};  // m: each foot's body origin (x, y) at its last touch-down
  std::array<double, 2> lifted_{0, 0};   // s (index x timestep), when each foot last left it
  int last_leg_ = -1;                    // the foot that made the last step
  int strikes_ = 0;                      // strike states ended by a touch-down
  int nq_ = 0;
  // Recording the evaluated strides.
  bool recording_ = false;
  bool complete_ = false;
  int state_ = 0;
  std::vector<double> state_time_, state_qpos_;   // the current state's steps
  std::vector<int> sample_state_;                  // per sample: its state
  std::vector<double> sample_tau_, sample_time_, sample_qpos_;
  std::vector<double> sample_heading_;             // per sample: its stride's heading (rad)
  double stride_heading_ = 0;                      // rad, at the touch-down that began the stride
};

}  // namespace diverse
