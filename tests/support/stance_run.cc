#include "support/stance_run.h"

#include <cmath>
#include <fstream>

#include "character/character.h"
#include "control/controller.h"
#include "control/stance_controller.h"
#include "io/files.h"
#include "io/motion_record.h"
#include "params/parameters.h"
#include "physics/drive.h"
#include "task/task.h"

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

class WalkHooks : public StepHooks {
 public:
  WalkHooks(const Character& body, Controller& walk, JointDrive& drive, int steps, WalkMotion& out)
      : body_(body), walk_(walk), drive_(drive), steps_(steps), out_(out) {}
  void control(mjModel* m, mjData* d) override {
    contacts_ = scan_contacts(m, d, body_);
    if (first_) {
      walk_.reset(m, d);
      first_ = false;
      out_.phases.emplace_back(walk_.phase_times().names[static_cast<size_t>(walk_.phase())], d->time);
    }
    walk_.control(m, d, contacts_, drive_);
  }
  bool observe(const mjModel*, const mjData* d) override {
    if (walk_.phase_changed() && d->time > 0) {
      const int phase = walk_.phase();
      out_.phases.emplace_back(walk_.phase_times().names[static_cast<size_t>(phase)], d->time);
      if (phase == 0 || phase == 2) ++touchdowns_;  // a lift phase begins: the other foot came down
    }
    return contacts_.non_foot || touchdowns_ >= steps_;
  }

 private:
  const Character& body_;
  Controller& walk_;
  JointDrive& drive_;
  int steps_;
  WalkMotion& out_;
  ContactState contacts_;
  bool first_ = true;
  int touchdowns_ = 0;
};

void write_motion_file(const fs::path& dir, std::size_t i, const std::string& task,
                       const SharedModel& model, const StepRecorder& record,
                       const std::vector<std::pair<std::string, double>>& phases, nlohmann::json& motions) {
  const std::string stem = "m" + std::to_string(i);
  const std::string label = "M" + std::to_string(i);
  const fs::path model_path = dir / "model" / (stem + ".xml");
  const fs::path json_path = dir / "motions" / (stem + ".json");
  write_file_atomic(model_path, model.xml());
  nlohmann::json phase_list = nlohmann::json::array();
  for (const auto& [name, begin] : phases) phase_list.push_back({{"name", name}, {"begin", begin}});
  write_json_atomic(json_path, {{"format", "diverse.motion"},
                                {"version", 1},
                                {"task", task},
                                {"label", label},
                                {"parameters", nlohmann::json::object()},
                                {"constraint", {{"total", 0.0}, {"fell", false}, {"failed", false}}},
                                {"phases", phase_list},
                                {"replay", replay_record_json(record, model_path, json_path)}});
  motions.push_back({{"index", i}, {"label", label}, {"constraint", 0.0}, {"dmin", 0.0},
                     {"fell", false}, {"failed", false}, {"file", "motions/" + stem + ".json"}});
}

void write_run_files(const fs::path& dir, const std::string& task, const nlohmann::json& motions) {
  write_json_atomic(dir / "run.json", {{"format", "diverse.run"}, {"task_file", ""}, {"metric", "md"}});
  write_json_atomic(dir / "summary.json", {{"format", "diverse.summary"},
                                           {"task", task},
                                           {"metric", "md"},
                                           {"N", motions.size() - 1},
                                           {"motions", motions}});
}

}  // namespace

WalkMotion walk_motion(const std::string& character, const std::string& parameters, int steps) {
  const std::string root = DIVERSE_SOURCE_DIR;
  const auto spec = std::make_shared<CharacterSpec>(load_character_file(root + "/assets/characters/" + character + ".toml"));
  WalkMotion out;
  out.model = SharedModel::from_file(spec->model);
  const Character body = bind_character(spec, out.model->get(), spec->model);
  // The character's walk task names its skill (skills/walk3d.toml, skills/robot_walk3d.toml).
  const Task task = load_task(root + "/tasks/" + (character == "human3d" ? "silly_walk" : "robot_silly_walk") + ".toml");
  const std::vector<ParamSpec> specs = task.controller_type->parameter_specs(body, *task.controller_config);
  ParameterSet values(specs, std::vector<double>(specs.size(), 0.0));
  const std::string file = root + "/tasks/" + parameters;
  std::ifstream in(file);
  values.set_from_json(nlohmann::json::parse(in).at("parameters"), file);
  const std::unique_ptr<Controller> walk = task.controller_type->make(body, *task.controller_config, values.values());
  SimWorker worker(out.model);
  worker.reset();
  walk->start_state(worker.model(), worker.data());
  JointDrive drive = make_drive(body);
  WalkHooks hooks(body, *walk, drive, steps, out);
  run_rollout(worker, hooks, static_cast<int>(60.0 / worker.model()->opt.timestep), drive, &out.record);
  return out;
}

void write_walk_run(const fs::path& dir, const std::string& character,
                    const std::vector<std::string>& parameters, int steps) {
  fs::remove_all(dir);
  fs::create_directories(dir / "motions");
  fs::create_directories(dir / "model");
  nlohmann::json motions = nlohmann::json::array();
  for (std::size_t i = 0; i < parameters.size(); ++i) {
    const WalkMotion walk = walk_motion(character, parameters[i], steps);
    write_motion_file(dir, i, character + "_walk", *walk.model, walk.record, walk.phases, motions);
  }
  write_run_files(dir, character + "_walk", motions);
}

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
    write_motion_file(dir, i, character + "_stand", *motion.model, motion.record, {}, motions);
  }
  write_run_files(dir, character + "_stand", motions);
}

}  // namespace diverse::test_support
