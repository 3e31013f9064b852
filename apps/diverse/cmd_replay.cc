// `diverse replay DIR/motion.json`: loads the motion's saved model in plain MuJoCo, sets
// the recorded initial state, replays the recorded inputs with mj_step and reports the
// largest |qpos difference| from the recorded trajectory, and the net-torque check: at
// every step, each driven joint's motor plus damper torque against its limit (the driven
// joints and limits come from the saved model's actuators, physics/drive.h). Exits 1 if
// the qpos difference exceeds 1e-6 or a net torque exceeds its limit by more than 1 %
// (SPEC section 8).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "command.h"
#include "options.h"
#include "io/files.h"
#include "io/motion_record.h"
#include "physics/drive.h"
#include "physics/model.h"

namespace diverse::cli {
namespace {

constexpr double kTolerance = 1e-6;
constexpr double kTorqueTolerance = 0.01;  // fraction of the limit

// Replays the motion file's record on its saved model and checks the net torques.
NetTorqueCheck check_motion_torques(const std::string& path, std::string* worst_joint) {
  std::filesystem::path model_path;
  const StepRecorder record = read_replay_record(read_json(path), path, &model_path);
  const auto model = SharedModel::from_file(model_path.string());
  const std::vector<DrivenJoint> joints = driven_joints(model->get());
  mjModel* m = mj_copyModel(nullptr, model->get());
  const NetTorqueCheck check = check_net_torque(m, record, joints);
  mj_deleteModel(m);
  if (check.worst_joint >= 0) {
    const DrivenJoint& j = joints[static_cast<size_t>(check.worst_joint)];
    const char* name = mj_id2name(model->get(), mjOBJ_JOINT, model->get()->dof_jntid[j.dof]);
    *worst_joint = name != nullptr ? name : "dof " + std::to_string(j.dof);
  }
  return check;
}

void install(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "replay", "Replay a motion record in plain MuJoCo, compare qpos and check net joint torques");
  cmd->add_option("motion", *path, "motion.json written by simulate or run")->required();
  cmd->callback([path] {
    int steps = 0;
    const double diff = replay_motion_file(*path, &steps);
    std::printf("replayed %d steps, max |qpos difference| = %.3g\n", steps, diff);
    std::string joint;
    const NetTorqueCheck torque = check_motion_torques(*path, &joint);
    if (torque.blew_up) {
      std::printf("net torque: the replay blew up after %d steps\n", torque.steps);
    } else if (torque.worst_joint < 0) {
      std::printf("net torque: the model has no driven joints\n");
    } else {
      // Excess as a fraction of the limit: -0.03 is 97 % of the limit, 0.05 is 105 %.
      std::printf("net torque: worst excess over the limit %+.3g %% (%s, step %d, %.6g Nm), "
                  "%d of %d steps over the limit by more than %g %%\n",
                  100 * torque.worst_excess, joint.c_str(), torque.worst_step, torque.worst_torque,
                  torque.steps_over_1_percent, torque.steps, 100 * kTorqueTolerance);
    }
    bool failed = false;
    if (!(diff <= kTolerance)) {
      std::fprintf(stderr, "diverse: replay differs from the record by more than %g\n", kTolerance);
      failed = true;
    }
    if (!(torque.worst_excess <= kTorqueTolerance)) {
      std::fprintf(stderr, "diverse: a net joint torque exceeds its limit by more than %g %%\n",
                   100 * kTorqueTolerance);
      failed = true;
    }
    if (failed) std::exit(1);
  });
}

const bool registered = register_command(51, install);

}  // namespace
}  // namespace diverse::cli
