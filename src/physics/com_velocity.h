// The velocity of a subtree's centre of mass, as a controller reads it every step.
//
// mj_subtreeVel computes, for every body, its subtree's linear velocity AND angular
// momentum; the angular momenta are most of its cost and no controller here reads them.
// SubtreeComVelocity computes the one subtree's linear velocity with the same MuJoCo
// operations in the same order as mj_subtreeVel (MuJoCo 2.2, engine_core_smooth.c): each
// body's momentum m_b v_b, children's momenta added to their parents in decreasing body id,
// divided by the subtree's mass. The result is bit for bit what mj_subtreeVel leaves in
// d->subtree_linvel (tests/physics/com_velocity_test.cc), so swapping one for the other
// changes no motion. It reads what mj_step1 computed (xipos, cvel, subtree_com) and writes
// nothing to mjData.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <vector>

namespace diverse {

class SubtreeComVelocity {
 public:
  SubtreeComVelocity() = default;
  // The subtree of body `root` of `m`.
  SubtreeComVelocity(const mjModel* m, int root);

  // The subtree's centre-of-mass velocity (world frame, m/s) in state `d`.
  std::array<double, 3> operator()(const mjModel* m, const mjData* d);

 private:
  int root_ = -1;
  std::vector<int> bodies_;        // the subtree's bodies, root first, increasing id
  std::vector<mjtNum> momentum_;   // 3 per body of the model
};

}  // namespace diverse
