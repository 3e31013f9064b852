#include "control/module_spotting.h"

#include <algorithm>
#include <cmath>

namespace diverse {

SpottingModule::SpottingModule(const ModuleSettings& settings)
    : turn_(settings.get("turn", 0)), open_time_(settings.get("open_time", 0)) {}

void SpottingModule::reset(const mjModel* m, const mjData* d, SkillState& s) {
  (void)d;
  centroidal_ = CentroidalPitchOf(m, s.body->root_body);
}

void SpottingModule::enter(const mjModel* m, const mjData* d, SkillState& s) {
  takeoff_inertia_ = centroidal_(m, d, s.com.data(), s.com_vel.data()).inertia;
  flight_turn_ = 0;
  spin_time_ = s.time;
}

void SpottingModule::update(const mjModel* m, const mjData* d, SkillState& s) {
  spin_ = centroidal_(m, d, s.com.data(), s.com_vel.data());
  flight_turn_ += spin_.rate() * (s.time - spin_time_);
  spin_time_ = s.time;
}

bool SpottingModule::spotted(const SkillState& s) const {
  const double vz = s.com_vel[2];
  const double above = std::max(s.com[2] - s.takeoff_com_z, 0.0);
  const double t_down = (vz + std::sqrt(vz * vz + 2 * s.gravity * above)) / s.gravity;
  if (t_down <= open_time_ || spin_.inertia <= 0 || takeoff_inertia_ <= 0) return true;
  const double opening = open_time_;
  const double turn = spin_.momentum * (0.5 * opening * (1 / spin_.inertia + 1 / takeoff_inertia_) +
                                        (t_down - opening) / takeoff_inertia_);
  return flight_turn_ + turn >= turn_;
}

}  // namespace diverse
