#include "optimize/objective.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <limits>
#include <stdexcept>
#include <string>

namespace diverse {

std::shared_ptr<const Outcome> DiversityProblem::confirm(const Eigen::VectorXd&, const Outcome&,
                                                         int) const {
  throw std::logic_error("DiversityProblem::confirm: this problem gave a provisional outcome "
                         "but does not confirm outcomes");
}

void DiversityProblem::tally(const Outcome&, nlohmann::json&) const {}

bool is_failure(const Outcome& outcome) {
  return outcome.failed || !std::isfinite(outcome.constraint);
}

double scored_constraint(const Outcome& outcome) {
  if (!std::isfinite(outcome.constraint)) return kFailedConstraint;
  if (outcome.constraint < 0.0) {
    throw std::logic_error("diversity: constraint value must be >= 0, got " +
                           std::to_string(outcome.constraint));
  }
  return outcome.constraint;
}

double scored_distance(const DiversityProblem& problem, const Outcome& a, const Outcome& b) {
  if (is_failure(a) || is_failure(b)) return 0.0;
  const double d = problem.distance(a, b);
  if (!std::isfinite(d) || d < 0.0) {
    throw std::logic_error("diversity: distance between two valid outcomes must be finite and "
                           ">= 0, got " + std::to_string(d));
  }
  return d;
}

double diversity_objective(const Eigen::MatrixXd& distance, const Eigen::VectorXd& constraint,
                           double k, Eigen::VectorXd* dmin) {
  const Eigen::Index count = constraint.size();  // N + 1
  if (count < 2 || distance.rows() != count || distance.cols() != count) {
    throw std::logic_error("diversity_objective: need N + 1 >= 2 motions and a matching "
                           "square distance matrix");
  }
  Eigen::VectorXd nearest(count);
  for (Eigen::Index i = 0; i < count; ++i) {
    double m = std::numeric_limits<double>::infinity();
    for (Eigen::Index j = 0; j < count; ++j) {
      if (j != i && distance(i, j) < m) m = distance(i, j);
    }
    nearest[i] = m;
  }
  // Eq. 1 term by term, K dmin(M_i) inside the sum over j (see header).
  double d_total = 0.0;
  for (Eigen::Index i = 0; i < count; ++i) {
    double term = -constraint[i];
    for (Eigen::Index j = 0; j < count; ++j) term += distance(i, j) + k * nearest[i];
    d_total += term;
  }
  if (dmin) *dmin = nearest;
  return d_total;
}

DiversityScore score_diversity(const DiversityProblem& problem,
                               const std::vector<std::shared_ptr<const Outcome>>& outcomes,
                               double k) {
  const Eigen::Index count = static_cast<Eigen::Index>(outcomes.size());
  DiversityScore score;
  score.distance = Eigen::MatrixXd::Zero(count, count);
  score.constraint.resize(count);
  for (Eigen::Index i = 0; i < count; ++i) {
    score.constraint[i] = scored_constraint(*outcomes[i]);
    for (Eigen::Index j = i + 1; j < count; ++j) {
      const double d = scored_distance(problem, *outcomes[i], *outcomes[j]);
      score.distance(i, j) = d;
      score.distance(j, i) = d;
    }
  }
  score.D = diversity_objective(score.distance, score.constraint, k, &score.dmin);
  return score;
}

}  // namespace diverse
