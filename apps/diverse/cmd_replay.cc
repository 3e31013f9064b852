// `diverse replay DIR/motion.json`: loads the motion's saved model in plain MuJoCo, sets
// the recorded initial state, replays the recorded inputs with mj_step and reports the
// largest |qpos difference| from the recorded trajectory, and the net-torque check: at
// every step, each driven joint's motor plus damper torque against its limit (the driven
// joints and limits come from the saved model's actuators, physics/drive.h). Exits 1 if
// the qpos difference exceeds 1e-6 or a net torque exceeds its limit by more than 1 %
// (SPEC section 8).
//
// A walk (a motion whose summary has walk steps) is also audited from geometry alone
// (task/walk_audit.h): steps counted from foot contacts, every step's length in the
// heading frame, pelvis and torso tilt, falls and the turn, against the task's [walk]
// rules; one line per step and exit 1 on a broken rule. The task file is --task, else the
// run's (RUN/run.json beside motions/), else tasks/<task>.toml. A --task for another
// controller or character than the motion's is refused before anything is replayed: one
// line naming the motion file, the field (parameters, replay.model) and what was expected.
//
// Every motion's feet are measured from the same plain-MuJoCo replay (task/foot_slip.h):
// per side, the stances and how far the loaded feet slid in them. `diverse foot-slip
// PATH...` measures that alone, for motion files and for every motion of run directories,
// as a Markdown table or (--json) JSON: a run written before the measure, or a motion of
// `simulate`, has it without being run again. It is a command of its own rather than an
// option of replay because it takes many motions and whole runs, and never fails a motion.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>

#include "command.h"
#include "options.h"
#include "core/error.h"
#include "io/files.h"
#include "io/motion_record.h"
#include "physics/drive.h"
#include "physics/model.h"
#include "task/evaluate.h"
#include "task/task.h"
#include "task/walk_audit.h"

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

// The task file of a motion: `given`, else the run's, else tasks/<name>.toml.
std::string motion_task_file(const std::string& motion_path, const nlohmann::json& motion, const std::string& given) {
  if (!given.empty()) return resolve_task_path(given);
  const std::filesystem::path run_json = std::filesystem::path(motion_path).parent_path().parent_path() / "run.json";
  if (std::filesystem::exists(run_json)) {
    const nlohmann::json run = read_json(run_json);
    if (run.contains("task_file") && run["task_file"].is_string()) {
      const std::string file = run["task_file"].get<std::string>();
      if (std::filesystem::exists(file)) return file;
    }
  }
  const std::string name = motion.value("task", std::string());
  try {
    return resolve_task_path(name);
  } catch (const UserError&) {
    throw UserError(motion_path + ": task: the motion's task file '" + name +
                    "' was not found; give it with --task FILE");
  }
}

// True when motion_task_file() finds a task file without --task.
bool task_file_exists(const std::string& motion_path, const nlohmann::json& motion) {
  try {
    motion_task_file(motion_path, motion, "");
    return true;
  } catch (const UserError&) {
    return false;
  }
}

// With --task: the task must be for the motion's controller and character, or the
// replay would be judged against rules of another skill. The motion's parameters must be
// exactly the task's controller's for its character (shape scales aside), and the
// motion's saved model must have the task scene's joints, in order.
void check_task_of_motion(const std::string& path, const std::string& task_option) {
  const nlohmann::json motion = read_json(path);
  const Task task = load_task(resolve_task_path(task_option));
  const TaskEvaluator ev(task);
  const std::string of_task = " (task " + task.file + ")";
  const std::string motion_task = motion.is_object() ? motion.value("task", std::string("?")) : std::string("?");
  // A skill file's task is named by its skill, any other by its controller.
  const std::string skill = task.controller_config->skill_name();
  const std::string runs = skill.empty() ? "controller '" + task.controller + "'" : "skill '" + skill + "'";
  const std::string expected = "expected the parameters of " + runs + " for character '" + task.character_spec->name + "'" + of_task;
  if (!motion.is_object() || !motion.contains("parameters") || !motion["parameters"].is_object())
    throw_field_error(path, "parameters", expected);
  const nlohmann::json& named = motion["parameters"];
  std::size_t control = 0;
  for (const auto& [name, value] : named.items()) {
    if (name.rfind("shape.", 0) == 0) continue;
    ++control;
    if (ev.parameters().find(name) < 0)
      throw_field_error(path, "parameters", expected + ", got '" + name + "' of a motion of task '" + motion_task + "'");
  }
  if (static_cast<int>(control) != ev.dim())
    throw_field_error(path, "parameters",
                      expected + ": " + std::to_string(ev.dim()) + " of them, got " + std::to_string(control) +
                          " of a motion of task '" + motion_task + "'");
  std::filesystem::path model_path;
  read_replay_record(motion, path, &model_path);
  const auto saved = SharedModel::from_file(model_path.string());
  const mjModel* a = saved->get();
  const mjModel* b = ev.model().get();
  bool same = a->njnt == b->njnt;
  for (int j = 0; same && j < a->njnt; ++j) {
    const char* na = mj_id2name(a, mjOBJ_JOINT, j);
    const char* nb = mj_id2name(b, mjOBJ_JOINT, j);
    same = std::string(na ? na : "") == std::string(nb ? nb : "") && a->jnt_type[j] == b->jnt_type[j];
  }
  if (!same)
    throw_field_error(path, "replay.model",
                      "expected a model of character '" + task.character_spec->name + "'" + of_task +
                          " (its joints, in order), got a model of task '" + motion_task + "'");
}

// How far a motion's feet slid, measured by replaying it (task/foot_slip.h); the feet
// are those of its task's character.
FootSlip motion_foot_slip(const std::string& path, const std::string& task_option) {
  const nlohmann::json motion = read_json(path);
  const Task task = load_task(motion_task_file(path, motion, task_option));
  return motion_file_foot_slip(path, task.character_spec);
}

// Prints the audit of a walk motion; returns false if it breaks a rule of its task.
// `slip` (task/foot_slip.h) gives each step the slide of the stance it begins.
bool audit_walk_motion(const std::string& path, const std::string& task_option, const FootSlip* slip) {
  const nlohmann::json motion = read_json(path);
  if (!motion.contains("summary") || !motion["summary"].contains("walk_steps")) return true;
  const Task task = load_task(motion_task_file(path, motion, task_option));
  if (!task.walk.enabled) throw UserError(task.file + ": expected a walk task (a [walk] table) for the walk " + path);
  std::filesystem::path model_path;
  const StepRecorder record = read_replay_record(motion, path, &model_path);
  const auto model = SharedModel::from_file(model_path.string());
  const Character body = bind_character(task.character_spec, model->get(), model_path.string());
  const WalkAudit a = audit_walk(model->get(), record, body, task.walk);
  std::printf("walk audit (%s, from foot contacts): %zu steps, %d re-landings of a foot\n", task.name.c_str(),
              a.steps.size(), a.relandings);
  std::printf("  step  leg    time   forward   lateral   tilt  heading  footprint  stance slide\n");
  for (size_t k = 0; k < a.steps.size(); ++k) {
    const WalkAudit::Step& s = a.steps[k];
    // The landing foot's stance that begins at this touch-down.
    std::string slid = "     -";
    if (slip != nullptr) {
      for (const FootSlip::Stance& st : slip->sides[static_cast<size_t>(s.leg)].stances) {
        if (std::fabs(st.begin - s.time) < 0.5 * record.timestep) {
          char buffer[32];
          std::snprintf(buffer, sizeof buffer, "%6.2f cm", 100 * st.slide);
          slid = buffer;
        }
      }
    }
    std::printf("  %4zu  %s  %6.3f  %7.3f m %7.3f m %5.1f°  %6.1f°  %7.3f m  %s%s\n", k + 1,
                s.leg == 0 ? "left " : "right", s.time, s.forward, s.lateral, s.tilt * 180 / M_PI,
                s.heading * 180 / M_PI, s.footprint_forward, slid.c_str(),
                static_cast<int>(k) < task.walk.settle_steps ? "  (settling)" : "");
  }
  std::printf("  evaluated steps: forward %.3f to %.3f m (footprint to footprint %.3f to %.3f m), lateral %.3f to "
              "%.3f m, tilt at most %.1f°, turn %.1f°\n",
              a.forward_min, a.forward_max, a.footprint_forward_min, a.footprint_forward_max, a.lateral_min,
              a.lateral_max, a.max_tilt * 180 / M_PI, a.turn * 180 / M_PI);
  if (a.violations.empty()) {
    std::printf("  meets the walk rules of %s\n", task.name.c_str());
    return true;
  }
  for (const std::string& v : a.violations) std::fprintf(stderr, "diverse: walk audit: %s\n", v.c_str());
  return false;
}

void print_foot_slip(const FootSlip& slip) {
  const char* names[2] = {"left ", "right"};
  for (size_t s = 0; s < 2; ++s) {
    const FootSlip::Side& side = slip.sides[s];
    std::printf("foot slip, %s feet: %zu stances, %.4f m in all, per stance %.2f cm on average and %.2f cm at most, "
                "up to %.3f m/s",
                names[s], side.stances.size(), side.total, 100 * side.mean, 100 * side.largest, side.max_speed);
    if (side.max_speed_time >= 0) std::printf(" (at %.3f s)", side.max_speed_time);
    std::printf("\n");
  }
}

// `diverse foot-slip PATH...`: motion files, and run directories (every motions/*.json).
void install_foot_slip(CLI::App& app) {
  auto paths = std::make_shared<std::vector<std::string>>();
  auto task = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand(
      "foot-slip", "How far planted feet slide in motions, measured by replaying them in plain MuJoCo");
  cmd->add_option("paths", *paths, "Motion files (motion.json) and run directories")->required();
  cmd->add_option("--task", *task, "Task file whose character's feet are measured (default: the run's, else tasks/<task>.toml)");
  cmd->add_flag("--json", *json, "Print JSON (per motion: file, label and the measure) instead of a table");
  cmd->footer("Examples:\n"
              "  diverse foot-slip runs/robot_silly_walk            every motion of a run\n"
              "  diverse foot-slip out/motion.json --json           one motion of `diverse simulate`\n"
              "Definition: docs/reference/foot-slip.md");
  cmd->callback([paths, task, json] {
    std::vector<std::string> files;
    for (const std::string& p : *paths) {
      const std::filesystem::path motions = std::filesystem::path(p) / "motions";
      if (!std::filesystem::is_directory(p)) {
        if (!std::filesystem::exists(p)) throw UserError(p + ": no such motion file or run directory");
        files.push_back(p);
        continue;
      }
      if (!std::filesystem::is_directory(motions))
        throw UserError(p + ": not a run directory (no motions/) and not a motion file");
      std::vector<std::string> found;
      for (const auto& entry : std::filesystem::directory_iterator(motions))
        if (entry.path().extension() == ".json") found.push_back(entry.path().string());
      // m0, m1, ..., m10 in numeric order.
      std::sort(found.begin(), found.end(), [](const std::string& a, const std::string& b) {
        return a.size() != b.size() ? a.size() < b.size() : a < b;
      });
      files.insert(files.end(), found.begin(), found.end());
    }
    nlohmann::json out = nlohmann::json::array();
    if (!*json)
      std::printf("| motion | label | side | stances | slide in all (m) | mean per stance (cm) | largest per stance (cm) | "
                  "fastest (m/s) |\n|---|---|---|---|---|---|---|---|\n");
    for (const std::string& file : files) {
      const FootSlip slip = motion_foot_slip(file, *task);
      const std::string label = read_json(file).value("label", std::string());
      if (*json) {
        out.push_back({{"file", file}, {"label", label}, {"foot_slip", foot_slip_json(slip)}});
        continue;
      }
      for (size_t s = 0; s < 2; ++s) {
        const FootSlip::Side& side = slip.sides[s];
        std::printf("| %s | %s | %s | %zu | %.3f | %.2f | %.2f | %.2f |\n", file.c_str(), label.c_str(),
                    s == 0 ? "left" : "right", side.stances.size(), side.total, 100 * side.mean, 100 * side.largest,
                    side.max_speed);
      }
    }
    if (*json) std::printf("%s\n", out.dump(2).c_str());
  });
}

void install(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  auto task = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "replay", "Replay a motion record in plain MuJoCo, compare qpos, check net joint torques and measure foot slip");
  cmd->footer("Example:\n"
              "  diverse replay runs/jump_high/motions/m1.json");
  cmd->add_option("motion", *path, "motion.json written by simulate or run")->required();
  cmd->add_option("--task", *task,
                  "Task file whose character's feet are measured and whose [walk] rules a walk is audited against (default: the run's, else tasks/<task>.toml)");
  cmd->callback([path, task] {
    if (!task->empty()) check_task_of_motion(*path, *task);
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
    // The feet are the task's character's: a motion without a task file to find (made by
    // another program) is replayed and checked without them.
    const nlohmann::json motion = read_json(*path);
    std::optional<FootSlip> slip;
    if (!task->empty() || task_file_exists(*path, motion)) {
      slip = motion_foot_slip(*path, *task);
      print_foot_slip(*slip);
    } else {
      std::printf("foot slip: not measured (no task file for task '%s'; give it with --task FILE)\n",
                  motion.value("task", std::string()).c_str());
    }
    if (!audit_walk_motion(*path, *task, slip ? &*slip : nullptr)) failed = true;
    if (failed) std::exit(1);
  });
}

const bool registered = register_command(51, install);
const bool registered_foot_slip = register_command(53, install_foot_slip);

}  // namespace
}  // namespace diverse::cli
