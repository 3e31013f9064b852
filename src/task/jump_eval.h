// The rollout observer of a jump task: drives the jump controller, records the flight,
// measures what the constraints judge (peak COM height, the feet at touch-down and at
// rest, the root's rotation about pitch, roll and the vertical, the forward pitch; each
// listed constraint's own measures through task/rollout_terms.h), detects falls, and ends
// the rollout as soon as the outcome is decided: a fall, the character at rest
// settle_time after landing, or a time cap. TaskEvaluator (task/evaluate.h) uses it for
// every task without a [walk] table; task/walk_eval.h is its twin for walks.
//
// Falls: a contact of a body other than the feet with the ground or an object (unless
// constraints.allow_contact lists it), the COM within fall_com_height of the feet, the
// root tilting beyond fall_tilt on the ground, a hop before the jump (hop_is_fall), a
// topple over the edge of the feet (topple_distance), never leaving the ground, not
// landing in time, or not coming to rest after landing.
//
// Pose samples for the distance metrics (paper section 4, SPEC 2.3): the airborne
// states are recorded every step from take-off to landing, so poses can be sampled at any
// phase-normalized time of the two airborne phases (take-off to peak, peak to landing):
// `samples` per phase at (k + 0.5) / samples, for a jump that took off and landed.
#pragma once

#include <mujoco/mujoco.h>

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

// A free root's turn about the world's axes since the start, unwrapped (rad): its world
// angular velocity about each axis integrated step by step, so a full turn gives 2 pi and
// two give 4 pi. pitch about -y (positive backwards), roll about x (positive turning the
// left side up), vertical about z (positive turning left seen from above).
struct RootTurn {
  double pitch = 0, roll = 0, vertical = 0;
  // One step of `dt` s: R the root's world orientation (row-major 3x3, mjData::xmat),
  // w its angular velocity in its own frame (a free joint's qvel[3..5]).
  void add_step(const double* R, const double* w, double dt);
};

class JumpObserver : public TaskObserver {
 public:
  // `out` receives the summary (out.summary) and the flight record (out.flight_time,
  // out.flight_qpos). With end_when_decided the jump ends once it has landed where it can
  // no longer meet the task.
  JumpObserver(const Task& task, const Character& body, const mjModel* m, Controller& controller,
               JointDrive& drive, RolloutTerms& terms, int samples, bool end_when_decided, Evaluation& out);

  bool observe(const mjModel* m, const mjData* d) override;

  // The pose samples of the flight. Empty unless the jump took off and landed.
  std::vector<PoseSample> poses(SimWorker& worker) const override;

 private:
  double progress(double t) const;                        // how far the motion got, [0, 1]
  double forward_pitch(const mjData* d, double pitch) const;  // rad, from standing
  double tilt(const mjData* d, double pitch) const;       // rad, from standing upright
  double feet_mean(const mjData* d, int axis) const;      // m, of the two foot centres
  double root_pitch(const mjModel* m, const mjData* d);   // rad, unwrapped
  bool fall(double t, const char* why, const mjData* d, bool landed_fully = false);
  bool finish(double t, const mjData* d);
  void decide_if(bool cannot_meet) {
    if (cannot_meet && decided_ < 0) decided_ = index_;
  }

  const int rise_, fall_, land_;  // the controller's airborne phases and landing
  const int extend_;              // its push-off phase (-1: none)
  double off_since_ = -1;   // before the extend: time the last contact was lost, -1 if touching
  double still_since_ = -1;  // s: slow and balanced since then, without a break (-1: not now)
  double pitch0_ = 0, pitch_takeoff_ = 0, last_pitch_ = 0;
  RootTurn turn_, turn_takeoff_;  // a free root's turn since the start, and at take-off
  double up0_[3] = {0, 0, 1}, fwd0_[3] = {1, 0, 0};  // free root: standing axes in its frame
  double elevation0_ = 0;                            // rad, the standing forward axis's
};

// Poses at phase-normalized times `taus` of airborne phase `phase` (0: take-off to peak,
// 1: peak to landing) of an evaluation with a flight, on `body`'s model (the worker's).
// Uses the worker's mjData as scratch; throws std::logic_error without a flight.
std::vector<PoseSample> flight_poses(const Character& body, const Evaluation& e, int phase,
                                     const std::vector<double>& taus, SimWorker& worker);

}  // namespace diverse
