// CMA-ES: the (mu/mu_w, lambda) covariance matrix adaptation evolution strategy.
//
// Follows N. Hansen, "The CMA Evolution Strategy: A Tutorial" (arXiv:1604.00772,
// 2016), with all default constants from its appendix A: weighted recombination,
// cumulative step-size adaptation, rank-one and rank-mu covariance updates, and the
// active (negative-weight) update on by default. Minimizes.
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
// "genotype" space; each genotype is mapped into the box by reflection at the
// bounds (a periodic mirror, as pycma's BoundTransform does in its linear region).
// ask() returns the reflected, in-bounds points: what the objective sees is always
// exactly what is reported, and nothing is clipped.
//
// Determinism: all randomness comes from one Rng seeded from Options::seed; the
// samples of a generation are drawn in a fixed order before any evaluation, so
// results never depend on threads. to_json() / from_json() capture the full state
// (mean, sigma, C, its eigendecomposition, both paths, counters, RNG state) so a
// restored instance continues bit-identically.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
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
  kTolFun,           // range of recent best f values below tol_fun
  kTolX,             // sigma * max(sqrt(diag C), |p_c|) below tol_x
  kConditionNumber,  // condition number of C exceeded max_condition
  kNoEffectAxis,     // adding 0.1 sigma along a principal axis does not change the mean
};
const char* to_string(StopReason reason);

struct CmaesOptions {
  int dim = 0;                  // n, number of parameters (>= 1)
  int popsize = 0;              // lambda; 0 = default 4 + floor(3 ln n)
  double sigma0 = 0.3;          // initial step size (in parameter units)
  std::uint64_t seed = 1;       // RNG seed; 0 is a valid seed like any other
  bool active = true;           // active covariance update (negative weights)
  // Box bounds (reflection, see above). Ignored unless bounded.
  bool bounded = false;
  double lower = 0.0;
  double upper = 1.0;
  // Stopping criteria; a value <= 0 disables the criterion.
  double target_f = -1e300;     // stop when best f <= target_f
  long long max_evaluations = 0;
  long long max_generations = 0;
  double tol_fun = 1e-12;
  double tol_x = 1e-12;
  double max_condition = 1e14;
};

class Cmaes {
 public:
  Cmaes(const CmaesOptions& options, const Eigen::VectorXd& x0);

  // Draws lambda new candidates (in bounds when bounded). Must be followed by tell().
  const std::vector<Eigen::VectorXd>& ask();
  // Fitness of each candidate of the last ask(), same order; lower is better.
  // Non-finite values are treated as worse than every finite value.
  void tell(const std::vector<double>& fitness);

  StopReason stop_reason() const { return stop_reason_; }

  int dim() const;
  int popsize() const;
  // Distribution mean, mapped into the box when bounded (the point to report).
  Eigen::VectorXd mean() const;
  const Eigen::VectorXd& mean_genotype() const { return mean_; }
  double sigma() const { return sigma_; }
  const Eigen::MatrixXd& covariance() const { return C_; }
  long long generation() const { return generation_; }
  long long evaluations() const { return evaluations_; }
  // Best candidate ever told and its fitness.
  const Eigen::VectorXd& best_x() const { return best_x_; }
  double best_f() const { return best_f_; }

  nlohmann::json to_json() const;
  static Cmaes from_json(const nlohmann::json& state);

 private:
  Cmaes() = default;
  void set_defaults();
  void update_eigensystem(bool force);
  Eigen::VectorXd to_box(const Eigen::VectorXd& genotype) const;

  CmaesOptions options_;
  // Strategy constants (tutorial appendix A).
  int n_ = 0, lambda_ = 0, mu_ = 0;
  Eigen::VectorXd weights_;  // all lambda weights; the first mu positive
  double mueff_ = 0, cc_ = 0, cs_ = 0, c1_ = 0, cmu_ = 0, damps_ = 0, chin_ = 0;
  // Dynamic state.
  Eigen::VectorXd mean_, ps_, pc_;
  double sigma_ = 0;
  Eigen::MatrixXd C_, B_, invsqrtC_;
  Eigen::VectorXd D_;  // square roots of eigenvalues of C
  long long eigen_generation_ = 0;
  long long generation_ = 0, evaluations_ = 0;
  Rng rng_;
  std::vector<Eigen::VectorXd> genotypes_, candidates_;
  std::vector<double> recent_best_;
  Eigen::VectorXd best_x_;
  double best_f_ = 0;
  StopReason stop_reason_ = StopReason::kNone;
};

}  // namespace diverse
