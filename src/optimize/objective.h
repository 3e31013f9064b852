// The diversity objective (paper eq. 1) and the problem interface it is evaluated on.
//
// Agrawal, Shen, van de Panne, "Diverse Motions and Character Shapes for Simulated
// Skills", IEEE TVCG 2014, section 3, equation 1:
//
//   D = sum_{i=0..N} [ -C(M_i) + sum_{j=0..N} ( d(M_i, M_j) + K dmin(M_i) ) ]
//
// M_0 is the input (reference) motion, held fixed, and counts like any variation: its
// constraint value, its distances and its dmin are all part of D. dmin(M_i) is the
// smallest d(M_i, M_j) over j != i.
//
// Implemented literally as printed: the K dmin(M_i) term sits inside the sum over j,
// which runs over all N + 1 motions including j = i, so each dmin(M_i) is weighted by
// (N + 1) K rather than K. The d(M_i, M_i) = 0 terms add nothing, and every unordered
// pair is counted twice. K = 10 is the paper's value under this reading.
//
// Failures. A DiversityProblem reports a simulation that blew up, or anything else
// that has no meaningful result, as an Outcome with failed = true and a large
// constraint value. In D a failed outcome contributes its constraint value (or
// kFailedConstraint when that value is not finite) and every distance involving it
// counts as 0, so a failure always scores badly and D is always finite.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <vector>

namespace diverse {

// The result of evaluating one parameter vector: what the problem needs in order to
// measure constraint violation and distances. Problems derive from it (a toy point, a
// simulated motion with its pose samples, ...).
struct Outcome {
  virtual ~Outcome() = default;
  double constraint = 0.0;  // C(M) >= 0, 0 exactly when the task is met
  bool failed = false;      // no meaningful result (e.g. the simulation blew up)
  // Meets the constraints as far as evaluate() tells, but its final C needs a dearer
  // check (DiversityProblem::confirm); until confirmed it ranks as meeting them.
  bool provisional = false;
};

// Constraint value used for a failed outcome whose own value is not finite.
inline constexpr double kFailedConstraint = 1e12;

// A space of candidates to diversify over. Parameters are normalized: every coordinate
// of x lies in [0, 1] (the problem maps them to its own ranges).
class DiversityProblem {
 public:
  virtual ~DiversityProblem() = default;

  // |P|, the number of normalized parameters of one variation.
  virtual int dim() const = 0;
  // P0, the reference (input motion's) parameters, normalized; dim() entries in [0, 1].
  virtual Eigen::VectorXd reference() const = 0;
  // Evaluates one candidate. Must be thread-safe and a pure function of x (the same x
  // gives the same outcome, bit for bit, on any worker); `worker` in [0, threads)
  // selects per-thread scratch, and no two concurrent calls share a worker index.
  virtual std::shared_ptr<const Outcome> evaluate(const Eigen::VectorXd& x, int worker) const = 0;
  // d(a, b) >= 0, symmetric. Never called with a failed outcome. Thread-safe.
  virtual double distance(const Outcome& a, const Outcome& b) const = 0;

  // Checks that are dear and decide little are done only where they decide something.
  // evaluate() may return a provisional outcome (Outcome::provisional): one that meets
  // the constraints as far as its own evaluation tells, whose final C needs a further
  // check (for a motion: the same motion simulated at half the timestep). confirm(x,
  // outcome, worker) runs that check on the provisional outcome evaluate(x) returned and
  // gives the final outcome (not provisional), equal to what evaluate() would give if it
  // ran the check at once. The optimizer confirms an outcome before a variation may stand
  // at it, so every set it scores, keeps or returns holds only confirmed outcomes.
  // Thread-safe like evaluate(). The default is for problems that are never provisional.
  virtual std::shared_ptr<const Outcome> confirm(const Eigen::VectorXd& x, const Outcome& outcome,
                                                 int worker) const;

  // What evaluations cost, for the run's accounting (e.g. simulation steps by kind and
  // by outcome): adds one outcome's cost to `ledger`, a JSON object the problem defines
  // (null at the start). The optimizer calls it on its own thread, in a fixed order, for
  // every outcome it asked for (samples, means, confirmations; not the re-evaluations of
  // a restored checkpoint) and keeps the ledger in its checkpoints; an integer "total"
  // entry, when the problem keeps one, is logged with every step. Default: nothing.
  virtual void tally(const Outcome& outcome, nlohmann::json& ledger) const;
};

// D and its parts for one set of motions M_0..M_N.
struct DiversityScore {
  double D = 0.0;
  Eigen::MatrixXd distance;    // (N+1) x (N+1), d(M_i, M_j), zero diagonal, symmetric
  Eigen::VectorXd constraint;  // N+1, C(M_i) as scored (failures substituted)
  Eigen::VectorXd dmin;        // N+1, min over j != i of distance(i, j)
};

// True when an outcome counts as a failure in D (flagged, or a non-finite constraint).
bool is_failure(const Outcome& outcome);
// C(M) as scored in D: the constraint value, or kFailedConstraint for a failure whose
// value is not finite. Throws std::logic_error on a negative constraint.
double scored_constraint(const Outcome& outcome);
// d(a, b) as scored in D: 0 if either outcome failed, else problem.distance(a, b).
// Throws std::logic_error if the problem returns a negative or non-finite distance.
double scored_distance(const DiversityProblem& problem, const Outcome& a, const Outcome& b);

// Eq. 1 from a distance matrix and constraint values (both over M_0..M_N, N >= 1).
// Also returns each motion's dmin in `dmin` when it is not null.
double diversity_objective(const Eigen::MatrixXd& distance, const Eigen::VectorXd& constraint,
                           double k, Eigen::VectorXd* dmin = nullptr);

// Scores a full set of outcomes (index 0 = M_0). Computes every pairwise distance once,
// as problem.distance(outcome[i], outcome[j]) with i < j.
DiversityScore score_diversity(const DiversityProblem& problem,
                               const std::vector<std::shared_ptr<const Outcome>>& outcomes,
                               double k);

}  // namespace diverse
