// SubtreeComVelocity against mj_subtreeVel, bit for bit, on every character's model.
#include "physics/com_velocity.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "core/rng.h"
#include "task/evaluate.h"

namespace diverse {
namespace {

const std::string kTasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";

class ComVelocity : public ::testing::TestWithParam<const char*> {};

// Random states (joint angles within +-1 rad of the model's, velocities up to 5 per dof),
// and for each the velocity of every body's subtree.
TEST_P(ComVelocity, EqualsMjSubtreeVelBitForBit) {
  const TaskEvaluator evaluator(load_task(kTasks + GetParam()));
  mjModel* m = mj_copyModel(nullptr, evaluator.model().get());
  mjData* d = mj_makeData(m);
  mjData* reference = mj_makeData(m);
  Rng rng(7);
  int compared = 0;
  for (int state = 0; state < 20; ++state) {
    mj_resetData(m, d);
    for (int j = 0; j < m->njnt; ++j) {
      const int a = m->jnt_qposadr[j];
      if (m->jnt_type[j] == mjJNT_HINGE || m->jnt_type[j] == mjJNT_SLIDE) d->qpos[a] += (2 * rng.uniform() - 1);
    }
    for (int k = 0; k < m->nv; ++k) d->qvel[k] = 5 * (2 * rng.uniform() - 1);
    mj_forward(m, d);
    mj_copyData(reference, m, d);
    mj_subtreeVel(m, reference);
    const std::vector<mjtNum> before(d->subtree_linvel, d->subtree_linvel + 3 * m->nbody);
    for (int root = 1; root < m->nbody; ++root) {
      SubtreeComVelocity velocity(m, root);
      const std::array<double, 3> v = velocity(m, d);
      ASSERT_EQ(std::memcmp(v.data(), reference->subtree_linvel + 3 * root, sizeof v), 0)
          << GetParam() << " body " << root << " state " << state;
      ++compared;
    }
    // It wrote nothing to mjData.
    EXPECT_EQ(std::vector<mjtNum>(d->subtree_linvel, d->subtree_linvel + 3 * m->nbody), before);
  }
  EXPECT_GT(compared, 20 * 5);
  mj_deleteData(reference);
  mj_deleteData(d);
  mj_deleteModel(m);
}

INSTANTIATE_TEST_SUITE_P(Characters, ComVelocity,
                         ::testing::Values("backflip.toml", "jump_onto.toml", "robot_jump.toml", "silly_walk.toml",
                                           "robot_silly_walk.toml"),
                         [](const ::testing::TestParamInfo<const char*>& p) {
                           std::string name = p.param;
                           return name.substr(0, name.find('.'));
                         });

TEST(ComVelocityErrors, NoSuchBodyIsRefused) {
  const TaskEvaluator evaluator(load_task(kTasks + "backflip.toml"));
  EXPECT_THROW(SubtreeComVelocity(evaluator.model().get(), evaluator.model().get()->nbody), std::invalid_argument);
  EXPECT_THROW(SubtreeComVelocity(evaluator.model().get(), -1), std::invalid_argument);
}

}  // namespace
}  // namespace diverse
