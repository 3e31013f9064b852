#include "run/outputs.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/rng.h"
#include "finished/run_view.h"
#include "io/files.h"
#include "io/motion_record.h"
#include "physics/model.h"
#include "render/run_media.h"
#include "robust/robustness.h"

namespace diverse {
namespace fs = std::filesystem;

namespace {

nlohmann::json matrix_json(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    std::vector<double> row(static_cast<std::size_t>(m.cols()));
    for (Eigen::Index j = 0; j < m.cols(); ++j) row[static_cast<std::size_t>(j)] = m(i, j);
    rows.push_back(row);
  }
  return rows;
}

// (Built with append: GCC 12 warns falsely (-Wrestrict) on "literal" + std::string.)
std::string numbered(char prefix, std::size_t i) {
  std::string s(1, prefix);
  s.append(std::to_string(i));
  return s;
}
std::string label(std::size_t i) { return numbered('M', i); }

// The half-timestep check of a re-simulated motion (task/constraints.h): null when the
// task does not ask for it or the motion did not meet the task at its own timestep;
// otherwise whether it holds, with the term's violation and penalty.
nlohmann::json half_timestep_json(const Evaluation& e) {
  for (const ConstraintTerm& t : e.report.terms) {
    if (t.name == "half_timestep")
      return {{"holds", t.penalty == 0}, {"violation", t.violation}, {"penalty", t.penalty}};
  }
  return nullptr;
}
std::string stem(std::size_t i) { return numbered('m', i); }

}  // namespace

void write_run_outputs(const RunOutputs& o) {
  const DiversityResult result = o.optimizer.result();
  const DiversityOptions& options = o.optimizer.options();
  const std::size_t count = result.parameters.size();

  // Log: one record per step.
  std::string log;
  for (const DiversityRecord& r : o.optimizer.log()) log += to_json(r).dump() + "\n";
  write_file_atomic(o.dir / "log.jsonl", log);

  // Optimization paths as named parameters.
  const auto& paths = o.optimizer.paths();
  for (std::size_t v = 1; v < paths.size(); ++v) {
    nlohmann::json points = nlohmann::json::array();
    for (const PathPoint& point : paths[v])
      points.push_back({{"generation", point.generation},
                        {"step", point.step},
                        {"parameters", o.problem.named(point.x).to_json()}});
    write_json_atomic(o.dir / "paths" / (stem(v) + ".json"),
                      {{"variation", v}, {"metric", to_string(o.problem.distance_spec())}, {"points", points}});
  }

  // Every metric on the final outcomes: the motion metrics, the shape metric, and the
  // objective's combination if it is one.
  const DistanceSpec objective = o.problem.distance_spec();
  nlohmann::json distances;
  distances["objective"] = to_string(objective);
  std::vector<DistanceSpec> specs;
  for (Metric metric : kMotionMetrics) specs.push_back({metric, 0.0});
  specs.push_back({Metric::kShape, 0.0});
  if (objective.combined()) specs.push_back(objective);
  for (const DistanceSpec& spec : specs) {
    Eigen::MatrixXd d = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(count),
                                              static_cast<Eigen::Index>(count));
    for (std::size_t i = 0; i < count; ++i)
      for (std::size_t j = i + 1; j < count; ++j) {
        const auto& a = *result.outcomes[i];
        const auto& b = *result.outcomes[j];
        const double v = (is_failure(a) || is_failure(b)) ? 0.0 : o.problem.distance(a, b, spec);
        d(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = v;
        d(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(i)) = v;
      }
    distances[to_string(spec)] = matrix_json(d);
  }

  // The scale of "different": the mean distance between M0 and M0 nudged by 0.01 (in
  // normalized parameter units, 4 fixed draws). Variations should be far above it.
  constexpr int kNudges = 4;
  std::vector<double> nudge_distance(kNudges, 0.0);
  const Eigen::VectorXd x0 = result.parameters[0];
  o.pool.parallel_for(kNudges, [&](std::size_t k, int worker) {
    Rng rng(derive_seed(options.seed, {0x6e75646765ULL, k}));
    Eigen::VectorXd x = x0;
    for (Eigen::Index j = 0; j < x.size(); ++j)
      x[j] = std::clamp(x[j] + 0.01 * rng.normal(), 0.0, 1.0);
    const auto nudged = o.problem.evaluate(x, worker);
    nudge_distance[k] = is_failure(*nudged) ? 0.0 : o.problem.distance(*result.outcomes[0], *nudged);
  });
  double nudge_mean = 0;
  for (double d : nudge_distance) nudge_mean += d / kNudges;

  // Motion files (re-simulated with recording on) and the film strip rows.
  fs::create_directories(o.dir / "motions");
  fs::create_directories(o.dir / "model");
  std::vector<Evaluation> evaluations(count);
  std::vector<StepRecorder> records(count);
  o.pool.parallel_for(count, [&](std::size_t i, int) {
    const MotionRecordInfo info{label(i), o.dir / "model" / (stem(i) + ".xml")};
    evaluations[i] = write_motion(o.evaluator, o.problem.named(result.parameters[i]), info,
                                  o.dir / "motions" / (stem(i) + ".json"),
                                  &records[i]);
  });

  // How far each motion's planted feet slide (task/foot_slip.h), from a plain-MuJoCo
  // replay of the record just written on the model just saved.
  std::vector<nlohmann::json> foot_slips(count);
  o.pool.parallel_for(count, [&](std::size_t i, int) {
    foot_slips[i] = foot_slip_json(motion_file_foot_slip(o.dir / "motions" / (stem(i) + ".json"),
                                                         o.evaluator.task().character_spec));
  });

  // A character without shape parameters has no scales and no link lengths.
  const ShapeSpace* shapes = o.evaluator.has_shape() ? &o.evaluator.shapes() : nullptr;
  // Effort and distance from M0 of every motion, and whether it keeps the run's bounds.
  const MotionBounds& bounds = o.problem.bounds();
  const auto& m0_outcome = static_cast<const MotionOutcome&>(*result.outcomes[0]);
  nlohmann::json motions = nlohmann::json::array();
  for (std::size_t i = 0; i < count; ++i) {
    const auto& outcome = static_cast<const MotionOutcome&>(*result.outcomes[i]);
    const double effort_ratio = m0_outcome.effort > 0 ? outcome.effort / m0_outcome.effort : 0.0;
    const double from_m0 = (is_failure(outcome) || is_failure(m0_outcome))
                               ? 0.0 : o.problem.distance(outcome, m0_outcome);
    const bool within = !is_failure(outcome) &&
                        (bounds.effort <= 0 || effort_ratio <= bounds.effort) &&
                        (bounds.distance <= 0 || from_m0 <= bounds.distance);
    const auto idx = static_cast<Eigen::Index>(i);
    nlohmann::json scales = nlohmann::json::object();
    for (int p = 0; p < outcome.scales.size(); ++p)
      scales[shapes->specs()[static_cast<std::size_t>(p)].name] = outcome.scales[p];
    const Eigen::VectorXd& lengths = outcome.features.link_lengths;
    motions.push_back({{"index", i},
                       {"label", label(i)},
                       {"constraint", result.score.constraint[idx]},
                       {"dmin", result.score.dmin[idx]},
                       {"task_constraint", outcome.task_constraint},
                       {"effort", outcome.effort},
                       {"effort_ratio", effort_ratio},
                       {"positive_work", outcome.positive_work},
                       {"distance_to_m0", from_m0},
                       {"within_bounds", within},
                       {"fell", outcome.fell},
                       {"failed", outcome.failed},
                       {"landing_x", outcome.landing_x},
                       {"peak_com_z", outcome.peak_com_z},
                       {"half_timestep", half_timestep_json(evaluations[i])},
                       {"foot_slip", foot_slips[i]},
                       {"shape_scales", scales},
                       {"link_lengths", std::vector<double>(lengths.data(), lengths.data() + lengths.size())},
                       {"file", "motions/" + stem(i) + ".json"}});
  }

  // How many of the optimizer's samples met their constraints (C = 0, bounds included).
  long long samples = 0, feasible = 0;
  for (const DiversityRecord& r : o.optimizer.log()) {
    samples += r.samples;
    feasible += r.feasible;
  }

  const TaskEvaluator& ev = o.evaluator;
  nlohmann::json summary = {
      {"format", "diverse.summary"},
      {"version", 1},
      {"task", ev.task().name},
      {"task_file", ev.task().file},
      {"metric", to_string(objective)},
      {"vary", o.problem.vary_shape() ? nlohmann::json{"control", "shape"} : nlohmann::json{"control"}},
      {"N", options.variations},
      {"K", options.k},
      {"strategy", to_string(options.strategy)},
      {"seed", options.seed},
      {"popsize", options.popsize},
      {"sigma0", options.sigma0},
      {"max_generations", options.max_generations},
      {"generations", result.generations},
      {"evaluations", result.evaluations},
      {"confirmations", o.optimizer.confirmations()},
      {"steps", o.optimizer.ledger()},
      {"stop", to_string(result.stop)},
      {"D", result.score.D},
      {"all_satisfied", (result.score.constraint.array() == 0.0).all()},
      {"strength", ev.task().strength},
      {"bounds", to_json(bounds)},
      {"samples", samples},
      {"feasible_samples", feasible},
      {"link_names", shapes ? shapes->link_names() : std::vector<std::string>()},
      {"motions", motions},
      {"distances", distances},
      {"nudged_m0_distance", nudge_mean},
      {"timing",
       {{"wall_seconds", o.wall_seconds},
        {"threads", o.pool.size()},
        {"ranks", o.ranks},
        {"evaluations_per_second",
         o.wall_seconds > 0 ? static_cast<double>(result.evaluations) / o.wall_seconds : 0.0}}}};
  if (objective.combined()) summary["shape_weight"] = objective.shape_weight;
  if (!o.messages.is_null()) summary["timing"]["messages"] = o.messages;
  if (!o.rollouts.is_null()) summary["timing"]["rollouts"] = o.rollouts;
  // D, C and dmin above are under it; "distances" and distance_to_m0 are the built-in metrics'.
  if (!o.custom.is_null()) summary["custom"] = o.custom;

  // The robustness suite (robust/robustness.h) on every motion: robustness.json in full,
  // and each motion's shares, by kind and over all, in the summary.
  std::vector<MotionUnderTest> under_test;
  for (std::size_t i = 0; i < count; ++i)
    under_test.push_back({label(i), static_cast<int>(i), o.problem.named(result.parameters[i])});
  const nlohmann::json suite = robustness_json(o.evaluator, under_test, RobustnessSuite{}, o.pool);
  write_json_atomic(o.dir / "robustness.json", suite);
  nlohmann::json shares = nlohmann::json::array();
  for (const nlohmann::json& m : suite.at("motions")) {
    nlohmann::json kinds = nlohmann::json::object();
    for (const auto& [key, kind] : m.at("kinds").items())
      kinds[key] = {{"held", kind.at("held")}, {"count", kind.at("count")}};
    shares.push_back({{"label", m.at("label")}, {"held", m.at("held")}, {"count", m.at("count")},
                      {"share", m.at("share")}, {"kinds", kinds}});
  }
  summary["robustness"] = {{"suite", suite.at("suite")}, {"motions", shares}};
  write_json_atomic(o.dir / "summary.json", summary);

  // The film strip is drawn from the files just written, as `diverse render` draws it.
  if (o.render) write_run_film_strip(load_run_view(o.dir), o.dir / "filmstrip.png");
}

}  // namespace diverse
