#include "task/seed_motion.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "task/term_landing.h"
#include "core/error.h"
#include "core/rng.h"
#include "core/thread_pool.h"
#include "optimize/cmaes.h"
#include "task/evaluate.h"
#include "task/pushes.h"

namespace diverse {
namespace {

constexpr double kMarginCap = 0.1;  // m; slack beyond this earns nothing more
constexpr int kPatience = 25;       // generations without improvement that end the last stage
// Stream keys of the perturbation seeds (ASCII "seedrob" and "measrob").
constexpr std::uint64_t kSeedPerturbations = 0x73656564726f62;
constexpr std::uint64_t kMeasurePerturbations = 0x6d656173726f62;
constexpr std::uint64_t kSelectPerturbations = 0x73656c6563726f62;  // "selecrob"
constexpr std::uint64_t kPushMoments = 0x7075736865;                  // "pushe"
// Candidates of the last stage that met the task kept for the selection (seed_motion.h).
constexpr size_t kFinalists = 6;

// Reflection into [0, 1] with period 2, as the bounded CMA-ES maps its genotypes.
double reflect01(double g) {
  double t = std::fmod(g, 2.0);
  if (t < 0) t += 2.0;
  return t <= 1.0 ? t : 2.0 - t;
}

// Standard normal directions, direction k from derive_seed(seed, {k}).
std::vector<Eigen::VectorXd> directions(int dim, int count, std::uint64_t seed) {
  std::vector<Eigen::VectorXd> out;
  for (int k = 0; k < count; ++k) {
    Rng rng(derive_seed(seed, {static_cast<std::uint64_t>(k)}));
    Eigen::VectorXd z(dim);
    for (int i = 0; i < dim; ++i) z[i] = rng.normal();
    out.push_back(std::move(z));
  }
  return out;
}

Eigen::VectorXd displaced(const Eigen::VectorXd& x, double sigma, const Eigen::VectorXd& z) {
  Eigen::VectorXd y(x.size());
  for (int i = 0; i < x.size(); ++i) y[i] = reflect01(x[i] + sigma * z[i]);
  return y;
}

// What the objective needs besides the evaluators: the robustness term's fixed
// perturbation directions (empty = off) and their scale, and its pushes (empty = off):
// for push k, where in its ground phase it falls (a fraction of the phase), its
// direction and phase by k (task/pushes.h), and its speed.
struct Robustness {
  std::vector<Eigen::VectorXd> directions;
  double sigma = 0;
  std::vector<double> push_moments;  // in [0, 1)
  double push_speed = 0;
  std::size_t rollouts() const { return directions.size() + push_moments.size(); }
};

// `count` fractions in [0, 1), fraction k from derive_seed(seed, {k}).
std::vector<double> moments(int count, std::uint64_t seed) {
  std::vector<double> out;
  for (int k = 0; k < count; ++k) {
    Rng rng(derive_seed(seed, {static_cast<std::uint64_t>(k)}));
    out.push_back(rng.uniform());
  }
  return out;
}

// The perturbation directions of generation `generation` (0: the starting point) of
// continuation stage `stage`: shared by the generation's candidates, fresh in every
// generation, so that the search cannot tune a motion to a few fixed directions.
Robustness generation_robustness(const Task& task, int dim, const SeedOptions& options,
                                 size_t stage, long long generation) {
  Robustness r;
  r.sigma = options.perturbation_sigma;
  r.directions =
      directions(dim, options.perturbations,
                 derive_seed(task.seed.seed, {kSeedPerturbations, stage,
                                              static_cast<std::uint64_t>(generation)}));
  r.push_speed = options.push_speed;
  r.push_moments = moments(options.pushes, derive_seed(task.seed.seed, {kPushMoments, stage,
                                                                        static_cast<std::uint64_t>(generation)}));
  return r;
}

// The selection's pushes: as many as keep the search's ratio of pushes to perturbations
// (selection_samples of them without perturbations).
int selection_pushes(const SeedOptions& options) {
  if (options.pushes <= 0) return 0;
  if (options.perturbations <= 0) return options.selection_samples;
  return std::max(1, static_cast<int>(std::lround(static_cast<double>(options.selection_samples) *
                                                  options.pushes / options.perturbations)));
}

// The selection's perturbation directions (seed_motion.h, "Choosing the result"): fixed
// for the whole selection, drawn apart from every generation's and from
// measure_robustness()'s.
std::uint64_t selection_seed(const Task& task) { return derive_seed(task.seed.seed, {kSelectPerturbations}); }

Robustness selection_robustness(const Task& task, int dim, const SeedOptions& options) {
  Robustness r;
  r.sigma = options.perturbation_sigma;
  r.directions = directions(dim, options.perturbations > 0 ? options.selection_samples : 0, selection_seed(task));
  r.push_speed = options.push_speed;
  r.push_moments = moments(selection_pushes(options), derive_seed(task.seed.seed, {kSelectPerturbations, kPushMoments}));
  return r;
}

// C of one rollout as the search sees it: the task's C plus, when the search asks for a
// minimum rotation of the root between take-off and touch-down, K_c d^2 for a shortfall
// of d rad (the task's own weight, as for any other constraint).
double seed_constraint(const Evaluation& e, const Task& task, const SeedOptions& options) {
  double c = e.constraint;
  if (options.min_flight_rotation > 0 && !e.fell) {
    const double d = std::max(0.0, options.min_flight_rotation - e.summary.rotation_flight);
    c += task.constraints.weight * d * d;
  }
  return c;
}

// Both rollouts landed and came to rest, so their landing spots can be compared.
bool both_landed(const Evaluation& coarse, const Evaluation& fine) {
  return !(coarse.failed || fine.failed || coarse.fell || fine.fell);
}

// How far apart the feet land (touch-down or rest, m) at the two timesteps beyond
// kTimestepAgreement; 0 when either rollout has no landing to compare (a fall, which C
// already penalizes).
double landing_shift_excess(const Evaluation& coarse, const Evaluation& fine) {
  if (!both_landed(coarse, fine)) return 0;
  return std::max(0.0, landing_shift(coarse.summary, fine.summary) - kTimestepAgreement);
}

struct Scored {
  double f = 0;
  // C at the task's timestep plus C with it halved, plus K_c d^2 for landing spots
  // further apart than kTimestepAgreement by d.
  double constraint = 0;
  double margin = 0;      // smallest constraint_margin of the two
  double met = 0;         // fraction of the perturbations with C = 0 (0 if none)
  bool fell = true;
  // The requirement (SeedOptions::requirement), when it was judged: on a candidate that
  // met the task at both timesteps. A failure is in `constraint` as its penalty.
  bool checked = false;
  bool held = false;
  long long check_rollouts = 0;
  bool meets() const { return constraint == 0; }
};

// A candidate for the selection that ends a search with perturbations (seed_motion.h).
struct Finalist {
  Eigen::VectorXd x;
  double f = 0;       // its objective in the generation that scored it
  std::string label;  // "start", "CMA-ES mean", "generation G"
};

// Keeps the kFinalists lowest-objective candidates, in order of f (earlier first on ties).
void keep_finalist(std::vector<Finalist>& finalists, Finalist candidate) {
  const auto at = std::upper_bound(finalists.begin(), finalists.end(), candidate.f,
                                   [](double f, const Finalist& c) { return f < c.f; });
  if (static_cast<size_t>(at - finalists.begin()) >= kFinalists) return;
  finalists.insert(at, std::move(candidate));
  if (finalists.size() > kFinalists) finalists.pop_back();
}

// Scores x on the task at its timestep and again with the timestep halved: a motion
// counts as meeting the task only if it does so at both timesteps, landing within
// kTimestepAgreement of the same spot, which keeps input motions away from knife-edge
// landings that depend on integration details. With
// perturbations, x is also simulated at each x + sigma_r z_k, and f is the mean C over
// all these rollouts: the expected penalty under small parameter changes, a smoothed
// landscape on which CMA-ES moves towards regions where whole neighbourhoods meet the
// task, rather than towards single lucky points. Means keep the landscape graded: a
// candidate that meets the task coarsely but falls finely ranks among the falls by how
// early it fell. When every rollout meets the task, f is -robustness * min(margin, cap).
Scored score(const TaskEvaluator& ev, const TaskEvaluator& fine, const Eigen::VectorXd& x,
             SimWorker& worker, SimWorker& fine_worker, const Robustness& robust,
             const SeedOptions& seed) {
  EvaluationOptions options;
  options.samples_per_phase = 0;
  const Evaluation e = ev.evaluate_normalized(x, worker, options);
  const Evaluation f = fine.evaluate_normalized(x, fine_worker, options);
  Scored s;
  const double shift = landing_shift_excess(e, f);
  s.constraint = seed_constraint(e, ev.task(), seed) + seed_constraint(f, fine.task(), seed) +
                 ev.task().constraints.weight * shift * shift;
  s.fell = e.fell || f.fell;
  s.margin = std::min(e.failed ? -1 : constraint_margin(ev.task(), e.summary),
                      f.failed ? -1 : constraint_margin(fine.task(), f.summary));
  // Where the task checks the half timestep, how near the landing spots are to parting
  // counts as a margin too: a motion whose two landings sit at the agreement's edge has
  // no perturbation to spare.
  if (ev.task().constraints.half_timestep && both_landed(e, f))
    s.margin = std::min(s.margin, kTimestepAgreement - landing_shift(e.summary, f.summary));
  // The requirement beyond the task, only where it decides something: on a candidate
  // that meets the task at both timesteps.
  if (seed.requirement && s.constraint == 0) {
    ParameterSet named = ev.parameters();
    named.set_normalized(x);
    const SeedRequirement::Verdict verdict = seed.requirement.check(named);
    s.checked = true;
    s.held = verdict.holds;
    s.check_rollouts = verdict.rollouts;
    if (!verdict.holds) s.constraint += seed.requirement.penalty;
  }
  // What a rollout adds to the objective: its C, or with the share objective 1 when it
  // misses the task plus log(1 + C) / 100 to rank the misses (seed_motion.h).
  auto term = [&seed](double c) { return objective_term(seed.objective, c); };
  double sum = seed.objective == SeedObjective::kShare ? 2 * term(s.constraint) : s.constraint;
  int met = 0;
  // Perturbations meet the task as the diversity optimizer will judge them: with the
  // half-timestep check where the task asks for it.
  EvaluationOptions perturbed = options;
  perturbed.half_timestep_check = true;
  for (const Eigen::VectorXd& z : robust.directions) {
    const double c = seed_constraint(
        ev.evaluate_normalized(displaced(x, robust.sigma, z), worker, perturbed), ev.task(), seed);
    sum += term(c);
    if (c == 0) ++met;
  }
  // Pushes, each in a ground phase of this candidate's own rollout (seed_motion.h).
  if (!robust.push_moments.empty()) {
    const GroundWindows windows = ground_windows(ev.task(), e);
    const bool planar = ev.body().root == RootKind::kPlanar;
    for (std::size_t k = 0; k < robust.push_moments.size(); ++k) {
      EvaluationOptions pushed = perturbed;
      pushed.push = draw_push(windows, static_cast<int>(k), planar, 0, robust.push_moments[k], robust.push_speed).push;
      const double c = seed_constraint(ev.evaluate_normalized(x, worker, pushed), ev.task(), seed);
      sum += term(c);
      if (c == 0) ++met;
    }
  }
  const auto n = static_cast<double>(robust.rollouts());
  if (n > 0) s.met = met / n;
  s.f = sum / (2 + n);
  if (sum == 0) s.f = -ev.task().seed.robustness * std::min(std::max(s.margin, 0.0), kMarginCap);
  return s;
}

// ", robust part: holds" or ", robust part: fails" after a candidate judged by the
// requirement.
std::string requirement_note(const SeedRequirement& requirement, const Scored& s) {
  if (!requirement || !s.checked) return "";
  return ", " + requirement.name + (s.held ? ": holds" : ": fails");
}

Task halved(const Task& task, const mjModel* m) {
  Task t = task;
  t.simulation.timestep = 0.5 * m->opt.timestep;
  return t;
}

// The task with the continuation object at `height`. When the landing controller aims
// at the top of that object (a box to land on), its landing surface moves with it.
Task with_height(const Task& task, double height) {
  Task t = task;
  for (SceneObject& o : t.objects) {
    if (o.name != task.seed.object) continue;
    if (o.kind == "box" && task.controller_config->landing_height() == o.height) {
      t.controller_config = t.controller_config->with_landing_height(height);
    }
    o.height = height;
  }
  return t;
}

// The task with its landing constraint's centre at `x`.
Task with_distance(const Task& task, double x) {
  Task t = task;
  t.constraints.change<LandingConstraint>([x](LandingConstraint& landing) { landing.center = x; });
  return t;
}

}  // namespace

SeedResult seed_motion(const Task& task, const ParameterSet& start, const SeedOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  SeedResult result;
  result.parameters = start;
  result.lowest_mean = start;
  Eigen::VectorXd x = start.normalized();
  // Continuation stages: an object's heights, landing distances, or the task alone.
  const bool by_distance = !task.seed.distances.empty();
  std::vector<double> heights = by_distance ? task.seed.distances : task.seed.heights;
  if (task.seed.object.empty() && !by_distance) heights = {-1};
  const int generations = options.generations > 0 ? options.generations : task.seed.generations;
  ThreadPool pool(std::max(1, options.threads));
  char line[512];

  if (options.requirement && !(options.requirement.penalty > 0))
    throw std::invalid_argument("seed_motion: a requirement needs a penalty > 0");
  if (options.first_stage < 0 || static_cast<size_t>(options.first_stage) >= heights.size()) {
    throw UserError(task.file + ": --from-stage: expected a stage from 0 to " +
                    std::to_string(heights.size() - 1) + " (got " + std::to_string(options.first_stage) + ")");
  }

  for (size_t stage = static_cast<size_t>(options.first_stage); stage < heights.size(); ++stage) {
    const bool last = stage + 1 == heights.size();
    const Task stage_task = by_distance        ? with_distance(task, heights[stage])
                            : heights[stage] < 0 ? task
                                                 : with_height(task, heights[stage]);
    const TaskEvaluator ev(stage_task);
    const TaskEvaluator fine(halved(stage_task, ev.model().get()));
    std::vector<std::unique_ptr<SimWorker>> workers, fine_workers;
    for (int w = 0; w < pool.size(); ++w) {
      workers.push_back(ev.make_worker());
      fine_workers.push_back(fine.make_worker());
    }

    // Perturbations only in the last stage: an intermediate stage has to get over the
    // raised object, which a mean over perturbations discourages (a neighbourhood that
    // lands short of a box beats one that partly hits its face); the last stage then
    // looks for a robust motion.
    // The requirement likewise: the intermediate stages' tasks are not the task.
    SeedOptions stage_options = options;
    if (!last) {
      stage_options.perturbations = 0;
      stage_options.pushes = 0;
      stage_options.requirement = {};
    }
    const int dim = static_cast<int>(x.size());
    Robustness robust = generation_robustness(task, dim, stage_options, stage, 0);
    // Done with a stage: an intermediate one as soon as a candidate meets its task; the
    // last one when the candidate with the lowest objective meets the task and nothing
    // has improved for kPatience generations (or after the generation budget).
    Scored best = score(ev, fine, x, *workers[0], *fine_workers[0], robust, stage_options);
    Eigen::VectorXd best_x = x;
    bool have_valid = best.meets();
    Scored best_valid = best;
    Eigen::VectorXd best_valid_x = x;
    result.evaluations += static_cast<long long>(2 + robust.rollouts()) + best.check_rollouts;
    auto count_check = [&](const Scored& s) {
      result.requirement_checks += s.checked ? 1 : 0;
      result.requirement_held += s.checked && s.held ? 1 : 0;
    };
    count_check(best);
    if (options.log) {
      std::snprintf(line, sizeof(line),
                    "stage %zu (%s %.3f m): start f=%.6g C=%.6g margin=%.3f met=%.3f%s", stage,
                    by_distance ? "landing at" : "height", heights[stage], best.f, best.constraint, best.margin,
                    best.met, requirement_note(stage_options.requirement, best).c_str());
      options.log(line);
    }
    if (last) {
      result.lowest_mean = start;
      result.lowest_mean.set_normalized(x);
      result.lowest_mean_f = best.f;
      result.lowest_mean_meets = best.meets();
    }
    // The selection's candidates (seed_motion.h, "Choosing the result").
    const bool select = last && (stage_options.perturbations > 0 || stage_options.pushes > 0) &&
                        stage_options.selection_samples > 0;
    std::vector<Finalist> finalists;
    const Eigen::VectorXd stage_start = x;
    const bool stage_start_meets = best.meets();
    auto hand_on = [&](const Eigen::VectorXd& handed, double constraint) {
      if (last || !options.on_stage) return;
      ParameterSet p = start;
      p.set_normalized(handed);
      options.on_stage(static_cast<int>(stage), heights[stage], p, constraint);
    };
    if (!last && best.meets()) {
      hand_on(x, best.constraint);
      continue;
    }

    CmaesOptions co;
    co.dim = static_cast<int>(x.size());
    co.popsize = task.seed.popsize;
    co.sigma0 = options.sigma > 0 ? options.sigma : task.seed.sigma;
    co.seed = derive_seed(task.seed.seed, {static_cast<std::uint64_t>(stage)});
    co.bounded = true;
    co.lower = 0;
    co.upper = 1;
    co.max_generations = generations;
    Cmaes es(co, x);
    int since_improvement = 0;
    while (es.stop_reason() == StopReason::kNone) {
      const std::vector<Eigen::VectorXd>& xs = es.ask();
      robust = generation_robustness(task, dim, stage_options, stage, es.generation() + 1);
      std::vector<Scored> scores(xs.size());
      pool.parallel_for(xs.size(), [&](std::size_t k, int worker) {
        const auto w = static_cast<std::size_t>(worker);
        scores[k] = score(ev, fine, xs[k], *workers[w], *fine_workers[w], robust, stage_options);
      });
      long long checked = 0, held = 0, check_rollouts = 0;
      for (const Scored& s : scores) {
        count_check(s);
        checked += s.checked ? 1 : 0;
        held += s.checked && s.held ? 1 : 0;
        check_rollouts += s.check_rollouts;
      }
      std::vector<double> f(xs.size());
      bool improved = false;
      for (size_t k = 0; k < xs.size(); ++k) {
        f[k] = scores[k].f;
        if (select && scores[k].meets())
          keep_finalist(finalists, {xs[k], scores[k].f, "generation " + std::to_string(es.generation() + 1)});
        if (scores[k].f < best.f) {
          best = scores[k];
          best_x = xs[k];
          improved = true;
        }
        if (scores[k].meets() && (!have_valid || scores[k].f < best_valid.f)) {
          have_valid = true;
          best_valid = scores[k];
          best_valid_x = xs[k];
          improved = true;
        }
      }
      result.evaluations += static_cast<long long>(xs.size() * (2 + robust.rollouts())) + check_rollouts;
      es.tell(f);
      since_improvement = improved ? 0 : since_improvement + 1;
      if (options.log) {
        std::vector<double> sorted = f;
        std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2),
                         sorted.end());
        const double median = sorted[sorted.size() / 2];
        const Scored& b = have_valid ? best_valid : best;
        std::string checks;
        std::string none_yet = have_valid ? "" : " (none meets the task yet)";
        if (!have_valid && stage_options.requirement)
          none_yet = " (none meets the task and the " + stage_options.requirement.name + " yet)";
        if (stage_options.requirement) {
          checks = "; " + stage_options.requirement.name + ": " + std::to_string(held) + " of " +
                   std::to_string(checked) + " that met the task held";
        }
        std::snprintf(line, sizeof(line),
                      "stage %zu gen %lld: best f=%.6g C=%.6g margin=%.3f met=%.3f%s; lowest f=%.6g "
                      "median f=%.6g sigma=%.4f%s",
                      stage, es.generation(), b.f, b.constraint, b.margin, b.met,
                      none_yet.c_str(), best.f, median, es.sigma(), checks.c_str());
        options.log(line);
      }
      if (!last && have_valid) break;
      if (last && best.meets() && since_improvement >= kPatience) break;
    }
    x = have_valid ? best_valid_x : best_x;
    if (select) {
      if (stage_start_meets) finalists.insert(finalists.begin(), {stage_start, 0, "start"});
      finalists.push_back({es.mean(), 0, "CMA-ES mean"});
      const Robustness selection = selection_robustness(task, dim, stage_options);
      std::vector<Scored> judged(finalists.size());
      pool.parallel_for(finalists.size(), [&](std::size_t k, int worker) {
        const auto w = static_cast<std::size_t>(worker);
        judged[k] = score(ev, fine, finalists[k].x, *workers[w], *fine_workers[w], selection, stage_options);
      });
      int chosen = -1;
      std::string compared;
      for (size_t k = 0; k < finalists.size(); ++k) {
        const Scored& j = judged[k];
        result.evaluations += static_cast<long long>(2 + selection.rollouts()) + j.check_rollouts;
        count_check(j);
        const int held = static_cast<int>(std::lround(j.met * static_cast<double>(selection.rollouts())));
        compared += (k ? ", " : "") + finalists[k].label + " " +
                    (j.meets() ? std::to_string(held) : std::string("misses the task"));
        if (!j.meets()) continue;
        if (chosen < 0 || j.met > judged[static_cast<size_t>(chosen)].met ||
            (j.met == judged[static_cast<size_t>(chosen)].met && j.f < judged[static_cast<size_t>(chosen)].f))
          chosen = static_cast<int>(k);
      }
      result.selection_candidates = static_cast<int>(finalists.size());
      if (chosen >= 0) {
        const auto c = static_cast<size_t>(chosen);
        x = finalists[c].x;
        result.selected = finalists[c].label;
        result.robustness = judged[c].met;
      }
      if (options.log) {
        const std::string pushes =
            selection.push_moments.empty() ? "" : " and " + std::to_string(selection.push_moments.size()) + " pushes";
        options.log("selection on " + std::to_string(selection.directions.size()) + " perturbations" + pushes +
                    " of each (meeting the task): " + compared + "; chosen: " +
                    (chosen >= 0 ? result.selected : std::string("none meets the task")));
      }
    }
    hand_on(x, have_valid ? best_valid.constraint : best.constraint);
    if (last) {
      result.lowest_mean.set_normalized(best_x);
      result.lowest_mean_f = best.f;
      result.lowest_mean_meets = best.meets();
    }
  }

  // The result on the full task.
  const TaskEvaluator ev(task);
  const TaskEvaluator fine(halved(task, ev.model().get()));
  auto worker = ev.make_worker();
  auto fine_worker = fine.make_worker();
  const Robustness robust =
      generation_robustness(task, static_cast<int>(x.size()), options, heights.size() - 1, 0);
  const Scored final_score = score(ev, fine, x, *worker, *fine_worker, robust, options);
  result.parameters.set_normalized(x);
  result.constraint = final_score.constraint;
  result.requirement_failed = final_score.checked && !final_score.held;
  result.margin = final_score.margin;
  if (result.selected.empty()) result.robustness = final_score.met;
  result.fell = final_score.fell;
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

std::vector<Eigen::VectorXd> perturb(const Eigen::VectorXd& x, double sigma, int count,
                                     std::uint64_t seed) {
  std::vector<Eigen::VectorXd> out;
  for (const Eigen::VectorXd& z : directions(static_cast<int>(x.size()), count, seed)) {
    out.push_back(displaced(x, sigma, z));
  }
  return out;
}

double objective_term(SeedObjective objective, double c) {
  if (objective == SeedObjective::kMeanC) return c;
  return c > 0 ? 1.0 + std::log1p(c) / 100 : 0.0;
}

std::vector<Eigen::VectorXd> selection_perturbations(const Task& task, const Eigen::VectorXd& x,
                                                     const SeedOptions& options) {
  return perturb(x, options.perturbation_sigma, options.selection_samples, selection_seed(task));
}

std::uint64_t robustness_seed(const Task& task, double sigma) {
  return derive_seed(task.seed.seed, {kMeasurePerturbations, std::bit_cast<std::uint64_t>(sigma)});
}

namespace {

// x at the task's timestep, half and a quarter of it: whether it touched down, where
// (m, x and y), its C and its peak COM height.
struct ThreeSteps {
  std::array<bool, 3> landed_at{};
  std::array<std::array<double, 2>, 3> touchdown{};
  std::array<double, 3> constraint{};
  std::array<double, 3> peak{};  // m
  bool landed() const { return landed_at[0] && landed_at[1] && landed_at[2]; }
};
ThreeSteps at_three_steps(const TaskEvaluator& ev, const Eigen::VectorXd& x, SimWorker& worker) {
  ThreeSteps t;
  double scale = 1.0;
  for (int k = 0; k < 3; ++k, scale *= 0.5) {
    EvaluationOptions options;
    options.samples_per_phase = 0;
    options.timestep_scale = scale;
    const Evaluation e = ev.evaluate_normalized(x, worker, options);
    t.landed_at[static_cast<std::size_t>(k)] = e.summary.landed && !e.summary.unstable;
    t.touchdown[static_cast<std::size_t>(k)] = {e.summary.touchdown_feet_x, e.summary.touchdown_feet_y};
    t.constraint[static_cast<std::size_t>(k)] = e.constraint;
    t.peak[static_cast<std::size_t>(k)] = e.summary.peak_com_z;
  }
  return t;
}

double apart(const std::array<double, 2>& a, const std::array<double, 2>& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1]);
}

}  // namespace

RobustnessReport measure_robustness(const Task& task, const ParameterSet& parameters,
                                    const std::vector<double>& sigmas, int samples, int threads,
                                    bool convergence) {
  if (convergence && task.walk.enabled)
    throw std::logic_error("measure_robustness: convergence compares a jump's touch-downs; " + task.name + " is a walk");
  const TaskEvaluator ev(task);
  const TaskEvaluator fine(halved(task, ev.model().get()));
  ThreadPool pool(std::max(1, threads));
  std::vector<std::unique_ptr<SimWorker>> workers;
  for (int w = 0; w < pool.size(); ++w) workers.push_back(ev.make_worker());
  EvaluationOptions options;
  options.samples_per_phase = 0;
  RobustnessReport report;
  const Eigen::VectorXd x = parameters.normalized();
  const Evaluation coarse = ev.evaluate_normalized(x, *workers[0], options);
  auto fine_worker = fine.make_worker();
  const Evaluation fine_e = fine.evaluate_normalized(x, *fine_worker, options);
  report.constraint = coarse.constraint;
  report.constraint_fine = fine_e.constraint;
  report.landing_shift = both_landed(coarse, fine_e) ? landing_shift(coarse.summary, fine_e.summary)
                                                     : std::numeric_limits<double>::quiet_NaN();
  for (size_t level = 0; level < sigmas.size(); ++level) {
    const std::vector<Eigen::VectorXd> xs = perturb(x, sigmas[level], samples, robustness_seed(task, sigmas[level]));
    // Meeting the task as the diversity optimizer judges it: with the half-timestep check
    // where the task asks for it.
    EvaluationOptions perturbed = options;
    perturbed.half_timestep_check = true;
    std::vector<double> c(xs.size());
    pool.parallel_for(xs.size(), [&](std::size_t k, int worker) {
      c[k] = ev.evaluate_normalized(xs[k], *workers[static_cast<std::size_t>(worker)], perturbed).constraint;
    });
    RobustnessReport::Level l;
    l.sigma = sigmas[level];
    l.samples = samples;
    l.met = static_cast<int>(std::count(c.begin(), c.end(), 0.0));
    l.constraints = std::move(c);
    if (convergence) {
      std::vector<ThreeSteps> three(xs.size());
      pool.parallel_for(xs.size(), [&](std::size_t k, int worker) {
        three[k] = at_three_steps(ev, xs[k], *workers[static_cast<std::size_t>(worker)]);
      });
      TimestepConvergence& v = l.convergence;
      for (const ThreeSteps& t : three) {  // in perturb()'s order: the sums do not depend on threads
        if (!t.landed()) continue;
        const double half = apart(t.touchdown[0], t.touchdown[1]);
        const double quarter = apart(t.touchdown[1], t.touchdown[2]);
        ++v.compared;
        v.half_mean += half;
        v.quarter_mean += quarter;
        v.peak_half_mean += std::fabs(t.peak[0] - t.peak[1]);
        v.peak_quarter_mean += std::fabs(t.peak[1] - t.peak[2]);
        v.half_max = std::max(v.half_max, half);
        v.quarter_max = std::max(v.quarter_max, quarter);
      }
      if (v.compared > 0) {
        v.half_mean /= v.compared;
        v.quarter_mean /= v.compared;
        v.peak_half_mean /= v.compared;
        v.peak_quarter_mean /= v.compared;
      }
    }
    report.levels.push_back(l);
  }
  if (convergence) {
    const ThreeSteps t = at_three_steps(ev, x, *workers[0]);
    for (std::size_t k = 0; k < 3; ++k)
      report.touchdown_x[k] = t.landed_at[k] ? t.touchdown[k][0] : std::numeric_limits<double>::quiet_NaN();
    report.constraint_quarter = t.constraint[2];
  }
  return report;
}

}  // namespace diverse
