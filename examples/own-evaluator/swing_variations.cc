// Diverse ways to swing an arm up, found with the installed diverse library on a problem of
// this project's own: a two-link arm (arm.xml) under a PD controller that tracks two
// poses, one after the other. The task: after 1.5 s the arm's tip is at least 1.6 m high
// (the shoulder is at 1 m; hanging, the tip is at 0). The distance between two swings: how
// far apart their tips travel, summed over 15 moments. diverse's optimizer finds N swings
// that all meet the task and are as different from each other as it can make them.
//
//   swing_variations [N] [GENERATIONS] [SEED]
//
// Prints each swing's parameters, constraint value and nearest distance, and D.
#include <mujoco/mujoco.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "core/thread_pool.h"
#include "optimize/diversity.h"
#include "optimize/objective.h"

namespace {

// The controller's parameters, each scaled from [0, 1]: the first pose (shoulder, elbow),
// the time it switches to the second pose, the second pose.
constexpr int kParameters = 5;
constexpr double kSeconds = 1.5;
constexpr int kSamples = 15;  // tip positions kept for the distance
constexpr double kTipHeight = 1.6;

struct Swing : diverse::Outcome {
  std::array<std::array<double, 2>, kSamples> tip{};  // x, z
};

class SwingProblem : public diverse::DiversityProblem {
 public:
  SwingProblem(const char* xml, int workers) {
    char error[1000] = "";
    model_ = mj_loadXML(xml, nullptr, error, sizeof error);
    if (!model_) {
      std::fprintf(stderr, "swing_variations: %s: %s\n", xml, error);
      std::exit(2);
    }
    for (int w = 0; w < workers; ++w) data_.push_back(mj_makeData(model_));
    tip_ = mj_name2id(model_, mjOBJ_SITE, "tip");
  }
  ~SwingProblem() override {
    for (mjData* d : data_) mj_deleteData(d);
    mj_deleteModel(model_);
  }

  int dim() const override { return kParameters; }

  // The reference swing M0: shoulder back, elbow bent, then both forward and up.
  Eigen::VectorXd reference() const override {
    Eigen::VectorXd x(kParameters);
    x << 0.30, 0.75, 0.40, 0.95, 0.50;
    return x;
  }

  std::shared_ptr<const diverse::Outcome> evaluate(const Eigen::VectorXd& x, int worker) const override {
    mjData* d = data_[static_cast<std::size_t>(worker)];
    mj_resetData(model_, d);
    const double pose1[2] = {-3 + 6 * x[0], -3 + 6 * x[1]};
    const double switch_time = 0.2 + 0.8 * x[2];
    const double pose2[2] = {-3 + 6 * x[3], -3 + 6 * x[4]};
    auto swing = std::make_shared<Swing>();
    const int steps = static_cast<int>(std::lround(kSeconds / model_->opt.timestep));
    int sample = 0;
    for (int k = 0; k < steps; ++k) {
      const double* target = d->time < switch_time ? pose1 : pose2;
      for (int j = 0; j < 2; ++j)
        d->ctrl[j] = std::clamp(120.0 * (target[j] - d->qpos[j]) - 12.0 * d->qvel[j], -40.0, 40.0);
      mj_step(model_, d);
      if (!std::isfinite(d->qpos[0])) {
        swing->failed = true;
        swing->constraint = diverse::kFailedConstraint;
        return swing;
      }
      if ((k + 1) % (steps / kSamples) == 0 && sample < kSamples) {
        const double* p = d->site_xpos + 3 * tip_;
        swing->tip[static_cast<std::size_t>(sample++)] = {p[0], p[2]};
      }
    }
    const double z = d->site_xpos[3 * tip_ + 2];
    swing->constraint = z >= kTipHeight ? 0.0 : 100.0 * (kTipHeight - z) * (kTipHeight - z);
    return swing;
  }

  double distance(const diverse::Outcome& a, const diverse::Outcome& b) const override {
    const auto& p = static_cast<const Swing&>(a).tip;
    const auto& q = static_cast<const Swing&>(b).tip;
    double sum = 0;
    for (int k = 0; k < kSamples; ++k)
      sum += std::hypot(p[static_cast<std::size_t>(k)][0] - q[static_cast<std::size_t>(k)][0],
                        p[static_cast<std::size_t>(k)][1] - q[static_cast<std::size_t>(k)][1]);
    return sum;
  }

 private:
  mjModel* model_ = nullptr;
  std::vector<mjData*> data_;
  int tip_ = -1;
};

}  // namespace

int main(int argc, char** argv) {
  diverse::DiversityOptions options;
  options.variations = argc > 1 ? std::atoi(argv[1]) : 3;
  options.max_generations = argc > 2 ? std::atoll(argv[2]) : 40;
  options.seed = argc > 3 ? std::strtoull(argv[3], nullptr, 10) : 1;
  options.popsize = 8;
  options.sigma0 = 0.1;

  const int threads = 2;
  diverse::ThreadPool pool(threads);
  const SwingProblem problem(ARM_XML, threads);
  const auto m0 = problem.evaluate(problem.reference(), 0);
  std::printf("M0: C = %.4g (tip %s)\n", m0->constraint, m0->constraint == 0 ? "high enough" : "too low");

  diverse::DiversityOptimizer optimizer(problem, options, pool);
  optimizer.run();
  const diverse::DiversityResult result = optimizer.result();

  int met = 0;
  for (std::size_t i = 0; i < result.parameters.size(); ++i) {
    const Eigen::VectorXd& x = result.parameters[i];
    std::printf("M%zu: pose 1 (%.2f, %.2f) rad, switch at %.2f s, pose 2 (%.2f, %.2f) rad; C = %.4g, dmin = %.3f\n",
                i, -3 + 6 * x[0], -3 + 6 * x[1], 0.2 + 0.8 * x[2], -3 + 6 * x[3], -3 + 6 * x[4],
                result.score.constraint[static_cast<Eigen::Index>(i)], result.score.dmin[static_cast<Eigen::Index>(i)]);
    if (i > 0 && result.score.constraint[static_cast<Eigen::Index>(i)] == 0.0) ++met;
  }
  std::printf("D = %.4f after %lld generations, %lld evaluations (%s)\n", result.score.D, result.generations,
              result.evaluations, diverse::to_string(result.stop));
  std::printf("%d of %d variations meet the task\n", met, options.variations);
  return met == options.variations ? 0 : 1;
}
