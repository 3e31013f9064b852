// The SIMBICON walks as skill files (skills/walk3d.toml, skills/robot_walk3d.toml): each
// walk task, which names its skill, gives its committed input motion the same rollout
// under the skill engine (control/skill_controller.h) as the "walk3d" controller gave it
// before the walk was a skill file: the same parameter names, ranges and order, and the
// same qpos and ctrl at every step to the last bit, at the task's timestep and at half of
// it, the same phase times and the same C.
//
// tests/control/data/walk_replay_reference.txt holds what walk3d did, written by describe()
// below from the walk3d controller before it was removed (the task files as they named it,
// `type = "walk3d"`): per task and timestep the number of steps, the phase times and C (as hexadecimal floats,
// exact) and a 64-bit FNV-1a hash of the bytes of qpos and ctrl over every 100 steps (so
// a difference is found to within 100 steps).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "physics/rollout.h"
#include "support/text_files.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {
namespace {

const std::string kReference = std::string(DIVERSE_SOURCE_DIR) + "/tests/control/data/walk_replay_reference.txt";
constexpr int kChunk = 100;  // steps per hash

std::string hex(double v) {
  char text[64];
  std::snprintf(text, sizeof text, "%a", v);
  return text;
}

uint64_t fnv1a(const double* begin, size_t count, uint64_t h = 1469598103934665603ull) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(begin);
  for (size_t i = 0; i < count * sizeof(double); ++i) h = (h ^ bytes[i]) * 1099511628211ull;
  return h;
}

// The lines that describe one rollout of `task`'s input motion at `scale` times its step.
std::vector<std::string> describe(const Task& task, const std::string& name, double scale) {
  const TaskEvaluator eval(task);
  const ParameterSet m0 = eval.load_parameters(task.m0);
  StepRecorder record;
  EvaluationOptions o;
  o.timestep_scale = scale;
  o.recorder = &record;
  auto worker = eval.make_worker();
  const Evaluation e = eval.evaluate(m0.values(), *worker, o);
  std::vector<std::string> lines;
  const std::string head = name + " x" + hex(scale) + " ";
  lines.push_back(head + "steps " + std::to_string(record.steps()));
  lines.push_back(head + "C " + hex(e.constraint));
  std::string times;
  for (size_t p = 0; p < e.phases.begin.size(); ++p) times += " " + e.phases.names[p] + "=" + hex(e.phases.begin[p]);
  lines.push_back(head + "phases" + times);
  std::string params;
  for (const ParamSpec& s : m0.specs()) params += " " + s.name + "[" + hex(s.lower) + "," + hex(s.upper) + "]";
  lines.push_back(head + "parameters" + params);
  lines.push_back(head + "qpos0 " + std::to_string(fnv1a(record.qpos0.data(), record.qpos0.size())));
  const size_t nq = static_cast<size_t>(record.nq), nu = static_cast<size_t>(record.nu);
  for (int first = 0; first < record.steps(); first += kChunk) {
    const size_t n = static_cast<size_t>(std::min(kChunk, record.steps() - first));
    const uint64_t h = fnv1a(record.ctrl.data() + first * nu, n * nu, fnv1a(record.qpos.data() + first * nq, n * nq));
    lines.push_back(head + "steps " + std::to_string(first) + "+ " + std::to_string(h));
  }
  return lines;
}

class WalkReplay : public ::testing::TestWithParam<const char*> {};

TEST_P(WalkReplay, SameRolloutAsWalk3dGave) {
  const std::string name = GetParam();
  const Task task = load_task(std::string(DIVERSE_SOURCE_DIR) + "/tasks/" + name + ".toml");
  ASSERT_EQ(task.controller, "skill");
  ASSERT_TRUE(task.walk.enabled);
  std::vector<std::string> expected;
  {
    std::istringstream in(test_files::read_text(kReference));
    for (std::string line; std::getline(in, line);)
      if (line.rfind(name + " x", 0) == 0) expected.push_back(line);
  }
  std::vector<std::string> got;
  for (double scale : {1.0, 0.5}) {
    const std::vector<std::string> lines = describe(task, name, scale);
    EXPECT_EQ(lines[1], name + " x" + hex(scale) + " C 0x0p+0") << "the input walk meets its task";
    got.insert(got.end(), lines.begin(), lines.end());
  }
  ASSERT_GT(expected.size(), 40u) << kReference;
  ASSERT_EQ(got.size(), expected.size());
  // The first line that differs (a chunk of 100 steps, or a figure).
  for (size_t i = 0; i < got.size(); ++i) ASSERT_EQ(got[i], expected[i]) << "line " << i;
}

INSTANTIATE_TEST_SUITE_P(Walks, WalkReplay, ::testing::Values("silly_walk", "robot_silly_walk"),
                         [](const ::testing::TestParamInfo<const char*>& param) { return std::string(param.param); });

}  // namespace
}  // namespace diverse
