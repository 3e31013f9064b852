// The 2D jumps as skill files (skills/): each committed task, which names its skill, gives
// its input motion the rollout it gave under the C++ controller the tasks ran before
// ("jump2d", with the keys each task gave it), to the last bit: the fingerprints of its
// qpos and ctrl at every step, its C and its phase times, at the task's timestep and at half
// of it, were taken from the engine after its rollouts and that controller's had been
// compared equal step by step (qpos and ctrl, C, phase times, and the parameters' names,
// ranges and order), before the controller was removed. The same for the tailwalker's leap
// (examples/own-character/leap.toml), which named "jump2d" with the paper's keys and names
// skills/jump2d.toml now. The input motions' parameter files are read strictly, so every
// parameter keeps its name.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "physics/rollout.h"
#include "support/fingerprint.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {
namespace {

const std::string kSource = DIVERSE_SOURCE_DIR;

using test_files::fingerprint;

// One rollout of a task's input motion: its steps, the fingerprints of qpos and ctrl at
// every step, C and the phases' begin times (s), as hex floats.
struct Pinned {
  double scale;
  int steps;
  uint64_t qpos, ctrl;
  double constraint;
  std::vector<double> begin;
};

void expect_pinned(const std::string& file, size_t parameters, const std::vector<Pinned>& pinned) {
  const Task task = load_task(file);
  ASSERT_EQ(task.controller, "skill");
  const TaskEvaluator ev(task);
  EXPECT_EQ(ev.parameters().size(), parameters) << file;
  const ParameterSet m0 = ev.load_parameters(task.m0);
  for (const Pinned& p : pinned) {
    StepRecorder record;
    EvaluationOptions o;
    o.timestep_scale = p.scale;
    o.recorder = &record;
    auto worker = ev.make_worker();
    const Evaluation e = ev.evaluate(m0.values(), *worker, o);
    EXPECT_EQ(record.steps(), p.steps) << file << " x" << p.scale;
    EXPECT_EQ(fingerprint(record.qpos), p.qpos) << file << " x" << p.scale << ": qpos 0x" << std::hex << fingerprint(record.qpos);
    EXPECT_EQ(fingerprint(record.ctrl), p.ctrl) << file << " x" << p.scale << ": ctrl 0x" << std::hex << fingerprint(record.ctrl);
    EXPECT_EQ(e.constraint, p.constraint) << file << " x" << p.scale;
    EXPECT_EQ(e.phases.names, (std::vector<std::string>{"start", "crouch", "extend", "rise", "fall", "land"})) << file;
    EXPECT_EQ(e.phases.begin, p.begin) << file << " x" << p.scale;
  }
}

TEST(SkillReplay, TheFivePlanarJumpsAsUnderJump2d) {
  const std::map<std::string, std::pair<size_t, std::vector<Pinned>>> tasks = {
      {"backflip",
       {90,
        {{1.0, 1152, 0xc88fc014cba8fe06ull, 0x89840f2edea3360eull, 0.0,
          {0x0p+0, 0x1.4395810624dd7p-3, 0x1.10624dd2f1aa3p-2, 0x1.9fbe76c8b439bp-2, 0x1.83126e978d503p-1, 0x1.ed916872b0213p-1}},
         {0.5, 2293, 0x0a58ae269837399cull, 0xf6cc4b23b0331516ull, 0.0,
          {0x0p+0, 0x1.4395810624dd7p-3, 0x1.0f5c28f5c28f9p-2, 0x1.9cac083126e9dp-2, 0x1.851eb851eb857p-1, 0x1.ec083126e9794p-1}}}}},
      {"jump_forward",
       {90,
        {{1.0, 710, 0xf96a93561772e880ull, 0xb60e1c0ce0f32f28ull, 0.0,
          {0x0p+0, 0x1.1db22d0e56045p-2, 0x1.5cac083126e9cp-1, 0x1.926e978d4fdf9p-1, 0x1.e5604189374c3p-1, 0x1.20c49ba5e352ep+0}},
         {0.5, 1421, 0x6016417b0092e4f2ull, 0x4618e3960b7842fdull, 0.0,
          {0x0p+0, 0x1.1db22d0e56045p-2, 0x1.5cac083126e6p-1, 0x1.91a9fbe76c85bp-1, 0x1.e624dd2f1a96dp-1, 0x1.2189374bc6a46p+0}}}}},
      {"jump_over",
       {90,
        {{1.0, 1174, 0xc0a95c27858242f2ull, 0x11e8451bffa1155full, 0.0,
          {0x0p+0, 0x1.916872b020c4fp-3, 0x1.0c49ba5e353fbp-1, 0x1.46a7ef9db22d5p-1, 0x1.e147ae147ae1bp-1, 0x1.4a3d70a3d70a8p+0}},
         {0.5, 2350, 0x2f187f61ee8851aeull, 0xf3f2db76373b5fedull, 0.0,
          {0x0p+0, 0x1.8f5c28f5c28fbp-3, 0x1.0b43958106251p-1, 0x1.45a1cac08312bp-1, 0x1.e04189374bc71p-1, 0x1.49374bc6a7e6fp+0}}}}},
      {"jump_high",
       {87,
        {{1.0, 567, 0x66bf117cd8e9e6f6ull, 0x570f2847e261d5bdull, 0.0,
          {0x0p+0, 0x1.5c28f5c28f5c7p-2, 0x1.70a3d70a3d70fp-1, 0x1.a7ef9db22d0ebp-1, 0x1.09374bc6a7efdp+0, 0x1.449ba5e353f81p+0}},
         {0.5, 1131, 0xa062b35e46cce34aull, 0xb979e163ee248abfull, 0.0,
          {0x0p+0, 0x1.5a1cac0831273p-2, 0x1.6e978d4fdf3bbp-1, 0x1.a2d0e56041899p-1, 0x1.072b020c49ba9p+0, 0x1.428f5c28f5c2dp+0}}}}},
      {"jump_onto",
       {90,
        {{1.0, 1104, 0x6838df62a0152f08ull, 0x09ddee2677260b23ull, 0.0,
          {0x0p+0, 0x1.1a9fbe76c8b47p-3, 0x1.666666666666bp-1, 0x1.a6e978d4fdf41p-1, 0x1.06a7ef9db22d4p+0, 0x1.3020c49ba5e39p+0}},
         {0.5, 2203, 0xc6f728914aea3ee4ull, 0x2f8f20005459c813ull, 0.0,
          {0x0p+0, 0x1.189374bc6a7f3p-3, 0x1.65604189374c1p-1, 0x1.a5e353f7ced97p-1, 0x1.05e353f7ced89p+0, 0x1.2f1a9fbe76c33p+0}}}}},
  };
  for (const auto& [task, pins] : tasks) expect_pinned(kSource + "/tasks/" + task + ".toml", pins.first, pins.second);
}

// Another character: the tailwalker's leap under the paper's jump.
TEST(SkillReplay, TheTailwalkersLeapAsUnderJump2d) {
  expect_pinned(kSource + "/examples/own-character/leap.toml", 84,
                {{1.0, 1150, 0xf33ef3da53ffdc24ull, 0xa96fc2b4f2c2837aull, 0.0,
                  {0x0p+0, 0x1.1374bc6a7efa1p-1, 0x1.65604189374c1p-1, 0x1.6b851eb851ebdp-1, 0x1.b4395810624e3p-1, 0x1.fdf3b645a1cb3p-1}},
                 {0.5, 2358, 0xdbb67ef2d0ea64edull, 0x5f79007a532f4c7bull, 0.0,
                  {0x0p+0, 0x1.1374bc6a7efa1p-1, 0x1.64dd2f1a9fbecp-1, 0x1.6b020c49ba5e8p-1, 0x1.b126e978d4fe5p-1, 0x1.0189374bc6a7fp+0}}});
}

}  // namespace
}  // namespace diverse
