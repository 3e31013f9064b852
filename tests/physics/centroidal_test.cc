// CentroidalPitchOf against MuJoCo: its momentum is mj_subtreeVel's angular momentum of the
// planar human about its COM (the pitch component), and in a free flight of the human
// the momentum holds while the inertia follows the pose.
#include "physics/centroidal.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/rng.h"
#include "physics/com_velocity.h"
#include "task/evaluate.h"

namespace diverse {
namespace {

const std::string kTasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";

TEST(CentroidalPitch, MomentumIsMujocosAngularMomentumAboutTheCom) {
  const TaskEvaluator evaluator(load_task(kTasks + "backflip.toml"));
  mjModel* m = mj_copyModel(nullptr, evaluator.model().get());
  mjData* d = mj_makeData(m);
  const int root = evaluator.body().root_body;
  const CentroidalPitchOf spin(m, root);
  SubtreeComVelocity com_velocity(m, root);
  Rng rng(3);
  for (int state = 0; state < 20; ++state) {
    mj_resetData(m, d);
    for (int j = 0; j < m->njnt; ++j)
      if (m->jnt_type[j] == mjJNT_HINGE) d->qpos[m->jnt_qposadr[j]] += 2 * rng.uniform() - 1;
    for (int k = 0; k < m->nv; ++k) d->qvel[k] = 5 * (2 * rng.uniform() - 1);
    mj_forward(m, d);
    const std::array<double, 3> v = com_velocity(m, d);
    const CentroidalPitch p = spin(m, d, d->subtree_com + 3 * root, v.data());
    mj_subtreeVel(m, d);
    // The planar root pitches about -y: backwards positive.
    EXPECT_NEAR(p.momentum, -d->subtree_angmom[3 * root + 1], 1e-9) << "state " << state;
    EXPECT_GT(p.inertia, 0);
  }
  mj_deleteData(d);
  mj_deleteModel(m);
}

// Thrown spinning into the air with the joints driven from a tuck to a stretch: the
// momentum stays what it was (the joints' small armature aside) while the inertia grows
// and the mean pitch rate falls with it.
TEST(CentroidalPitch, HoldsInFlightWhileTheInertiaFollowsThePose) {
  const TaskEvaluator evaluator(load_task(kTasks + "backflip.toml"));
  mjModel* m = mj_copyModel(nullptr, evaluator.model().get());
  mjData* d = mj_makeData(m);
  const Character& body = evaluator.body();
  const int root = body.root_body;
  const CentroidalPitchOf spin(m, root);
  SubtreeComVelocity com_velocity(m, root);
  mj_resetData(m, d);
  // A tuck: hips and knees bent far.
  auto tuck = [](const CharacterJoint& j) {
    if (j.name.find("hip") != std::string::npos) return 2.0;
    if (j.name.find("knee") != std::string::npos) return -2.2;
    return 0.0;
  };
  for (const CharacterJoint& j : body.joints) d->qpos[j.qpos] = tuck(j);
  d->qpos[body.root_z_qpos] += 3;  // far above the floor
  d->qvel[body.root_pitch_dof] = 8;
  mj_forward(m, d);
  std::array<double, 3> v = com_velocity(m, d);
  const CentroidalPitch first = spin(m, d, d->subtree_com + 3 * root, v.data());
  std::vector<double> momentum, inertia;
  for (int step = 0; step < 300; ++step) {
    const double stretch = std::min(1.0, d->time / 0.3);  // from a tuck to straight
    for (const CharacterJoint& j : body.joints) {
      const double q = d->qpos[j.qpos], qd = d->qvel[m->jnt_dofadr[j.joint]];
      const double goal = (1 - stretch) * tuck(j);
      d->ctrl[j.actuator] = 300 * (goal - q) - 20 * qd;
    }
    mj_step(m, d);
    mj_forward(m, d);
    v = com_velocity(m, d);
    const CentroidalPitch p = spin(m, d, d->subtree_com + 3 * root, v.data());
    momentum.push_back(p.momentum);
    inertia.push_back(p.inertia);
  }
  for (double l : momentum) EXPECT_NEAR(l, first.momentum, 0.03 * std::fabs(first.momentum));
  EXPECT_GT(std::fabs(first.momentum), 1);
  EXPECT_GT(inertia.back(), 1.5 * inertia.front());
  mj_deleteData(d);
  mj_deleteModel(m);
}

TEST(CentroidalPitch, NoSuchBodyIsRefused) {
  const TaskEvaluator evaluator(load_task(kTasks + "backflip.toml"));
  EXPECT_THROW(CentroidalPitchOf(evaluator.model().get(), -1), std::invalid_argument);
  EXPECT_THROW(CentroidalPitchOf(evaluator.model().get(), evaluator.model().get()->nbody), std::invalid_argument);
}

}  // namespace
}  // namespace diverse
