// The strength model (--strength) and the bounds on the variations (--effort-bound,
// --max-distance): scaled limits and gains, the effort measure, bounds that hold on every
// motion a run returns, and runs that keep all three across a kill and resume.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "eval/motion_problem.h"
#include "io/files.h"
#include "io/motion_record.h"
#include "run/run.h"
#include "support/cli.h"
#include "task/evaluate.h"
#include "task/task.h"
#include "support/scratch.h"
#include "support/text_files.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

using cli_test::run_cli;

const std::string kSource = DIVERSE_SOURCE_DIR;
const std::string kTask = kSource + "/tasks/jump_high.toml";

fs::path scratch(const std::string& name) {
  const fs::path dir = test_files::scratch_dir("strength_bounds_" + name);
  return dir;
}

Task task_at(const std::string& path, double strength) {
  Task task = load_task(path);
  task.strength = strength;
  return task;
}

// Every forcerange="lo hi" of an MJCF text, in order.
std::vector<double> force_ranges(const std::string& xml) {
  std::vector<double> values;
  const std::regex attribute(R"(forcerange="([^"]*)\")");
  for (std::sregex_iterator it(xml.begin(), xml.end(), attribute), end; it != end; ++it) {
    std::istringstream in((*it)[1].str());
    double v = 0;
    while (in >> v) values.push_back(v);
  }
  return values;
}

TEST(Strength, ScalesEveryTorqueLimitOfEveryCharacter) {
  std::vector<std::string> tasks = {kSource + "/examples/own-character/leap.toml"};
  for (const auto& entry : fs::directory_iterator(kSource + "/tasks"))
    if (entry.path().extension() == ".toml") tasks.push_back(entry.path().string());
  std::sort(tasks.begin(), tasks.end());
  ASSERT_GE(tasks.size(), 9u);
  for (const std::string& path : tasks) {
    SCOPED_TRACE(path);
    const TaskEvaluator plain(task_at(path, 1.0));
    const TaskEvaluator strong(task_at(path, 2.5));
    EXPECT_EQ(strong.body().strength, 2.5);
    ASSERT_EQ(plain.body().joints.size(), strong.body().joints.size());
    for (std::size_t k = 0; k < plain.body().joints.size(); ++k)
      EXPECT_DOUBLE_EQ(strong.body().joints[k].torque_limit, 2.5 * plain.body().joints[k].torque_limit) << k;
    // The model text itself carries the limits, so a saved model does.
    const std::vector<double> a = force_ranges(plain.model().xml());
    const std::vector<double> b = force_ranges(strong.model().xml());
    ASSERT_EQ(a.size(), b.size());
    ASSERT_FALSE(a.empty());
    for (std::size_t i = 0; i < a.size(); ++i) EXPECT_DOUBLE_EQ(b[i], 2.5 * a[i]);
  }
}

TEST(Strength, DoublesThePdRequestOfTheJumpController) {
  // The same state, the same parameters: at strength 2 the jump controller asks the drive
  // for twice the PD torque and twice the damping on every joint the balance torque does
  // not act on (arms, neck), and twice the damping everywhere.
  const TaskEvaluator plain(task_at(kTask, 1.0));
  const TaskEvaluator strong(task_at(kTask, 2.0));
  const ParameterSet m0 = plain.load_parameters(plain.task().m0);
  auto worker = plain.make_worker();
  worker->reset();
  mjModel* m = worker->model();
  mjData* d = worker->data();
  const auto weak_controller = plain.task().controller_type->make(plain.body(), *plain.task().controller_config, m0.values());
  const auto strong_controller = strong.task().controller_type->make(strong.body(), *strong.task().controller_config, m0.values());
  weak_controller->start_state(m, d);
  mj_step1(m, d);
  weak_controller->reset(m, d);
  strong_controller->reset(m, d);
  JointDrive weak = make_drive(plain.body()), strongd = make_drive(strong.body());
  int checked = 0;
  for (int step = 0; step < 60; ++step) {
    const ContactState contacts = scan_contacts(m, d, plain.body());
    weak_controller->control(m, d, contacts, weak);
    strong_controller->control(m, d, contacts, strongd);
    for (int k = 0; k < weak.size(); ++k) {
      EXPECT_EQ(strongd.kd(k), 2.0 * weak.kd(k)) << "joint " << k << " step " << step;
      const JointRole role = plain.body().groups[static_cast<std::size_t>(plain.body().joints[static_cast<std::size_t>(k)].group)].role;
      if (role == JointRole::kShoulder || role == JointRole::kElbow) {
        EXPECT_EQ(strongd.u(k), 2.0 * weak.u(k)) << "joint " << k << " step " << step;
        if (weak.u(k) != 0.0) ++checked;
      }
    }
    // The plain character moves; both controllers see its states.
    if (weak.apply(m, d)) mj_passive(m, d);
    mj_step2(m, d);
    mj_step1(m, d);
  }
  EXPECT_GT(checked, 20) << "the arms' PD torques should be non-zero";
}

TEST(Effort, IsTheIntegralOfTheRecordedSquaredNetTorques) {
  const TaskEvaluator ev(task_at(kTask, 1.0));
  const ParameterSet m0 = ev.load_parameters(ev.task().m0);
  StepRecorder record;
  EvaluationOptions options;
  options.recorder = &record;
  auto worker = ev.make_worker();
  const Evaluation e = ev.evaluate(m0.values(), *worker, options);
  ASSERT_FALSE(e.failed);
  const JointDrive drive = make_drive(ev.body());
  ASSERT_EQ(record.ndamp, drive.size());
  double effort = 0;
  const int steps = record.steps();
  ASSERT_EQ(steps, e.stats.steps);
  for (int s = 0; s < steps; ++s) {
    double squared = 0;
    for (int k = 0; k < drive.size(); ++k) {
      const DrivenJoint& j = drive.joints()[static_cast<std::size_t>(k)];
      const double net = record.actuator_force[static_cast<std::size_t>(s * record.nu + j.actuator)] +
                         record.damping_force[static_cast<std::size_t>(s * record.ndamp + k)];
      squared += net * net;
    }
    effort += record.timestep * squared;
  }
  EXPECT_NEAR(e.stats.effort, effort, 1e-9 * effort);
  // Positive mechanical work: at least the potential energy the jump gains by its peak
  // (the body starts at rest; joints are its only source of energy, contacts and joint
  // damping only take energy away).
  auto w = ev.make_worker();
  w->reset();
  std::copy(record.qpos0.begin(), record.qpos0.end(), w->data()->qpos);
  mj_forward(w->model(), w->data());
  const double com_z0 = w->data()->subtree_com[3 * ev.body().root_body + 2];
  const double gain = ev.body().total_mass * 9.81 * (e.summary.peak_com_z - com_z0);
  ASSERT_GT(gain, 100.0);
  EXPECT_GT(e.stats.positive_work, gain);
}

// The high jump without the half-timestep check: the bounds are what is tested here, and
// in 6 generations under the check the variations stay within a few MD of M0 (the check
// has its own tests, tests/task/half_timestep_test.cc).
std::string unchecked_task() {
  std::string toml = test_files::read_text(kTask);
  const auto swap = [&toml](const std::string& from, const std::string& to) {
    const auto at = toml.find(from);
    if (at == std::string::npos) throw std::runtime_error("jump_high.toml has no '" + from + "'");
    toml.replace(at, from.size(), to);
  };
  swap("half_timestep = true", "half_timestep = false");
  swap("\"../assets/", "\"" + kSource + "/assets/");
  swap("\"../skills/", "\"" + kSource + "/skills/");
  swap("\"jump_high.m0.json\"", "\"" + kSource + "/tasks/jump_high.m0.json\"");
  swap("\"jump_high_start.json\"", "\"" + kSource + "/tasks/jump_high_start.json\"");
  const fs::path dir = test_files::scratch_dir("strength_bounds_task");
  fs::create_directories(dir);
  test_files::write_text((dir / "jump_high.toml").string(), toml);
  return (dir / "jump_high.toml").string();
}

// A short real run's summary.
nlohmann::json short_run(const fs::path& out, const std::string& extra) {
  static const std::string task = unchecked_task();
  const auto r = run_cli("run " + task + " --n 2 --popsize 8 --sigma0 0.02 --generations 6 --seed 3 --threads 2 "
                         "--quiet --no-render --out " + out.string() + " " + extra);
  EXPECT_EQ(r.status, 0) << r.output;
  return read_json(out / "summary.json");
}

TEST(Bounds, HoldOnEveryMotionTheRunReturns) {
  const fs::path free_dir = scratch("free"), bounded_dir = scratch("bounded");
  const nlohmann::json free = short_run(free_dir, "");
  double largest_ratio = 0, largest_distance = 0;
  for (std::size_t i = 1; i < free["motions"].size(); ++i) {
    largest_ratio = std::max(largest_ratio, free["motions"][i]["effort_ratio"].get<double>());
    largest_distance = std::max(largest_distance, free["motions"][i]["distance_to_m0"].get<double>());
  }
  // Bounds below what the unbounded run reaches, so they bind.
  const double R = 1.0 + 0.5 * (largest_ratio - 1.0), X = 0.5 * largest_distance;
  ASSERT_GT(largest_ratio, 1.0);
  ASSERT_GT(X, 1.0);
  const nlohmann::json bounded = short_run(
      bounded_dir, "--effort-bound " + std::to_string(R) + " --max-distance " + std::to_string(X));
  EXPECT_EQ(bounded["bounds"]["effort"].get<double>(), std::stod(std::to_string(R)));
  EXPECT_EQ(bounded["bounds"]["distance"].get<double>(), std::stod(std::to_string(X)));
  EXPECT_TRUE(bounded["all_satisfied"].get<bool>());
  const nlohmann::json& motions = bounded["motions"];
  const double m0_effort = read_json(bounded_dir / "motions/m0.json")["effort"].get<double>();
  for (std::size_t i = 0; i < motions.size(); ++i) {
    SCOPED_TRACE(i);
    const nlohmann::json& m = motions[i];
    EXPECT_TRUE(m["within_bounds"].get<bool>());
    EXPECT_EQ(m["constraint"].get<double>(), 0.0);
    EXPECT_LE(m["effort_ratio"].get<double>(), R);
    EXPECT_LE(m["distance_to_m0"].get<double>(), X);
    // The same figures as the motion's replayable file and the summary's matrix.
    const nlohmann::json file = read_json(bounded_dir / ("motions/m" + std::to_string(i) + ".json"));
    EXPECT_EQ(file["effort"].get<double>(), m["effort"].get<double>());
    EXPECT_DOUBLE_EQ(m["effort_ratio"].get<double>(), file["effort"].get<double>() / m0_effort);
    EXPECT_DOUBLE_EQ(m["distance_to_m0"].get<double>(), bounded["distances"]["md"][0][i].get<double>());
    EXPECT_LT(replay_motion_file(bounded_dir / ("motions/m" + std::to_string(i) + ".json")), 1e-6);
  }
  // Every sample is counted (evaluations adds M0's), and some met every constraint.
  for (const nlohmann::json* summary : {&free, &bounded}) {
    EXPECT_EQ((*summary)["samples"].get<long long>() + 1, (*summary)["evaluations"].get<long long>());
    EXPECT_GT((*summary)["feasible_samples"].get<long long>(), 0);
    EXPECT_LE((*summary)["feasible_samples"].get<long long>(), (*summary)["samples"].get<long long>());
  }
}

TEST(Strength, RunSavesScaledModelsAndResumeKeepsStrengthAndBounds) {
  const fs::path whole = scratch("whole"), killed = scratch("killed");
  const std::string args = kTask + " --n 2 --popsize 8 --sigma0 0.03 --generations 6 --seed 3 --threads 1 "
                           "--quiet --no-render --checkpoint-seconds 0 --strength 2 --effort-bound 3 --max-distance 60";
  const auto a = run_cli("run " + args + " --out " + whole.string());
  ASSERT_EQ(a.status, 0) << a.output;
  const nlohmann::json run = read_json(whole / "run.json");
  EXPECT_EQ(run["strength"], 2.0);
  EXPECT_EQ(run["bounds"]["effort"], 3.0);
  EXPECT_EQ(run["bounds"]["distance"], 60.0);

  ASSERT_GE(cli_test::run_then_kill(args, killed, 2), 2);
  ASSERT_FALSE(fs::exists(killed / "summary.json")) << "the run finished before it was killed";
  const auto r = run_cli("resume " + killed.string() + " --threads 2 --quiet --no-render");
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json summary = read_json(whole / "summary.json");
  EXPECT_EQ(without_timing(summary), without_timing(read_json(killed / "summary.json")));
  EXPECT_EQ(summary["strength"], 2.0);
  EXPECT_EQ(summary["bounds"], run["bounds"]);

  // The saved models carry twice the character's torque limits, and every motion replays
  // exactly on them with its net torque within them (`diverse replay` checks both).
  const std::vector<double> base = force_ranges(read_file(kSource + "/assets/characters/human2d.xml"));
  for (int i = 0; i <= 2; ++i) {
    SCOPED_TRACE(i);
    const std::vector<double> saved = force_ranges(read_file(whole / "model" / ("m" + std::to_string(i) + ".xml")));
    ASSERT_EQ(saved.size(), base.size());
    for (std::size_t k = 0; k < base.size(); ++k) EXPECT_EQ(saved[k], 2 * base[k]);
    EXPECT_EQ(read_json(whole / "motions" / ("m" + std::to_string(i) + ".json"))["strength"], 2.0);
    const auto replay = run_cli("replay " + (whole / "motions" / ("m" + std::to_string(i) + ".json")).string());
    EXPECT_EQ(replay.status, 0) << replay.output;
  }
}

}  // namespace
}  // namespace diverse
