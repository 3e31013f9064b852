#include "optimize/diversity.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "core/error.h"
#include "core/rng.h"

namespace diverse {
namespace {

constexpr const char* kCheckpointFormat = "diverse.diversity_checkpoint";
constexpr int kCheckpointVersion = 3;

nlohmann::json vector_json(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

// An integer field of a saved state, checked to be an integer (not a float or a bool)
// that fits T: a float cast to an int out of its range is undefined behaviour.
template <class T>
T integer_from_json(const nlohmann::json& j, const char* field) {
  bool fits = false;
  if (j.is_number_unsigned()) {
    fits = j.get<std::uint64_t>() <= static_cast<std::uint64_t>(std::numeric_limits<T>::max());
  } else if (j.is_number_integer()) {
    const long long v = j.get<long long>();
    fits = v >= static_cast<long long>(std::numeric_limits<T>::min()) &&
           (v < 0 || static_cast<unsigned long long>(v) <= static_cast<unsigned long long>(std::numeric_limits<T>::max()));
  }
  if (!fits)
    throw UserError(std::string(field) + ": expected an integer in [" +
                    std::to_string(std::numeric_limits<T>::min()) + ", " +
                    std::to_string(std::numeric_limits<T>::max()) + "], got " + j.dump());
  return j.get<T>();
}

Eigen::VectorXd vector_from_json(const nlohmann::json& j) {
  const auto values = j.get<std::vector<double>>();
  return Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
}

nlohmann::json points_json(const std::vector<Eigen::VectorXd>& points) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& p : points) j.push_back(vector_json(p));
  return j;
}

std::vector<Eigen::VectorXd> points_from_json(const nlohmann::json& j) {
  std::vector<Eigen::VectorXd> points;
  for (const auto& p : j) points.push_back(vector_from_json(p));
  return points;
}

DiversityStop parse_stop(const std::string& name) {
  for (DiversityStop s : {DiversityStop::kNone, DiversityStop::kMaxGenerations,
                          DiversityStop::kStagnation, DiversityStop::kConverged}) {
    if (name == to_string(s)) return s;
  }
  throw UserError("checkpoint: stop: expected a stop reason, got '" + name + "'");
}

std::shared_ptr<const Outcome> checked(std::shared_ptr<const Outcome> outcome) {
  if (!outcome) throw std::logic_error("diversity: DiversityProblem::evaluate returned null");
  return outcome;
}

// Evaluates several points on the pool, one outcome per point, in index order.
std::vector<std::shared_ptr<const Outcome>> evaluate_on_pool(const DiversityProblem& problem,
                                                             ThreadPool& pool,
                                                             const std::vector<Eigen::VectorXd>& xs) {
  std::vector<std::shared_ptr<const Outcome>> outcomes(xs.size());
  pool.parallel_for(xs.size(), [&](std::size_t k, int worker) {
    outcomes[k] = checked(problem.evaluate(xs[k], worker));
  });
  return outcomes;
}

// D of `base` (the present motions, already scored) with motion `index` replaced by
// `outcome`: only row and column `index` of the distance matrix change.
double replaced_objective(const DiversityProblem& problem,
                          const std::vector<std::shared_ptr<const Outcome>>& outcomes,
                          const DiversityScore& base, int index, const Outcome& outcome, double k) {
  Eigen::MatrixXd distance = base.distance;
  Eigen::VectorXd constraint = base.constraint;
  constraint[index] = scored_constraint(outcome);
  for (Eigen::Index j = 0; j < constraint.size(); ++j) {
    if (j == index) continue;
    // Arguments in index order, as score_diversity calls them.
    const double d = j < index ? scored_distance(problem, *outcomes[j], outcome)
                               : scored_distance(problem, outcome, *outcomes[j]);
    distance(index, j) = d;
    distance(j, index) = d;
  }
  return diversity_objective(distance, constraint, k);
}

}  // namespace

const char* to_string(DiversityStrategy strategy) {
  switch (strategy) {
    case DiversityStrategy::kRoundRobin: return "round-robin";
    case DiversityStrategy::kProgressive: return "progressive";
    case DiversityStrategy::kJoint: return "joint";
    case DiversityStrategy::kSimultaneous: return "simultaneous";
  }
  return "?";
}

DiversityStrategy parse_strategy(const std::string& name, const std::string& where) {
  for (DiversityStrategy s : {DiversityStrategy::kRoundRobin, DiversityStrategy::kProgressive,
                              DiversityStrategy::kJoint, DiversityStrategy::kSimultaneous}) {
    if (name == to_string(s)) return s;
  }
  throw UserError(where + ": expected one of round-robin, progressive, joint, simultaneous, got '" +
                  name + "'");
}

const char* to_string(ConstraintRule rule) {
  switch (rule) {
    case ConstraintRule::kDominant: return "dominant";
    case ConstraintRule::kPenalty: return "penalty";
  }
  return "?";
}

const char* to_string(VariationPoint point) {
  switch (point) {
    case VariationPoint::kBestSample: return "best-sample";
    case VariationPoint::kMean: return "mean";
  }
  return "?";
}

VariationPoint parse_variation_point(const std::string& name, const std::string& where) {
  for (VariationPoint p : {VariationPoint::kBestSample, VariationPoint::kMean}) {
    if (name == to_string(p)) return p;
  }
  throw UserError(where + ": expected one of best-sample, mean, got '" + name + "'");
}

ConstraintRule parse_constraint_rule(const std::string& name, const std::string& where) {
  for (ConstraintRule r : {ConstraintRule::kDominant, ConstraintRule::kPenalty}) {
    if (name == to_string(r)) return r;
  }
  throw UserError(where + ": expected one of dominant, penalty, got '" + name + "'");
}

const char* to_string(DiversityStop stop) {
  switch (stop) {
    case DiversityStop::kNone: return "none";
    case DiversityStop::kMaxGenerations: return "max-generations";
    case DiversityStop::kStagnation: return "stagnation";
    case DiversityStop::kConverged: return "converged";
  }
  return "?";
}

void validate(const DiversityOptions& o) {
  auto fail = [](const std::string& what) {
    throw std::invalid_argument("diversity options: " + what);
  };
  // The upper limits keep a corrupt or hostile checkpoint from asking for memory or time
  // no run could use (N^2 distances per set, lambda samples per generation).
  if (o.variations < 1 || o.variations > kMaxDiversityVariations)
    fail("variations must be in [1, " + std::to_string(kMaxDiversityVariations) + "]");
  if (!(o.k >= 0.0) || !std::isfinite(o.k)) fail("k must be a finite number >= 0");
  if (o.popsize < 2 || o.popsize > kMaxDiversityPopsize)
    fail("popsize must be in [2, " + std::to_string(kMaxDiversityPopsize) + "]");
  if (!(o.sigma0 > 0.0) || !std::isfinite(o.sigma0)) fail("sigma0 must be > 0");
  if (o.max_generations < 1) fail("max_generations must be >= 1");
  if (o.window < 0) fail("window must be >= 0");
  if (!(o.epsilon >= 0.0) || !std::isfinite(o.epsilon)) fail("epsilon must be a finite number >= 0");
}

nlohmann::json to_json(const DiversityOptions& o) {
  return {{"variations", o.variations},         {"k", o.k},
          {"strategy", to_string(o.strategy)},  {"constraints", to_string(o.constraints)},
          {"point", to_string(o.point)},
          {"popsize", o.popsize},
          {"sigma0", o.sigma0},                 {"max_generations", o.max_generations},
          {"window", o.window},                 {"epsilon", o.epsilon},
          {"seed", o.seed}};
}

DiversityOptions diversity_options_from_json(const nlohmann::json& j) {
  DiversityOptions o;
  o.variations = integer_from_json<int>(j.at("variations"), "variations");
  o.k = j.at("k").get<double>();
  o.strategy = parse_strategy(j.at("strategy").get<std::string>(), "strategy");
  o.constraints = parse_constraint_rule(j.at("constraints").get<std::string>(), "constraints");
  o.point = parse_variation_point(j.at("point").get<std::string>(), "point");
  o.popsize = integer_from_json<int>(j.at("popsize"), "popsize");
  o.sigma0 = j.at("sigma0").get<double>();
  o.max_generations = integer_from_json<long long>(j.at("max_generations"), "max_generations");
  o.window = integer_from_json<int>(j.at("window"), "window");
  o.epsilon = j.at("epsilon").get<double>();
  o.seed = integer_from_json<std::uint64_t>(j.at("seed"), "seed");
  return o;
}

nlohmann::json to_json(const DiversityRecord& r) {
  return {{"generation", r.generation}, {"step", r.step},
          {"variation", r.variation},   {"D", r.D},
          {"best_D", r.best_D},         {"constraint", vector_json(r.constraint)},
          {"dmin", vector_json(r.dmin)}, {"evaluations", r.evaluations},
          {"samples", r.samples},       {"feasible", r.feasible},
          {"confirmations", r.confirmations}, {"simulation_steps", r.simulation_steps}};
}

namespace {

DiversityRecord record_from_json(const nlohmann::json& j) {
  DiversityRecord r;
  r.generation = integer_from_json<long long>(j.at("generation"), "log.generation");
  r.step = integer_from_json<long long>(j.at("step"), "log.step");
  r.variation = integer_from_json<int>(j.at("variation"), "log.variation");
  r.D = j.at("D").get<double>();
  r.best_D = j.at("best_D").get<double>();
  r.constraint = vector_from_json(j.at("constraint"));
  r.dmin = vector_from_json(j.at("dmin"));
  r.evaluations = integer_from_json<long long>(j.at("evaluations"), "log.evaluations");
  // Absent from checkpoints written before they were counted.
  if (j.contains("samples")) r.samples = integer_from_json<int>(j.at("samples"), "log.samples");
  if (j.contains("feasible")) r.feasible = integer_from_json<int>(j.at("feasible"), "log.feasible");
  r.confirmations = integer_from_json<long long>(j.at("confirmations"), "log.confirmations");
  r.simulation_steps = integer_from_json<long long>(j.at("simulation_steps"), "log.simulation_steps");
  return r;
}

}  // namespace

DiversityOptimizer::DiversityOptimizer(const DiversityProblem& problem, ThreadPool& pool,
                                       BatchEvaluator* batch)
    : problem_(&problem), pool_(&pool), batch_(batch) {}

std::vector<std::shared_ptr<const Outcome>> DiversityOptimizer::evaluate_all(
    const std::vector<Eigen::VectorXd>& xs, bool tally) {
  std::vector<std::shared_ptr<const Outcome>> outcomes;
  if (!batch_) {
    outcomes = evaluate_on_pool(*problem_, *pool_, xs);
  } else {
    outcomes = batch_->evaluate(xs);
    if (outcomes.size() != xs.size())
      throw std::logic_error("diversity: BatchEvaluator returned the wrong number of outcomes");
    for (auto& outcome : outcomes) outcome = checked(std::move(outcome));
  }
  if (tally)
    for (const auto& outcome : outcomes) problem_->tally(*outcome, ledger_);
  return outcomes;
}

void DiversityOptimizer::confirm_all(const std::vector<Eigen::VectorXd>& xs,
                                     std::vector<std::shared_ptr<const Outcome>>& outcomes,
                                     bool tally) {
  std::vector<std::size_t> open;
  for (std::size_t k = 0; k < outcomes.size(); ++k)
    if (outcomes[k]->provisional) open.push_back(k);
  if (open.empty()) return;
  // Confirmations run on this process's pool: they are few, and each gives the same
  // outcome bit for bit wherever it runs.
  std::vector<std::shared_ptr<const Outcome>> confirmed(open.size());
  pool_->parallel_for(open.size(), [&](std::size_t i, int worker) {
    confirmed[i] = checked(problem_->confirm(xs[open[i]], *outcomes[open[i]], worker));
    if (confirmed[i]->provisional)
      throw std::logic_error("diversity: DiversityProblem::confirm returned a provisional outcome");
  });
  for (std::size_t i = 0; i < open.size(); ++i) {
    outcomes[open[i]] = confirmed[i];
    if (tally) problem_->tally(*confirmed[i], ledger_);
  }
  confirmations_ += tally ? static_cast<long long>(open.size()) : 0;
}

std::vector<std::size_t> DiversityOptimizer::confirmation_order(
    const std::vector<std::shared_ptr<const Outcome>>& outcomes, std::size_t first,
    std::vector<double> C, std::vector<double> D, std::size_t width) const {
  // Each confirmation that fails drops its sample below every sample that meets the
  // constraints, so the loop of choose_confirmed() would take the candidates in their
  // order until one holds: the best, the best of the rest, and so on, up to the first one
  // that is confirmed already or the incumbent.
  const std::size_t n = C.size() - 1;
  std::vector<std::size_t> order;
  while (order.size() < width) {
    const std::size_t best = best_candidate(C, D);
    if (best == n || !outcomes[first + best]->provisional) break;
    order.push_back(best);
    C[best] = std::numeric_limits<double>::infinity();
    D[best] = -std::numeric_limits<double>::infinity();
  }
  return order;
}

std::size_t DiversityOptimizer::choose_confirmed(int v, const std::vector<Eigen::VectorXd>& xs,
                                                 std::vector<std::shared_ptr<const Outcome>>& outcomes,
                                                 std::size_t first, std::vector<double>& C,
                                                 std::vector<double>& D) {
  const std::size_t n = C.size() - 1;  // candidates; the last entry is the incumbent
  // Confirmations run kConfirmWidth at a time: the winner's and those of the candidates
  // that would be confirmed next if it failed (most fail, and one check alone would
  // leave all workers but one idle). Only the ones the loop below asks for are used, so
  // the choice is the same as with one check at a time; the others' steps are counted.
  std::vector<std::shared_ptr<const Outcome>> checked_ahead(n);
  for (;;) {
    const std::size_t best = best_candidate(C, D);
    if (best == n || !outcomes[first + best]->provisional) return best;
    // The winner is provisional: confirm it, rank it again with its final C, and choose
    // again. A confirmation that holds ends the search; one that fails drops the sample.
    if (!checked_ahead[best]) {
      const std::vector<std::size_t> order = confirmation_order(outcomes, first, C, D, kConfirmWidth);
      std::vector<Eigen::VectorXd> ahead_x;
      std::vector<std::shared_ptr<const Outcome>> ahead;
      for (std::size_t k : order) {
        ahead_x.push_back(xs[k]);
        ahead.push_back(outcomes[first + k]);
      }
      confirm_all(ahead_x, ahead, true);
      for (std::size_t i = 0; i < order.size(); ++i) checked_ahead[order[i]] = ahead[i];
    }
    outcomes[first + best] = checked_ahead[best];
    C[best] = scored_constraint(*outcomes[first + best]);
    D[best] = replaced_objective(*problem_, outcomes_, current_, v, *outcomes[first + best], options_.k);
  }
}

DiversityOptimizer::DiversityOptimizer(const DiversityProblem& problem,
                                       const DiversityOptions& options, ThreadPool& pool,
                                       BatchEvaluator* batch)
    : problem_(&problem), pool_(&pool), batch_(batch), options_(options) {
  validate(options_);
  const int n = options_.variations;
  const int dim = problem_->dim();
  const Eigen::VectorXd p0 = problem_->reference();
  if (dim < 1 || p0.size() != dim || !(p0.array() >= 0.0).all() || !(p0.array() <= 1.0).all()) {
    throw std::logic_error("diversity: the problem's reference must have dim() >= 1 entries, "
                           "all in [0, 1]");
  }

  // Every variation starts at P_0, so all share M_0's outcome until they move.
  std::vector<std::shared_ptr<const Outcome>> first = evaluate_all({p0});
  confirm_all({p0}, first, true);
  const auto m0 = first.front();
  evaluations_ = 1;
  points_.assign(n + 1, p0);
  outcomes_.assign(n + 1, m0);
  paths_.assign(n + 1, {PathPoint{0, 0, p0}});

  if (options_.strategy == DiversityStrategy::kJoint) {
    cmas_.emplace_back(cma_options(n * dim, 0), p0.replicate(n, 1));
  } else {
    for (int v = 1; v <= n; ++v) cmas_.emplace_back(cma_options(dim, v), p0);
  }
  if (options_.strategy == DiversityStrategy::kProgressive) {
    active_ = 1;
    phase_start_ = 0;
    phase_budget_ = std::max<long long>(1, options_.max_generations / n);
  }
  rescore();
  best_ = Snapshot{points_, outcomes_, current_};
  best_history_.push_back(merit(best_.score));
}

DiversityOptimizer::Merit DiversityOptimizer::merit(const DiversityScore& score) const {
  Merit m;
  m.D = score.D;
  if (options_.constraints == ConstraintRule::kDominant) m.violation = score.constraint.sum();
  return m;
}

bool DiversityOptimizer::better(const Merit& a, const Merit& b) const {
  if (a.violation != b.violation) return a.violation < b.violation;
  return a.D > b.D;
}

std::size_t DiversityOptimizer::best_candidate(const std::vector<double>& constraint,
                                               const std::vector<double>& D) const {
  // The last candidate is the incumbent; it wins ties, so a point only moves to improve.
  std::size_t best = D.size() - 1;
  for (std::size_t k = 0; k + 1 < D.size(); ++k) {
    if (better(Merit{options_.constraints == ConstraintRule::kDominant ? constraint[k] : 0.0, D[k]},
               Merit{options_.constraints == ConstraintRule::kDominant ? constraint[best] : 0.0,
                     D[best]})) {
      best = k;
    }
  }
  return best;
}

std::vector<double> DiversityOptimizer::fitness(const std::vector<double>& constraint,
                                                const std::vector<double>& D) const {
  // CMA-ES minimizes.
  std::vector<double> f(D.size());
  for (std::size_t k = 0; k < D.size(); ++k) f[k] = -D[k];
  if (options_.constraints == ConstraintRule::kPenalty) return f;
  // Dominant: every infeasible sample above (worse than) every feasible one, in the
  // order of its C. Ranks, not C itself, so that no C is lost to rounding beside a large
  // D; CMA-ES only uses the order.
  double worst_feasible = 0.0;
  std::vector<double> violations;
  for (std::size_t k = 0; k < D.size(); ++k) {
    if (constraint[k] > 0.0) {
      violations.push_back(constraint[k]);
    } else {
      worst_feasible = std::max(worst_feasible, f[k]);
    }
  }
  std::sort(violations.begin(), violations.end());
  violations.erase(std::unique(violations.begin(), violations.end()), violations.end());
  for (std::size_t k = 0; k < D.size(); ++k) {
    if (constraint[k] > 0.0) {
      const auto rank = std::lower_bound(violations.begin(), violations.end(), constraint[k]) -
                        violations.begin();
      f[k] = worst_feasible + 1.0 + static_cast<double>(rank);
    }
  }
  return f;
}

CmaesOptions DiversityOptimizer::cma_options(int dim, int instance) const {
  CmaesOptions o;
  o.dim = dim;
  o.popsize = options_.popsize;
  o.sigma0 = options_.sigma0;
  o.seed = derive_seed(options_.seed, {static_cast<std::uint64_t>(instance)});
  o.bounded = true;  // normalized parameters: reflection into [0, 1]
  o.lower = 0.0;
  o.upper = 1.0;
  // D moves as the other variations move, so "f stopped changing" and "x stopped moving"
  // say little about one instance; the optimizer's own stagnation test decides instead.
  o.tol_fun = 0.0;
  o.tol_x = 0.0;
  return o;
}

int DiversityOptimizer::present() const {
  return options_.strategy == DiversityStrategy::kProgressive ? active_ + 1
                                                              : options_.variations + 1;
}

void DiversityOptimizer::rescore() {
  const std::vector<std::shared_ptr<const Outcome>> present_outcomes(
      outcomes_.begin(), outcomes_.begin() + present());
  current_ = score_diversity(*problem_, present_outcomes, options_.k);
}

bool DiversityOptimizer::step() {
  if (done()) return false;
  struct InStep {
    explicit InStep(bool& flag) : flag_(flag) { flag_ = true; }
    ~InStep() { flag_ = false; }
    bool& flag_;
  } in_step(in_step_);
  ++generation_;
  switch (options_.strategy) {
    case DiversityStrategy::kRoundRobin:
      if (options_.point == VariationPoint::kBestSample) {
        step_round_robin();
      } else {
        for (int v = 1; v <= options_.variations; ++v) {
          if (cmas_[v - 1].stop_reason() == StopReason::kNone) step_variation(v);
        }
      }
      break;
    case DiversityStrategy::kProgressive:
      for (int s = 0; s < options_.variations; ++s) {
        if (cmas_[active_ - 1].stop_reason() != StopReason::kNone) break;
        step_variation(active_);
      }
      break;
    case DiversityStrategy::kJoint:
      step_joint();
      break;
    case DiversityStrategy::kSimultaneous:
      step_simultaneous();
      break;
  }
  end_generation();
  return !done();
}

void DiversityOptimizer::run() {
  while (step()) {
  }
}

DiversityOptimizer::Drawn DiversityOptimizer::draw_generation() {
  Drawn g;
  g.xs.resize(static_cast<std::size_t>(options_.variations) + 1);
  g.first.assign(g.xs.size(), 0);
  for (int v = 1; v <= options_.variations; ++v) {
    if (cmas_[v - 1].stop_reason() != StopReason::kNone) continue;
    g.active.push_back(v);
    g.xs[v] = cmas_[v - 1].ask();
    g.first[v] = g.batch.size();
    g.batch.insert(g.batch.end(), g.xs[v].begin(), g.xs[v].end());
  }
  return g;
}

void DiversityOptimizer::score_against_current(int v, const std::vector<std::shared_ptr<const Outcome>>& outcomes,
                                               std::size_t first, std::size_t n, std::vector<double>& C,
                                               std::vector<double>& D) const {
  C.resize(n);
  D.resize(n);
  pool_->parallel_for(n, [&](std::size_t k, int) {
    const Outcome& o = *outcomes[first + k];
    D[k] = replaced_objective(*problem_, outcomes_, current_, v, o, options_.k);
    C[k] = scored_constraint(o);
  });
}

void DiversityOptimizer::step_round_robin() {
  // A rollout depends on its sample alone and variation v's samples on its own CMA
  // instance alone, so every variation's samples of this generation are drawn and
  // simulated in one batch (N x lambda rollouts keep more workers busy than lambda). Only
  // the scoring depends on where the others stand: it runs variation by variation, each
  // against the moves of those before it, exactly as one batch per variation would.
  Drawn g = draw_generation();
  if (g.active.empty()) return;
  const auto outcomes = evaluate_all(g.batch, false);
  for (int v : g.active) {
    const auto begin = outcomes.begin() + static_cast<std::ptrdiff_t>(g.first[v]);
    std::vector<std::shared_ptr<const Outcome>> own(begin, begin + static_cast<std::ptrdiff_t>(g.xs[v].size()));
    // Tallied as the variation's step comes, so the log counts steps as it always did.
    for (const auto& outcome : own) problem_->tally(*outcome, ledger_);
    evaluations_ += static_cast<long long>(g.xs[v].size());
    move_to_best_sample(v, g.xs[v], own);
  }
}

void DiversityOptimizer::step_variation(int v) {
  Cmaes& es = cmas_[v - 1];
  const std::vector<Eigen::VectorXd> xs = es.ask();

  // The previous step's new mean rides along with this step's samples, so that its
  // single evaluation does not leave the other workers idle.
  std::vector<Eigen::VectorXd> batch = xs;
  if (pending_ > 0) batch.push_back(points_[pending_]);  // only with VariationPoint::kMean
  auto outcomes = evaluate_all(batch);
  if (pending_ > 0) {
    std::vector<std::shared_ptr<const Outcome>> mean{outcomes.back()};
    confirm_all({batch.back()}, mean, true);
    settle_pending(mean.front());
    outcomes.pop_back();
  }
  evaluations_ += static_cast<long long>(xs.size());
  if (options_.point == VariationPoint::kBestSample) {
    move_to_best_sample(v, xs, outcomes);
    return;
  }

  // Each sample replaces M_v in the current set and is ranked by its D and its own C.
  std::vector<double> D, C;
  score_against_current(v, outcomes, 0, xs.size(), C, D);
  count_samples(outcomes, xs.size());
  es.tell(fitness(C, D));
  // The new mean is what the other variations' samples are scored against from now on;
  // it is evaluated with the next batch (or at the end of the generation).
  points_[v] = es.mean();
  pending_ = v;
}

void DiversityOptimizer::move_to_best_sample(int v, const std::vector<Eigen::VectorXd>& xs,
                                             std::vector<std::shared_ptr<const Outcome>>& outcomes) {
  // Each sample replaces M_v in the current set and is ranked by its D and its own C.
  std::vector<double> D, C;
  score_against_current(v, outcomes, 0, xs.size(), C, D);
  // M_v becomes this generation's best sample if it beats M_v as it stands, confirmed
  // (DiversityProblem::confirm) before it may; CMA-ES learns every confirmation's result.
  D.push_back(current_.D);
  C.push_back(current_.constraint[v]);
  const std::size_t best = choose_confirmed(v, xs, outcomes, 0, C, D);
  D.pop_back();
  C.pop_back();
  count_samples(outcomes, xs.size());
  cmas_[v - 1].tell(fitness(C, D));
  if (best < xs.size()) {
    points_[v] = xs[best];
    outcomes_[v] = outcomes[best];
  }
  finish_step(v);
}

void DiversityOptimizer::count_samples(const std::vector<std::shared_ptr<const Outcome>>& outcomes,
                                       std::size_t n) {
  step_samples_ = static_cast<int>(n);
  step_feasible_ = 0;
  for (std::size_t k = 0; k < n; ++k)
    if (scored_constraint(*outcomes[k]) == 0.0) ++step_feasible_;
}

void DiversityOptimizer::step_simultaneous() {
  // Every instance still running draws its generation; one batch holds them all.
  Drawn g = draw_generation();
  const std::vector<int>& active = g.active;
  const std::vector<std::vector<Eigen::VectorXd>>& xs = g.xs;
  const std::vector<Eigen::VectorXd>& batch = g.batch;
  const std::vector<std::size_t>& first = g.first;
  if (active.empty()) return;
  auto outcomes = evaluate_all(batch);
  evaluations_ += static_cast<long long>(batch.size());

  // Each sample of variation v replaces M_v in the set as it stood when the generation
  // was drawn, ranked by its D and its own C; every instance learns from that.
  std::vector<double> D(batch.size()), C(batch.size());
  std::vector<int> owner(batch.size());
  for (int v : active)
    for (std::size_t k = 0; k < xs[v].size(); ++k) owner[first[v] + k] = v;
  const std::vector<std::shared_ptr<const Outcome>> drawn = outcomes_;
  const DiversityScore drawn_score = current_;
  pool_->parallel_for(batch.size(), [&](std::size_t k, int) {
    D[k] = replaced_objective(*problem_, drawn, drawn_score, owner[k], *outcomes[k], options_.k);
    C[k] = scored_constraint(*outcomes[k]);
  });
  auto tell_all = [&] {
    count_samples(outcomes, batch.size());
    for (int v : active) {
      const auto begin = static_cast<std::ptrdiff_t>(first[v]);
      const auto end = begin + static_cast<std::ptrdiff_t>(xs[v].size());
      cmas_[v - 1].tell(fitness(std::vector<double>(C.begin() + begin, C.begin() + end),
                                std::vector<double>(D.begin() + begin, D.begin() + end)));
    }
  };
  if (options_.point != VariationPoint::kBestSample) tell_all();

  if (options_.point == VariationPoint::kBestSample) {
    // The variations move one after another, in order 1..N, each to its best sample if
    // that beats where it stands among the others as they now stand (some moved a moment
    // ago): ranked as in round-robin, so two variations never step onto the same ground
    // and the current set never gets worse. Costs distances only, no rollout.
    for (int v : active) {
      const std::size_t lambda = xs[v].size();
      std::vector<double> Dv, Cv;
      score_against_current(v, outcomes, first[v], lambda, Cv, Dv);
      Dv.push_back(current_.D);
      Cv.push_back(current_.constraint[v]);
      const std::size_t best = choose_confirmed(v, xs[v], outcomes, first[v], Cv, Dv);
      // A confirmation changes the sample's C and so its D in the drawn set as well.
      for (std::size_t k = 0; k < lambda; ++k) {
        const Outcome& o = *outcomes[first[v] + k];
        if (scored_constraint(o) != C[first[v] + k]) {
          C[first[v] + k] = scored_constraint(o);
          D[first[v] + k] = replaced_objective(*problem_, drawn, drawn_score, v, o, options_.k);
        }
      }
      if (best < lambda) {
        points_[v] = xs[v][best];
        outcomes_[v] = outcomes[first[v] + best];
        rescore();
      }
    }
    tell_all();
    finish_step(0);
    return;
  }
  // The paper's choice: every variation stands at its new mean, evaluated in one batch.
  std::vector<Eigen::VectorXd> means;
  for (int v : active) means.push_back(cmas_[v - 1].mean());
  auto mean_outcomes = evaluate_all(means);
  confirm_all(means, mean_outcomes, true);
  evaluations_ += static_cast<long long>(means.size());
  for (std::size_t i = 0; i < active.size(); ++i) {
    points_[active[i]] = means[i];
    outcomes_[active[i]] = mean_outcomes[i];
  }
  finish_step(0);
}

void DiversityOptimizer::settle_pending(std::shared_ptr<const Outcome> outcome) {
  outcomes_[pending_] = std::move(outcome);
  evaluations_ += 1;
  const int v = pending_;
  pending_ = 0;
  finish_step(v);
}

void DiversityOptimizer::step_joint() {
  Cmaes& es = cmas_.front();
  const int n = options_.variations;
  const int dim = problem_->dim();
  const std::vector<Eigen::VectorXd> xs = es.ask();
  const std::size_t lambda = xs.size();

  // Every sample is a whole set M_1..M_N: N evaluations each, all independent.
  std::vector<Eigen::VectorXd> motions;
  motions.reserve(lambda * n);
  for (std::size_t k = 0; k < lambda; ++k)
    for (int v = 0; v < n; ++v) motions.push_back(xs[k].segment(v * dim, dim));
  // A sample set's motions are scored together, so every provisional one is confirmed.
  std::vector<std::shared_ptr<const Outcome>> outcomes = evaluate_all(motions);
  confirm_all(motions, outcomes, true);
  evaluations_ += static_cast<long long>(lambda * n);
  count_samples(outcomes, outcomes.size());
  std::vector<double> D(lambda), C(lambda);
  pool_->parallel_for(lambda, [&](std::size_t k, int) {
    std::vector<std::shared_ptr<const Outcome>> set{outcomes_.front()};
    set.insert(set.end(), outcomes.begin() + k * n, outcomes.begin() + (k + 1) * n);
    const DiversityScore score = score_diversity(*problem_, set, options_.k);
    D[k] = score.D;
    C[k] = score.constraint.tail(n).sum();
  });
  es.tell(fitness(C, D));

  if (options_.point == VariationPoint::kBestSample) {
    D.push_back(current_.D);
    C.push_back(current_.constraint.tail(n).sum());
    const std::size_t best = best_candidate(C, D);
    if (best < lambda) {
      for (int v = 1; v <= n; ++v) {
        points_[v] = xs[best].segment((v - 1) * dim, dim);
        outcomes_[v] = outcomes[best * n + v - 1];
      }
    }
    finish_step(0);
    return;
  }
  const Eigen::VectorXd mean = es.mean();
  std::vector<Eigen::VectorXd> means;
  for (int v = 1; v <= n; ++v) means.push_back(mean.segment((v - 1) * dim, dim));
  auto mean_outcomes = evaluate_all(means);
  confirm_all(means, mean_outcomes, true);
  evaluations_ += n;
  for (int v = 1; v <= n; ++v) {
    points_[v] = means[v - 1];
    outcomes_[v] = mean_outcomes[v - 1];
  }
  finish_step(0);
}

void DiversityOptimizer::finish_step(int variation) {
  ++steps_;
  rescore();
  if (better(merit(current_), merit(best_.score))) best_ = Snapshot{points_, outcomes_, current_};

  DiversityRecord record;
  record.generation = generation_;
  record.step = steps_;
  record.variation = variation;
  record.D = current_.D;
  record.best_D = best_.score.D;
  record.constraint = current_.constraint;
  record.dmin = current_.dmin;
  record.evaluations = evaluations_;
  record.samples = step_samples_;
  record.feasible = step_feasible_;
  record.confirmations = confirmations_;
  record.simulation_steps = ledger_.is_object() ? ledger_.value("total", 0LL) : 0LL;
  log_.push_back(record);

  // A path records where a variation went: a point for every step that moved it.
  auto extend_path = [&](int v) {
    if (points_[v] != paths_[v].back().x) {
      paths_[v].push_back(PathPoint{generation_, steps_, points_[v]});
    }
  };
  if (variation > 0) {
    extend_path(variation);
  } else {
    for (int v = 1; v <= options_.variations; ++v) extend_path(v);
  }
  if (callback_) callback_(record);
}

void DiversityOptimizer::end_generation() {
  if (pending_ > 0) {
    std::vector<std::shared_ptr<const Outcome>> mean = evaluate_all({points_[pending_]});
    confirm_all({points_[pending_]}, mean, true);
    settle_pending(mean.front());
  }
  best_history_.push_back(merit(best_.score));
  const int window = options_.window;
  // Stagnation: over the window, the best set neither lost violation nor gained epsilon D.
  auto stagnated = [&](long long since) {
    if (window <= 0 || generation_ - since < window) return false;
    const Merit& now = best_history_.back();
    const Merit& then = best_history_[generation_ - window];
    return now.violation >= then.violation && now.D - then.D < options_.epsilon;
  };

  if (options_.strategy != DiversityStrategy::kProgressive) {
    const bool all_stopped = std::all_of(cmas_.begin(), cmas_.end(), [](const Cmaes& es) {
      return es.stop_reason() != StopReason::kNone;
    });
    if (generation_ >= options_.max_generations) {
      stop_ = DiversityStop::kMaxGenerations;
    } else if (stagnated(0)) {
      stop_ = DiversityStop::kStagnation;
    } else if (all_stopped) {
      stop_ = DiversityStop::kConverged;
    }
    return;
  }

  // Progressive: does the newest variation's phase end here?
  DiversityStop phase_end = DiversityStop::kNone;
  if (generation_ - phase_start_ >= phase_budget_) {
    phase_end = DiversityStop::kMaxGenerations;
  } else if (stagnated(phase_start_)) {
    phase_end = DiversityStop::kStagnation;
  } else if (cmas_[active_ - 1].stop_reason() != StopReason::kNone) {
    phase_end = DiversityStop::kConverged;
  }
  if (phase_end == DiversityStop::kNone) return;

  // Freeze the newest variation where the phase's best set had it.
  points_ = best_.points;
  outcomes_ = best_.outcomes;
  current_ = best_.score;
  if (active_ == options_.variations) {
    stop_ = phase_end;
    return;
  }
  ++active_;
  phase_start_ = generation_;
  const long long left = options_.max_generations - generation_;
  phase_budget_ = std::max<long long>(1, left / (options_.variations - active_ + 1));
  rescore();
  best_ = Snapshot{points_, outcomes_, current_};
  best_history_.back() = merit(best_.score);
}

DiversityResult DiversityOptimizer::result() const {
  DiversityResult r;
  const int count = present();
  r.parameters.assign(best_.points.begin(), best_.points.begin() + count);
  r.outcomes.assign(best_.outcomes.begin(), best_.outcomes.begin() + count);
  r.score = best_.score;
  r.generations = generation_;
  r.evaluations = evaluations_;
  r.stop = stop_;
  return r;
}

nlohmann::json DiversityOptimizer::checkpoint() const {
  if (in_step_) {
    throw std::logic_error("DiversityOptimizer::checkpoint: only between generations, not "
                           "from inside step()");
  }
  nlohmann::json j;
  j["format"] = kCheckpointFormat;
  j["version"] = kCheckpointVersion;
  j["options"] = to_json(options_);
  j["reference"] = vector_json(points_.front());
  j["generation"] = generation_;
  j["steps"] = steps_;
  j["evaluations"] = evaluations_;
  j["confirmations"] = confirmations_;
  j["ledger"] = ledger_;
  j["stop"] = to_string(stop_);
  j["active"] = active_;
  j["phase_start"] = phase_start_;
  j["phase_budget"] = phase_budget_;
  nlohmann::json cmas = nlohmann::json::array();
  for (const auto& es : cmas_) cmas.push_back(es.to_json());
  j["cma"] = std::move(cmas);
  j["points"] = points_json(points_);
  j["current_D"] = current_.D;
  j["best"] = {{"points", points_json(best_.points)}, {"D", best_.score.D}};
  nlohmann::json history = nlohmann::json::array();
  for (const Merit& m : best_history_) history.push_back({m.violation, m.D});
  j["best_history"] = std::move(history);
  nlohmann::json log = nlohmann::json::array();
  for (const auto& r : log_) log.push_back(to_json(r));
  j["log"] = std::move(log);
  nlohmann::json paths = nlohmann::json::array();
  for (const auto& path : paths_) {
    nlohmann::json p = nlohmann::json::array();
    for (const auto& point : path) {
      p.push_back({{"generation", point.generation}, {"step", point.step},
                   {"x", vector_json(point.x)}});
    }
    paths.push_back(std::move(p));
  }
  j["paths"] = std::move(paths);
  return j;
}

DiversityOptimizer DiversityOptimizer::from_checkpoint(const DiversityProblem& problem,
                                                       const nlohmann::json& j,
                                                       ThreadPool& pool, BatchEvaluator* batch) {
  if (!j.is_object() || j.value("format", std::string()) != kCheckpointFormat) {
    throw UserError(std::string("checkpoint: format: expected \"") + kCheckpointFormat + "\"");
  }
  if (j.value("version", 0) != kCheckpointVersion) {
    throw UserError("checkpoint: version: expected " + std::to_string(kCheckpointVersion));
  }
  DiversityOptimizer opt(problem, pool, batch);
  try {
    opt.options_ = diversity_options_from_json(j.at("options"));
    validate(opt.options_);
    const Eigen::VectorXd reference = vector_from_json(j.at("reference"));
    if (reference.size() != problem.dim()) {
      throw UserError("checkpoint: reference: expected " + std::to_string(problem.dim()) +
                      " parameters, got " + std::to_string(reference.size()));
    }
    if (reference != problem.reference()) {
      throw UserError("checkpoint: reference: expected the problem's reference parameters");
    }
    opt.generation_ = integer_from_json<long long>(j.at("generation"), "checkpoint: generation");
    opt.steps_ = integer_from_json<long long>(j.at("steps"), "checkpoint: steps");
    opt.evaluations_ = integer_from_json<long long>(j.at("evaluations"), "checkpoint: evaluations");
    opt.confirmations_ = integer_from_json<long long>(j.at("confirmations"), "checkpoint: confirmations");
    opt.ledger_ = j.at("ledger");
    opt.stop_ = parse_stop(j.at("stop").get<std::string>());
    opt.active_ = integer_from_json<int>(j.at("active"), "checkpoint: active");
    opt.phase_start_ = integer_from_json<long long>(j.at("phase_start"), "checkpoint: phase_start");
    opt.phase_budget_ = integer_from_json<long long>(j.at("phase_budget"), "checkpoint: phase_budget");
    for (const auto& state : j.at("cma")) opt.cmas_.push_back(Cmaes::from_json(state));
    opt.points_ = points_from_json(j.at("points"));
    opt.best_.points = points_from_json(j.at("best").at("points"));
    for (const auto& m : j.at("best_history")) {
      opt.best_history_.push_back(Merit{m.at(0).get<double>(), m.at(1).get<double>()});
    }
    for (const auto& r : j.at("log")) opt.log_.push_back(record_from_json(r));
    for (const auto& path : j.at("paths")) {
      std::vector<PathPoint> p;
      for (const auto& point : path) {
        p.push_back(PathPoint{integer_from_json<long long>(point.at("generation"), "checkpoint: paths.generation"),
                              integer_from_json<long long>(point.at("step"), "checkpoint: paths.step"),
                              vector_from_json(point.at("x"))});
      }
      opt.paths_.push_back(std::move(p));
    }
  } catch (const nlohmann::json::exception& e) {
    throw UserError(std::string("checkpoint: ") + e.what());
  }
  const std::size_t count = static_cast<std::size_t>(opt.options_.variations) + 1;
  const std::size_t instances =
      opt.options_.strategy == DiversityStrategy::kJoint ? 1 : count - 1;
  if (opt.points_.size() != count || opt.best_.points.size() != count ||
      opt.cmas_.size() != instances || opt.paths_.size() != count ||
      static_cast<long long>(opt.best_history_.size()) != opt.generation_ + 1) {
    throw UserError("checkpoint: expected state for " + std::to_string(count - 1) +
                    " variations at generation " + std::to_string(opt.generation_));
  }
  for (const auto& p : opt.points_) {
    if (p.size() != problem.dim()) throw UserError("checkpoint: points: wrong dimension");
  }
  for (const auto& p : opt.best_.points) {
    if (p.size() != problem.dim()) throw UserError("checkpoint: best.points: wrong dimension");
  }
  for (const auto& path : opt.paths_) {
    for (const PathPoint& point : path) {
      if (point.x.size() != problem.dim()) throw UserError("checkpoint: paths: wrong dimension");
    }
  }
  const int cma_dim = opt.options_.strategy == DiversityStrategy::kJoint
                          ? opt.options_.variations * problem.dim()
                          : problem.dim();
  for (const Cmaes& cma : opt.cmas_) {
    if (cma.dim() != cma_dim || cma.popsize() != opt.options_.popsize)
      throw UserError("checkpoint: cma: expected states of dimension " + std::to_string(cma_dim) +
                      " and popsize " + std::to_string(opt.options_.popsize));
  }
  if (opt.options_.strategy == DiversityStrategy::kProgressive &&
      (opt.active_ < 1 || opt.active_ > opt.options_.variations))
    throw UserError("checkpoint: active: expected a variation in [1, " +
                    std::to_string(opt.options_.variations) + "]");
  if (opt.generation_ < 0 || opt.steps_ < 0 || opt.evaluations_ < 0 || opt.confirmations_ < 0)
    throw UserError("checkpoint: generation, steps, evaluations, confirmations: expected counts >= 0");

  // Outcomes are not stored: evaluate the distinct points of the current and best sets
  // again (evaluate() is a pure function of x, so these are the same outcomes).
  std::vector<Eigen::VectorXd> distinct;
  auto index_of = [&](const Eigen::VectorXd& x) {
    for (std::size_t i = 0; i < distinct.size(); ++i) {
      if (distinct[i] == x) return i;
    }
    distinct.push_back(x);
    return distinct.size() - 1;
  };
  std::vector<std::size_t> current_index, best_index;
  for (const auto& p : opt.points_) current_index.push_back(index_of(p));
  for (const auto& p : opt.best_.points) best_index.push_back(index_of(p));
  auto outcomes = opt.evaluate_all(distinct, false);
  opt.confirm_all(distinct, outcomes, false);
  for (std::size_t i : current_index) opt.outcomes_.push_back(outcomes[i]);
  for (std::size_t i : best_index) opt.best_.outcomes.push_back(outcomes[i]);

  opt.rescore();
  const std::vector<std::shared_ptr<const Outcome>> best_present(
      opt.best_.outcomes.begin(), opt.best_.outcomes.begin() + opt.present());
  opt.best_.score = score_diversity(problem, best_present, opt.options_.k);
  if (opt.current_.D != j.at("current_D").get<double>() ||
      opt.best_.score.D != j.at("best").at("D").get<double>()) {
    throw std::logic_error(
        "checkpoint: re-evaluated sets do not reproduce their recorded D "
        "(DiversityProblem::evaluate is not deterministic, or the problem changed)");
  }
  return opt;
}

}  // namespace diverse
