// Offscreen rendering cost (OSMesa, llvmpipe, no GPU): milliseconds per 240x240 picture of
// the planar human (assets/characters/human2d.xml) in a jump pose, with the default style
// (2x supersampling, shadows) and with each of those turned off, plus the one-off cost of
// creating a renderer (GL context, MuJoCo's GL resources). docs/guide/rendering.md lists
// measured values.
//
//   diverse_bench --benchmark_filter=Render
#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/offscreen.h"

namespace diverse {
namespace {

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};

std::unique_ptr<mjModel, ModelDeleter> load_human() {
  const std::string path = std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/human2d.xml";
  char error[1000] = "";
  std::unique_ptr<mjModel, ModelDeleter> model(mj_loadXML(path.c_str(), nullptr, error, 1000));
  if (!model) throw std::runtime_error(path + ": " + error);
  return model;
}

// Crouched before take-off, one metre along the floor.
std::vector<double> crouch(const mjModel* m) {
  std::vector<double> q(m->nq, 0.0);
  auto set = [&](const char* joint, double value) {
    q[m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, joint)]] = value;
  };
  set("rootx", 1.0);
  set("rootz", -0.25);
  set("rooty", -0.4);
  for (const char* side : {"_l", "_r"}) {
    set((std::string("hip") + side).c_str(), 1.2);
    set((std::string("knee") + side).c_str(), -1.8);
    set((std::string("ankle") + side).c_str(), 0.6);
    set((std::string("shoulder") + side).c_str(), -0.8);
  }
  return q;
}

// range(0): picture side in pixels; range(1): supersampling; range(2): shadows on/off.
void BM_RenderFrame(benchmark::State& state) {
  const auto model = load_human();
  const int size = static_cast<int>(state.range(0));
  RenderStyle style;
  style.supersample = static_cast<int>(state.range(1));
  style.shadows = state.range(2) != 0;
  OffscreenRenderer renderer(model.get(), size, size, style);
  const std::vector<double> qpos = crouch(model.get());
  SideCamera camera;
  camera.lookat = {1.0, 0.0, 0.8};
  camera.distance = 7.0;
  std::vector<double> pose = qpos;
  int frame = 0;
  for (auto _ : state) {
    pose[0] = qpos[0] + 0.01 * (frame++ % 50);  // a new pose every picture
    Image image = renderer.render(pose, camera);
    benchmark::DoNotOptimize(image.data());
  }
  state.counters["frames_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RenderFrame)
    ->ArgNames({"px", "ss", "shadows"})
    ->Args({240, 2, 1})
    ->Args({240, 2, 0})
    ->Args({240, 1, 1})
    ->Args({240, 1, 0})
    ->Args({480, 2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_CreateRenderer(benchmark::State& state) {
  const auto model = load_human();
  for (auto _ : state) {
    OffscreenRenderer renderer(model.get(), 240, 240);
    benchmark::DoNotOptimize(&renderer);
  }
}
BENCHMARK(BM_CreateRenderer)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace diverse
