// The physics layer: guarded stepping, instability as a result, exact replay,
// determinism and thread safety of the rollout.
#include "physics/rollout.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <thread>
#include <vector>

#include "physics/model.h"
#include "physics/mujoco_guard.h"
#include "core/error.h"
#include "task/evaluate.h"

namespace diverse {
namespace {

const std::string kTasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";

// A pendulum whose motor is driven by whatever the hooks write.
constexpr const char* kPendulum = R"(
<mujoco>
  <option timestep="0.002" integrator="Euler"/>
  <worldbody>
    <body pos="0 0 1">
      <joint name="hinge" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.02" mass="0.3"/>
    </body>
  </worldbody>
  <actuator><motor joint="hinge"/></actuator>
</mujoco>)";

class ConstantTorque : public StepHooks {
 public:
  explicit ConstantTorque(double tau) : tau_(tau) {}
  void control(mjModel*, mjData* d) override { d->ctrl[0] = tau_; }
  bool observe(const mjModel*, const mjData*) override { return false; }
  double tau_;
};

TEST(Rollout, AbsurdTorqueIsAnUnstableResultNotACrash) {
  auto model = SharedModel::from_xml(kPendulum, "pendulum");
  SimWorker worker(model);
  worker.reset();
  ConstantTorque hooks(1e200);
  const RolloutStats stats = run_rollout(worker, hooks, 1000, {}, nullptr);
  EXPECT_TRUE(stats.unstable);
  EXPECT_FALSE(stats.instability.empty());
  EXPECT_LT(stats.steps, 1000);
  // The worker is usable again after a reset.
  worker.reset();
  ConstantTorque calm(0.1);
  EXPECT_FALSE(run_rollout(worker, calm, 100, {}, nullptr).unstable);
}

TEST(Rollout, NanControlIsUnstable) {
  auto model = SharedModel::from_xml(kPendulum, "pendulum");
  SimWorker worker(model);
  worker.reset();
  ConstantTorque hooks(std::numeric_limits<double>::quiet_NaN());
  const RolloutStats stats = run_rollout(worker, hooks, 100, {}, nullptr);
  EXPECT_TRUE(stats.unstable);
  EXPECT_EQ(stats.instability, "bad ctrl");
}

TEST(Rollout, CompileErrorIsAUserError) {
  try {
    SharedModel::from_xml("<mujoco><worldbody><geom type=\"nothing\"/></worldbody></mujoco>", "bad.xml");
    FAIL();
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("bad.xml: MuJoCo cannot compile the model: ", 0), 0u);
  }
}

class TaskRollout : public ::testing::Test {
 protected:
  void SetUp() override {
    evaluator_ = std::make_unique<TaskEvaluator>(load_task(kTasks + "jump_high.toml"));
    params_ = evaluator_->load_parameters(evaluator_->task().m0);
  }
  std::unique_ptr<TaskEvaluator> evaluator_;
  ParameterSet params_;
};

// A NaN parameter or absurd gains end as a failed rollout with a penalty.
TEST_F(TaskRollout, InvalidParametersFailWithPenalty) {
  auto worker = evaluator_->make_worker();
  std::vector<double> v = params_.values();
  v[0] = std::numeric_limits<double>::quiet_NaN();
  const Evaluation nan = evaluator_->evaluate(v, *worker);
  EXPECT_TRUE(nan.failed);
  EXPECT_GE(nan.constraint, 3 * evaluator_->task().constraints.fall_penalty);

  std::vector<double> absurd = params_.values();
  for (size_t i = 0; i < absurd.size(); ++i) {
    if (params_.specs()[i].name.find(".kd_") != std::string::npos) absurd[i] = -1e12;
  }
  const Evaluation e = evaluator_->evaluate(absurd, *worker);
  EXPECT_TRUE(e.failed);
  EXPECT_GT(e.constraint, 0);

  Eigen::VectorXd x = params_.normalized();
  x[3] = 1.5;  // outside the normalized box
  const Evaluation outside = evaluator_->evaluate_normalized(x, *worker);
  EXPECT_TRUE(outside.failed);
  EXPECT_GT(outside.constraint, 0);
  // And the worker still simulates M0 correctly afterwards.
  EXPECT_EQ(evaluator_->evaluate(params_.values(), *worker).constraint, 0.0);
}

TEST_F(TaskRollout, ReplayReproducesTheRecordExactly) {
  auto worker = evaluator_->make_worker();
  StepRecorder record;
  EvaluationOptions options;
  options.recorder = &record;
  const Evaluation e = evaluator_->evaluate(params_.values(), *worker, options);
  ASSERT_FALSE(e.failed);
  ASSERT_GT(record.steps(), 100);
  EXPECT_EQ(record.steps(), e.stats.steps);
  mjModel* m = mj_copyModel(nullptr, evaluator_->model().get());
  EXPECT_LT(replay(m, record), 1e-12);
  mj_deleteModel(m);
}

TEST_F(TaskRollout, DeterministicAcrossWorkersAndThreads) {
  const Eigen::VectorXd x = params_.normalized();
  auto w0 = evaluator_->make_worker();
  const Evaluation a = evaluator_->evaluate_normalized(x, *w0);
  const Evaluation b = evaluator_->evaluate_normalized(x, *w0);
  EXPECT_EQ(a.constraint, b.constraint);
  EXPECT_EQ(a.flight_qpos, b.flight_qpos);
  // Two threads at once, each with its own worker, give the same bits.
  Eigen::VectorXd y = x;
  y[5] = std::min(1.0, y[5] + 0.05);
  Evaluation ra, rb;
  std::thread t1([&] { auto w = evaluator_->make_worker(); ra = evaluator_->evaluate_normalized(x, *w); });
  std::thread t2([&] { auto w = evaluator_->make_worker(); rb = evaluator_->evaluate_normalized(y, *w); });
  t1.join();
  t2.join();
  EXPECT_EQ(ra.flight_qpos, a.flight_qpos);
  auto w1 = evaluator_->make_worker();
  EXPECT_EQ(rb.flight_qpos, evaluator_->evaluate_normalized(y, *w1).flight_qpos);
}

TEST_F(TaskRollout, PoseSamplesCoverBothAirbornePhases) {
  auto worker = evaluator_->make_worker();
  const Evaluation e = evaluator_->evaluate(params_.values(), *worker);
  ASSERT_TRUE(e.has_flight());
  ASSERT_EQ(e.poses.size(), 20u);
  const double takeoff = e.phases.takeoff(), peak = e.phases.peak(), land = e.phases.landing();
  EXPECT_LT(takeoff, peak);
  EXPECT_LT(peak, land);
  for (int k = 0; k < 20; ++k) {
    const PoseSample& p = e.poses[k];
    EXPECT_EQ(p.phase, k / 10);
    EXPECT_NEAR(p.phase_time, (k % 10 + 0.5) / 10, 1e-12);
    const double a = p.phase == 0 ? takeoff : peak, b = p.phase == 0 ? peak : land;
    EXPECT_NEAR(p.time, a + p.phase_time * (b - a), 1e-12);
    EXPECT_EQ(p.link_com.cols(), 17);
    EXPECT_EQ(p.angles.size(), 16);  // the joints; the root's orientation is p.root
    EXPECT_NEAR(p.root.norm(), 1.0, 1e-12);
  }
  EXPECT_NEAR(evaluator_->link_masses().sum(), 80.0, 1e-9);
  // The COM is higher mid-flight than at take-off.
  auto com_z = [&](const PoseSample& p) {
    return (p.link_com.row(2).transpose().array() * evaluator_->link_masses().array()).sum() / 80.0;
  };
  EXPECT_GT(com_z(e.poses[9]), com_z(e.poses[0]));
}

}  // namespace
}  // namespace diverse
