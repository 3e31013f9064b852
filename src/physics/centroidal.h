// A planar character's spin in flight: its angular momentum about its own centre of mass
// and its moment of inertia there, both about the world's y axis, the axis a planar root
// pitches about.
//
// In flight the momentum is constant (no contact, gravity acts at the COM), and the
// inertia follows the pose: a tucked body turns fast, an open one slowly. A controller that
// knows both predicts how far the body will have turned by touch-down if it opened now,
// the way a gymnast times the opening of a flip (the skill engine's spotting module,
// control/module_spotting.h). It reads what mj_step1 computed (xipos, ximat, cvel,
// subtree_com) and writes nothing to mjData.
#pragma once

#include <mujoco/mujoco.h>

#include <vector>

namespace diverse {

struct CentroidalPitch {
  double momentum = 0;  // kg m^2/s about -y (a planar root's pitch axis, backwards positive)
  double inertia = 0;   // kg m^2 about y through the COM
  // The body's mean pitch rate (rad/s): what the whole body turns at, whatever its limbs do.
  double rate() const { return inertia > 0 ? momentum / inertia : 0; }
};

class CentroidalPitchOf {
 public:
  CentroidalPitchOf() = default;
  // The subtree of body `root` of `m`.
  CentroidalPitchOf(const mjModel* m, int root);

  // In state `d`, about the subtree's centre of mass `com` moving at `com_velocity`.
  CentroidalPitch operator()(const mjModel* m, const mjData* d, const double* com,
                             const double* com_velocity) const;

 private:
  std::vector<int> bodies_;  // the subtree's bodies
};

}  // namespace diverse
