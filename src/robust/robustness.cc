#include "robust/robustness.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "core/error.h"
#include "core/rng.h"
#include "task/pushes.h"

namespace diverse {
namespace {

// One perturbed rollout to run: its options and parameters, and what to report of it.
struct Job {
  std::size_t motion = 0;
  PerturbedRollout rollout;
  ParameterSet parameters;
  EvaluationOptions options;
};

EvaluationOptions judged_options() {
  EvaluationOptions o;
  o.samples_per_phase = 0;        // no pose samples: only C is needed
  o.half_timestep_check = true;   // as a run judges its samples, when the task asks for it
  return o;
}

// The perturbed rollouts of motion `m` (see the header), in order of kind and sample.
std::vector<Job> make_jobs(const TaskEvaluator& evaluator, const MotionUnderTest& motion, std::size_t m,
                           const Evaluation& base, const RobustnessSuite& suite) {
  std::vector<Job> jobs;
  const auto index = static_cast<std::uint64_t>(motion.index);
  const Eigen::VectorXd x = motion.parameters.normalized();
  for (int s = 0; s < suite.parameter_samples; ++s) {
    Rng rng(derive_seed(suite.seed, {index, static_cast<std::uint64_t>(PerturbationKind::kParameters),
                                     static_cast<std::uint64_t>(s)}));
    Eigen::VectorXd y(x.size());
    for (int i = 0; i < x.size(); ++i) y[i] = mirror_unit(x[i] + suite.sigma * rng.normal());
    Job job;
    job.motion = m;
    job.rollout.kind = PerturbationKind::kParameters;
    job.rollout.sample = s;
    job.rollout.distance = (y - x).norm();
    job.parameters = motion.parameters;
    job.parameters.set_normalized(y);
    // The linear map back may land an ulp outside a range at 0 or 1: put it on the bound.
    for (int i = 0; i < job.parameters.size(); ++i) {
      const ParamSpec& spec = job.parameters.specs()[static_cast<std::size_t>(i)];
      double& v = job.parameters.values()[static_cast<std::size_t>(i)];
      v = std::clamp(v, std::min(spec.lower, spec.upper), std::max(spec.lower, spec.upper));
    }
    job.options = judged_options();
    jobs.push_back(std::move(job));
  }
  const bool planar = evaluator.body().root == RootKind::kPlanar;
  const GroundWindows windows = ground_windows(evaluator.task(), base);
  for (int s = 0; s < suite.push_samples; ++s) {
    Rng rng(derive_seed(suite.seed, {index, static_cast<std::uint64_t>(PerturbationKind::kPush),
                                     static_cast<std::uint64_t>(s)}));
    const PushDraw draw = draw_push(windows, s, planar, suite.first_push_phase, rng.uniform(), suite.push_speed);
    Job job;
    job.motion = m;
    job.rollout.kind = PerturbationKind::kPush;
    job.rollout.sample = s;
    job.rollout.phase = draw.phase;
    job.rollout.direction = draw.direction;
    job.parameters = motion.parameters;
    job.options = judged_options();
    job.options.push = draw.push;
    job.rollout.dv = job.options.push.dv;
    jobs.push_back(std::move(job));
  }
  for (std::size_t f = 0; f < suite.friction_factors.size(); ++f) {
    Job job;
    job.motion = m;
    job.rollout.kind = PerturbationKind::kFriction;
    job.rollout.sample = static_cast<int>(f);
    job.rollout.friction = suite.friction_factors[f];
    job.parameters = motion.parameters;
    job.options = judged_options();
    job.options.friction_scale = suite.friction_factors[f];
    jobs.push_back(std::move(job));
  }
  if (suite.half_timestep) {
    Job job;
    job.motion = m;
    job.rollout.kind = PerturbationKind::kHalfTimestep;
    job.rollout.timestep_scale = 0.5;
    job.parameters = motion.parameters;
    job.options = judged_options();
    job.options.timestep_scale = 0.5;
    job.options.half_timestep_check = false;  // judged on its own C
    jobs.push_back(std::move(job));
  }
  return jobs;
}

bool holds(const Evaluation& e) { return !e.failed && e.constraint == 0; }

nlohmann::json rollout_json(const PerturbedRollout& r) {
  nlohmann::json j = {{"constraint", r.constraint}, {"holds", r.holds}};
  switch (r.kind) {
    case PerturbationKind::kParameters:
      j["distance"] = r.distance;
      if (!r.parameters.is_null()) j["parameters"] = r.parameters;
      break;
    case PerturbationKind::kPush:
      j["phase"] = r.phase;
      j["direction"] = r.direction;
      j["time"] = r.push_time;
      j["dv"] = r.dv;
      break;
    case PerturbationKind::kFriction: j["factor"] = r.friction; break;
    case PerturbationKind::kHalfTimestep: j["timestep_scale"] = r.timestep_scale; break;
  }
  if (!r.fall_reason.empty()) j["fell"] = r.fall_reason;
  if (r.fell_after_touchdown >= 0) j["fell_after_touchdown"] = r.fell_after_touchdown;
  if (!r.failure.empty()) j["failure"] = r.failure;
  return j;
}

constexpr PerturbationKind kKinds[kPerturbationKinds] = {PerturbationKind::kParameters, PerturbationKind::kPush,
                                                         PerturbationKind::kFriction, PerturbationKind::kHalfTimestep};

}  // namespace

const char* perturbation_key(PerturbationKind kind) {
  switch (kind) {
    case PerturbationKind::kParameters: return "parameters";
    case PerturbationKind::kPush: return "pushes";
    case PerturbationKind::kFriction: return "friction";
    case PerturbationKind::kHalfTimestep: return "half_timestep";
  }
  return "?";
}

double mirror_unit(double x) {
  if (!std::isfinite(x)) return 0.5;  // never from a finite sigma; kept inside all the same
  // The mirror is even (x and -x map alike), so work on |x|: exact for -0.1.
  const double t = std::fmod(std::fabs(x), 2.0);
  return t <= 1.0 ? t : 2.0 - t;
}

int MotionRobustness::held(PerturbationKind kind) const {
  return static_cast<int>(std::count_if(rollouts.begin(), rollouts.end(),
                                        [kind](const PerturbedRollout& r) { return r.kind == kind && r.holds; }));
}
int MotionRobustness::count(PerturbationKind kind) const {
  return static_cast<int>(std::count_if(rollouts.begin(), rollouts.end(),
                                        [kind](const PerturbedRollout& r) { return r.kind == kind; }));
}
int MotionRobustness::held() const {
  return static_cast<int>(
      std::count_if(rollouts.begin(), rollouts.end(), [](const PerturbedRollout& r) { return r.holds; }));
}
int MotionRobustness::count() const { return static_cast<int>(rollouts.size()); }

RobustnessSuite robust_sample_suite() {
  RobustnessSuite suite;
  suite.parameter_samples = 2;
  suite.push_samples = 2;
  suite.first_push_phase = 1;
  suite.friction_factors.clear();
  suite.half_timestep = false;
  suite.required_share = 0.75;
  return suite;
}

SuiteVerdict check_suite(const TaskEvaluator& evaluator, const ParameterSet& parameters,
                         const RobustnessSuite& suite) {
  SuiteVerdict verdict;
  EvaluationOptions plain;
  plain.samples_per_phase = 0;
  const Evaluation base = evaluator.evaluate_named(parameters, plain);
  verdict.steps += base.stats.steps;
  const MotionUnderTest motion{"sample", 0, parameters};
  const std::vector<Job> jobs = make_jobs(evaluator, motion, 0, base, suite);
  const int total = static_cast<int>(jobs.size());
  const int allowed = total - static_cast<int>(std::ceil(suite.required_share * total - 1e-9));
  int failed = 0;
  for (const Job& job : jobs) {
    const Evaluation e = evaluator.evaluate_named(job.parameters, job.options);
    ++verdict.rollouts;
    verdict.half_timestep_checks += e.check_steps > 0 ? 1 : 0;
    verdict.steps += e.stats.steps + e.check_steps;
    if (!holds(e) && ++failed > allowed) {
      verdict.holds = false;
      break;
    }
    if (verdict.rollouts - failed >= total - allowed) break;  // enough have held
  }
  return verdict;
}

std::vector<MotionRobustness> run_robustness_suite(const TaskEvaluator& evaluator,
                                                   const std::vector<MotionUnderTest>& motions,
                                                   const RobustnessSuite& suite, ThreadPool& pool) {
  // The unperturbed rollouts: C, and the phase times the pushes are drawn in.
  std::vector<Evaluation> base(motions.size());
  pool.parallel_for(motions.size(), [&](std::size_t m, int) {
    base[m] = evaluator.evaluate_named(motions[m].parameters, judged_options());
  });
  std::vector<Job> jobs;
  for (std::size_t m = 0; m < motions.size(); ++m) {
    std::vector<Job> more = make_jobs(evaluator, motions[m], m, base[m], suite);
    for (Job& j : more) jobs.push_back(std::move(j));
  }
  pool.parallel_for(jobs.size(), [&](std::size_t k, int) {
    Job& job = jobs[k];
    const Evaluation e = evaluator.evaluate_named(job.parameters, job.options);
    PerturbedRollout& r = job.rollout;
    r.constraint = e.constraint;
    r.holds = holds(e);
    r.failure = e.failed ? e.failure : "";
    r.fall_reason = e.fell ? e.summary.fall_reason : "";
    if (e.fell && e.summary.landed && e.phases.landing() >= 0)
      r.fell_after_touchdown = e.summary.end_time - e.phases.landing();
    if (r.kind == PerturbationKind::kPush) r.push_time = e.push_time;
    if (r.kind == PerturbationKind::kParameters) r.parameters = job.parameters.to_json();
  });
  std::vector<MotionRobustness> results(motions.size());
  for (std::size_t m = 0; m < motions.size(); ++m) {
    results[m].label = motions[m].label;
    results[m].index = motions[m].index;
    results[m].constraint = base[m].constraint;
  }
  for (Job& job : jobs) results[job.motion].rollouts.push_back(std::move(job.rollout));
  return results;
}

nlohmann::json robustness_json(const TaskEvaluator& evaluator, const RobustnessSuite& suite,
                               const std::vector<MotionRobustness>& results) {
  const bool planar = evaluator.body().root == RootKind::kPlanar;
  nlohmann::json directions = nlohmann::json::array();
  for (int k = 0; k < push_directions(planar); ++k) directions.push_back(push_direction(k, planar).name);
  nlohmann::json out = {
      {"format", "diverse.robustness"},
      {"version", 1},
      {"task", evaluator.task().name},
      {"strength", evaluator.task().strength},
      {"suite",
       {{"seed", suite.seed},
        {"parameter_samples", suite.parameter_samples},
        {"sigma", suite.sigma},
        {"bounds", "mirror"},
        {"push_samples", suite.push_samples},
        {"push_speed", suite.push_speed},
        {"push_directions", directions},
        {"friction_factors", suite.friction_factors},
        {"half_timestep", suite.half_timestep},
        {"task_half_timestep_check", evaluator.task().constraints.half_timestep}}},
  };
  nlohmann::json motions = nlohmann::json::array();
  for (const MotionRobustness& r : results) {
    nlohmann::json kinds = nlohmann::json::object();
    for (PerturbationKind kind : kKinds) {
      nlohmann::json list = nlohmann::json::array();
      for (const PerturbedRollout& p : r.rollouts)
        if (p.kind == kind) list.push_back(rollout_json(p));
      kinds[perturbation_key(kind)] = {{"held", r.held(kind)}, {"count", r.count(kind)}, {"rollouts", list}};
    }
    motions.push_back({{"label", r.label},
                       {"index", r.index},
                       {"constraint", r.constraint},
                       {"held", r.held()},
                       {"count", r.count()},
                       {"share", r.count() > 0 ? static_cast<double>(r.held()) / r.count() : 0.0},
                       {"kinds", kinds}});
  }
  out["motions"] = motions;
  return out;
}

nlohmann::json robustness_json(const TaskEvaluator& evaluator, const std::vector<MotionUnderTest>& motions,
                               const RobustnessSuite& suite, ThreadPool& pool) {
  return robustness_json(evaluator, suite, run_robustness_suite(evaluator, motions, suite, pool));
}

std::string robustness_shares(const nlohmann::json& motion, const std::string& origin) {
  static constexpr std::pair<const char*, const char*> kShort[kPerturbationKinds] = {
      {"parameters", "params"}, {"pushes", "pushes"}, {"friction", "friction"}, {"half_timestep", "half-step"}};
  auto count = [&](const nlohmann::json& j, const char* key, const std::string& field) {
    if (!j.is_object() || !j.contains(key) || !j[key].is_number_integer() || j[key].get<long long>() < 0)
      throw_field_error(origin, field + "." + key, "expected a count (an integer >= 0)");
    return j[key].get<long long>();
  };
  if (!motion.is_object() || !motion.contains("kinds") || !motion["kinds"].is_object())
    throw_field_error(origin, "motions[].kinds", "expected the counts of every kind of perturbation");
  std::string text;
  long long held = 0, total = 0;
  for (const auto& [key, name] : kShort) {
    const std::string field = std::string("motions[].kinds.") + key;
    if (!motion["kinds"].contains(key)) throw_field_error(origin, field, "expected the counts of this kind");
    const nlohmann::json& k = motion["kinds"][key];
    const long long h = count(k, "held", field), c = count(k, "count", field);
    if (h > c) throw_field_error(origin, field + ".held", "expected at most its count");
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%s%s %lld/%lld", text.empty() ? "" : ", ", name, h, c);
    text += buffer;
    held += h;
    total += c;
  }
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, ", all %lld/%lld = %.0f %%", held, total,
                total > 0 ? 100.0 * static_cast<double>(held) / static_cast<double>(total) : 0.0);
  return text + buffer;
}

}  // namespace diverse
