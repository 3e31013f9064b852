// "spotting": spotting the landing of a flip, as a gymnast does, opening out of the tuck
// when the floor comes into view. The module keeps the body's turn since the phase began
// (take-off): its mean pitch rate, the angular momentum about the COM over the inertia
// there (physics/centroidal.h), integrated step by step. The `spotted` transition condition
// holds when the body, opened now, would have turned `turn` by touch-down: what the
// momentum, constant in flight, turns it through while opening over `open_time` (the
// inertia going from the tuck's to the open body's, the mean of the two rates) and then
// open, with the inertia it had at take-off, until the COM is back at its take-off
// height; or when touch-down is no more than `open_time` away. A flip that took off with
// less spin stays tucked longer, one with more opens sooner.
//
// Settings: turn (rad), open_time (s). Planar characters.
#pragma once

#include "control/skill_module.h"
#include "physics/centroidal.h"

namespace diverse {

class SpottingModule : public SkillModule {
 public:
  explicit SpottingModule(const ModuleSettings& settings);
  void reset(const mjModel* m, const mjData* d, SkillState& s) override;
  void enter(const mjModel* m, const mjData* d, SkillState& s) override;
  void update(const mjModel* m, const mjData* d, SkillState& s) override;
  bool spotted(const SkillState& s) const override;

 private:
  double turn_, open_time_;
  CentroidalPitchOf centroidal_;  // of the character's subtree, set by reset()
  // The inertia about the COM at take-off (kg m^2), the turn since (rad), when that was
  // last brought up to date (s) and the spin in this step.
  double takeoff_inertia_ = 0, flight_turn_ = 0, spin_time_ = 0;
  CentroidalPitch spin_;
};

}  // namespace diverse
