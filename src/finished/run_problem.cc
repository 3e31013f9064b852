#include "finished/run_problem.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include "core/error.h"
#include "core/thread_pool.h"
#include "io/files.h"
#include "metric/metric.h"
#include "task/task.h"

namespace diverse {
namespace fs = std::filesystem;

ParameterSet named_parameters(const ParameterSet& like, nlohmann::json values, const std::string& origin) {
  ParameterSet set = like;
  if (values.is_object()) {
    for (const ParamSpec& spec : set.specs()) {
      auto it = values.find(spec.name);
      if (it == values.end() || !it->is_number()) continue;
      const double v = it->get<double>();
      const double slack = 1e-9 * std::abs(spec.upper - spec.lower);
      if (v > spec.upper && v <= spec.upper + slack) *it = spec.upper;
      if (v < spec.lower && v >= spec.lower - slack) *it = spec.lower;
    }
  }
  set.set_from_json(values, origin);
  return set;
}

ParameterSet motion_parameters(const ParameterSet& like, const fs::path& motion_file) {
  const nlohmann::json motion = read_json(motion_file);
  if (!motion.is_object() || !motion.contains("parameters"))
    throw_field_error(motion_file.string(), "parameters", "the motion's named controller parameters");
  return named_parameters(like, motion["parameters"], motion_file.string());
}

RunProblem open_run_problem(const RunView& run, int threads, const std::string& consequence) {
  const fs::path run_file = run.dir / "run.json";
  const std::string task_file = run.run.value("task_file", std::string());
  if (task_file.empty() || !fs::exists(task_file))
    throw UserError(run_file.string() + ": task_file: " + task_file + " is missing; " + consequence);
  if (read_file(task_file) != run.run.value("task_text", std::string()))
    throw UserError(run_file.string() + ": task_file: " + task_file + " changed since the run; " + consequence);
  // The run's strength model and bounds (absent in older runs: 1 and none), so that new
  // points are simulated and judged as the run judged its samples.
  Task task = load_task(task_file);
  const nlohmann::json strength = run.run.value("strength", nlohmann::json(1.0));
  if (!strength.is_number() || !(strength.get<double>() >= kMinStrength && strength.get<double>() <= kMaxStrength))
    throw_field_error(run_file.string(), "strength", "expected a number in [0.1, 10]");
  task.strength = strength.get<double>();
  const MotionBounds bounds = motion_bounds_from_json(run.run.value("bounds", nlohmann::json()), run_file.string());
  RunProblem p;
  auto evaluator = std::make_unique<const TaskEvaluator>(std::move(task));
  const DistanceSpec distance =
      parse_distance(run.metric, run.run.value("shape_weight", kDefaultShapeWeight),
                     (run.dir / "summary.json").string() + ": metric", run_file.string() + ": shape_weight");
  const nlohmann::json vary = run.run.value("vary", nlohmann::json::array());
  p.vary_shape = std::find(vary.begin(), vary.end(), "shape") != vary.end();
  p.like = evaluator->parameters();
  if (p.vary_shape) p.like = evaluator->with_shape(p.like, evaluator->shapes().identity());
  for (const RunMotion& m : run.motions) p.motions.push_back(motion_parameters(p.like, m.file).normalized());
  const int workers = threads > 0 ? threads : ThreadPool::hardware_threads();
  p.problem = std::make_unique<const MotionProblem>(*evaluator, distance, p.motions.front(), workers, p.vary_shape,
                                                    bounds);
  p.evaluator = std::move(evaluator);
  return p;
}

std::vector<RunPathPoint> read_run_path(const RunView& run, std::size_t variation, const ParameterSet& like) {
  const fs::path file = run.dir / "paths" / std::string("m").append(std::to_string(variation)).append(".json");
  if (!fs::exists(file))
    throw UserError(file.string() + ": missing; the run directory is incomplete (`diverse resume " +
                    run.dir.string() + "` writes its outputs again)");
  const nlohmann::json path = read_json(file);
  if (!path.is_object() || !path.contains("points") || !path["points"].is_array())
    throw_field_error(file.string(), "points", "a list of path points");
  std::vector<RunPathPoint> points;
  for (std::size_t k = 0; k < path["points"].size(); ++k) {
    const nlohmann::json& p = path["points"][k];
    const std::string field = "points[" + std::to_string(k) + "]";
    if (!p.is_object() || !p.contains("parameters"))
      throw_field_error(file.string(), field, "an object with \"parameters\"");
    const ParameterSet set = named_parameters(like, p["parameters"], file.string() + ": " + field);
    points.push_back({set.normalized(), p.value("generation", -1LL), p.value("step", -1LL), false});
  }
  const ParameterSet result = motion_parameters(like, run.motions[variation].file);
  points.push_back({result.normalized(), -1, -1, true});
  return points;
}

std::string run_fingerprint(const RunView& run) {
  nlohmann::json s = run.summary;
  if (s.is_object()) s.erase("timing");
  const std::string text = s.dump();
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

}  // namespace diverse
