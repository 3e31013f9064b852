#include "support/stance_run.h"

#include <cmath>

#include "character/character.h"
#include "control/stance_controller.h"
#include "io/files.h"
#include "io/motion_record.h"
#include "physics/drive.h"

namespace diverse::test_support {
namespace fs = std::filesystem;

namespace {

class Hooks : public StepHooks {
 public:
  Hooks(StanceController& stance, JointDrive& drive) : stance_(stance), drive_(drive) {}
  void control(mjModel* m, mjData* d) override { stance_.control(m, d, drive_); }
  bool observe(const mjModel*, const mjData*) override { return false; }

 private:
  StanceController& stance_;
  JointDrive& drive_;
};

}  // namespace

StanceMotion stance_motion(const std::string& character, const std::array<double, 3>& push,
                           double seconds) {
  const auto spec = std::make_shared<CharacterSpec>(load_character_file(
      std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/" + character + ".toml"));
  StanceMotion out;
  out.model = SharedModel::from_file(spec->model);
  const Character body = bind_character(spec, out.model->get(), spec->model);
  SimWorker worker(out.model);
  worker.reset();
  mjModel* m = worker.model();
  mjData* d = worker.data();
  StanceController stance(body, m);
  const std::vector<double> pose = stance.standing_pose(m);
  mju_copy(d->qpos, pose.data(), m->nq);
  for (int i = 0; i < 3; ++i) d->qvel[body.root_dof + i] = push[static_cast<std::size_t>(i)];
  mj_forward(m, d);
  stance.reset(m, d);
  std::vector<DrivenJoint> joints;
  for (const CharacterJoint& j : body.joints) joints.push_back({j.actuator, j.dof, j.torque_limit});
  JointDrive drive(std::move(joints));
  Hooks hooks(stance, drive);
  run_rollout(worker, hooks, static_cast<int>(std::lround(seconds / m->opt.timestep)), drive,
              &out.record);
  return out;
}

void write_stance_run(const fs::path& dir, const std::string& character,
                      const std::vector<std::array<double, 3>>& pushes, double seconds) {
  fs::remove_all(dir);
  fs::create_directories(dir / "motions");
  fs::create_directories(dir / "model");
  nlohmann::json motions = nlohmann::json::array();
  for (std::size_t i = 0; i < pushes.size(); ++i) {
    const StanceMotion motion = stance_motion(character, pushes[i], seconds);
    const std::string stem = "m" + std::to_string(i);
    const std::string label = "M" + std::to_string(i);
    const fs::path model_path = dir / "model" / (stem + ".xml");
    const fs::path json_path = dir / "motions" / (stem + ".json");
    write_file_atomic(model_path, motion.model->xml());
    write_json_atomic(json_path, {{"format", "diverse.motion"},
                                  {"version", 1},
                                  {"task", character + "_stand"},
                                  {"label", label},
                                  {"parameters", nlohmann::json::object()},
                                  {"constraint", {{"total", 0.0}, {"fell", false}, {"failed", false}}},
                                  {"phases", nlohmann::json::array()},
                                  {"replay", replay_record_json(motion.record, model_path, json_path)}});
    motions.push_back({{"index", i}, {"label", label}, {"constraint", 0.0}, {"dmin", 0.0},
                       {"fell", false}, {"failed", false}, {"file", "motions/" + stem + ".json"}});
  }
  write_json_atomic(dir / "run.json", {{"format", "diverse.run"}, {"task_file", ""}, {"metric", "md"}});
  write_json_atomic(dir / "summary.json", {{"format", "diverse.summary"},
                                           {"task", character + "_stand"},
                                           {"metric", "md"},
                                           {"N", pushes.size() - 1},
                                           {"motions", motions}});
}

}  // namespace diverse::test_support
