// CMA-ES: the (mu/mu_w, lambda) covariance matrix adaptation evolution strategy.
//
// Follows N. Hansen, "The CMA Evolution Strategy: A Tutorial" (arXiv:1604.00772,
// 2016), with all default constants from its appendix A: weighted recombination,
// cumulative step-size adaptation with the h_sigma stall, rank-one and rank-mu
// covariance updates, and the active (negative-weight) update on by default with the
// tutorial's scaling of the negative weights. Minimizes. Equation numbers in
// cmaes.cc refer to that tutorial. docs/reference/cmaes.md has the measured behaviour.
//
// Ask / tell: evaluation stays outside the optimizer, so callers may evaluate a
// generation's samples in parallel, in any order, on any number of threads.
//
//   Cmaes es(options, x0);
//   while (es.stop_reason() == StopReason::kNone) {
//     const auto& xs = es.ask();                     // lambda candidates
//     std::vector<double> f(xs.size());
//     for (size_t k = 0; k < xs.size(); ++k) f[k] = objective(xs[k]);
//     es.tell(f);
//   }
//
// Bounds: when Options::bounded is set, the search space is the box
// [lower, upper]^n (per coordinate) and the distribution lives in an unbounded
// "genotype" space; each genotype coordinate g is mapped into the box by periodic
// reflection at the bounds (a mirror of period 2 (upper - lower), as pycma's
// BoundTransform does in its linear region):
//   t = (g - lower) mod 2 w,  w = upper - lower;  x = lower + (t <= w ? t : 2 w - t).
// ask() returns the reflected, in-bounds points: what the objective sees is always
// exactly what is reported, and nothing is clipped. The update uses the genotypes,
// so the objective seen by the strategy is f(reflect(g)), which is continuous; an
// optimum on a bound becomes a ridge there, which CMA-ES converges to. After each
// update the genotype mean is shifted by whole periods to stay within half a box
// width of the box (this changes no phenotype). x0 is a genotype: a start outside
// the box is reflected into it.
//
// Eigendecomposition: C = B diag(D^2) B^T is decomposed lazily, at most once every
// 1 / (10 n (c1 + c_mu)) generations (the tutorial's footnote on complexity; libcmaes
// and pycma do the same), so the cost per generation stays O(n^2 lambda) for large
// n. Sampling and C^{-1/2} use the last decomposition. The condition number of C is
// capped at 1e14 by adding to its diagonal (the stop criterion max_condition fires
// first by default); sigma and the scale of C are kept within ranges where no
// sample can overflow, so no state value is ever NaN or infinite.
//
// Fitness: only the ranking is used. NaN and +-inf rank worse than every finite
// value (in index order among themselves) and never become best_f().
//
// Determinism: all randomness comes from one Rng seeded from Options::seed; the
// samples of a generation are drawn in a fixed order (sample by sample, coordinate
// by coordinate) before any evaluation, so results never depend on threads.
// to_json() / from_json() capture the full state (options, mean, sigma, C, its
// eigendecomposition, both paths, counters, RNG state, recent-best history, a
// pending population) with every double stored bit-exactly as a hexadecimal
// floating-point string, so a restored instance continues bit-identically.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/rng.h"

namespace diverse {

enum class StopReason {
  kNone = 0,
  kTargetReached,    // best f <= Options::target_f
  kMaxEvaluations,   // evaluations >= Options::max_evaluations
  kMaxGenerations,   // generation >= Options::max_generations
  kTolFun,           // range of recent best f values (and of the last generation) below tol_fun
  kTolX,             // sigma * max(sqrt(diag C), |p_c|) below tol_x in every coordinate
  kConditionNumber,  // condition number of C exceeded max_condition
  kNoEffectAxis,     // adding 0.1 sigma along a principal axis does not change the mean
};
// "none", "target", "max_evaluations", "max_generations", "tol_fun", "tol_x",
// "condition_number", "no_effect_axis".
const char* to_string(StopReason reason);

struct CmaesOptions {
  int dim = 0;             // n, number of parameters (>= 1)
  int popsize = 0;         // lambda (>= 2); 0 = default 4 + floor(3 ln n)
  double sigma0 = 0.3;     // initial step size (> 0, in parameter units)
  std::uint64_t seed = 1;  // RNG seed; 0 is a valid seed like any other
  bool active = true;      // active covariance update (negative weights)
  // Box bounds (reflection, see above). Ignored unless bounded; lower < upper.
  bool bounded = false;
  double lower = 0.0;
  double upper = 1.0;
  // Stopping criteria. target_f: stop when best f <= target_f (default: never).
  // For the others a value <= 0 disables the criterion.
  double target_f = -std::numeric_limits<double>::infinity();
  long long max_evaluations = 0;
  long long max_generations = 0;
  double tol_fun = 1e-12;
  double tol_x = 1e-12;
  double max_condition = 1e14;  // values above 1e14 act as 1e14 (C is capped there)
};

// Strategy constants derived from (n, lambda, active); tutorial appendix A.
struct CmaesConstants {
  int n = 0, lambda = 0, mu = 0;
  Eigen::VectorXd weights;  // all lambda weights, decreasing; the first mu positive, sum 1
  double mueff = 0;         // variance-effective selection mass of the positive weights
  double mueff_minus = 0;   // same for the negative part of the raw weights
  double cc = 0, cs = 0, c1 = 0, cmu = 0, damps = 0, cm = 1;
  double chi_n = 0;        // E||N(0, I)||
  double lazy_gap = 0;     // generations between eigendecompositions (at least)
  int history_length = 0;  // recent-best window of tol_fun: 10 + ceil(30 n / lambda)
};

class Cmaes {
 public:
  // Throws std::invalid_argument for options out of range or x0.size() != dim.
  Cmaes(const CmaesOptions& options, const Eigen::VectorXd& x0);

  // Draws lambda new candidates (in bounds when bounded). Must be followed by tell()
  // before the next ask() (std::logic_error otherwise). Allowed after a stop.
  const std::vector<Eigen::VectorXd>& ask();
  // Fitness of each candidate of the last ask(), same order; lower is better.
  // Non-finite values are treated as worse than every finite value.
  // Throws std::logic_error without a pending ask(), std::invalid_argument on a size
  // mismatch.
  void tell(const std::vector<double>& fitness);

  // The population of the last ask(), in bounds; while pending() it still awaits
  // tell(). After from_json() of a state saved between ask() and tell() this is the
  // population to evaluate and tell.
  const std::vector<Eigen::VectorXd>& candidates() const { return candidates_; }
  bool pending() const { return pending_; }

  StopReason stop_reason() const { return stop_reason_; }

  int dim() const { return k_.n; }
  int popsize() const { return k_.lambda; }
  const CmaesOptions& options() const { return options_; }
  const CmaesConstants& constants() const { return k_; }
  // Distribution mean, mapped into the box when bounded (the point to report).
  Eigen::VectorXd mean() const;
  const Eigen::VectorXd& mean_genotype() const { return mean_; }
  double sigma() const { return sigma_; }
  // C in genotype space; the sampling covariance is sigma^2 C.
  const Eigen::MatrixXd& covariance() const { return C_; }
  // Condition number of C at the last eigendecomposition (before capping).
  double condition_number() const { return condition_; }
  long long generation() const { return generation_; }
  long long evaluations() const { return evaluations_; }
  // Best candidate ever told (in bounds) and its fitness; +inf and the mapped x0
  // until a finite fitness has been told.
  const Eigen::VectorXd& best_x() const { return best_x_; }
  double best_f() const { return best_f_; }

  nlohmann::json to_json() const;
  // Throws diverse::UserError naming the field when the state is malformed.
  static Cmaes from_json(const nlohmann::json& state);

 private:
  Cmaes() = default;
  void set_constants();
  void update_eigensystem(bool force);
  void limit_scales();
  StopReason check_stop(const std::vector<double>& fitness) const;
  void draw_candidates();
  Eigen::VectorXd to_box(const Eigen::VectorXd& genotype) const;

  CmaesOptions options_;
  CmaesConstants k_;
  // Dynamic state.
  Eigen::VectorXd mean_, ps_, pc_;
  double sigma_ = 0;
  Eigen::MatrixXd C_, B_;
  Eigen::VectorXd D_;  // square roots of the eigenvalues of C (after capping)
  double condition_ = 1;
  long long eigen_generation_ = 0;  // generation of the last eigendecomposition
  long long generation_ = 0, evaluations_ = 0;
  Rng rng_;
  // Pending population: standard normal draws z (n x lambda), steps y = B D z and
  // genotypes / in-bounds candidates; valid between ask() and tell().
  bool pending_ = false;
  Eigen::MatrixXd Z_, Y_;
  std::vector<Eigen::VectorXd> genotypes_, candidates_;
  std::vector<double> recent_best_;  // best f of each of the last history_length generations
  Eigen::VectorXd best_x_;
  double best_f_ = std::numeric_limits<double>::infinity();
  StopReason stop_reason_ = StopReason::kNone;
};

}  // namespace diverse
