// How a batch of candidates is evaluated.
//
// DiversityOptimizer asks for its samples' outcomes one batch at a time (a CMA
// generation's lambda samples, plus a pending mean; the joint strategy's lambda x N
// motions; the sets a restored optimizer re-evaluates). By default a batch runs on the
// thread pool; a BatchEvaluator given to the optimizer replaces that, e.g. to spread the
// batch over several processes (distribute/cluster.h).
//
// Contract: evaluate(xs)[k] is problem.evaluate(xs[k]) for every k, bit for bit, in index
// order, whichever process or thread computed it; an evaluator that cannot deliver every
// outcome throws (UserError for causes a user can act on).
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <vector>

#include "optimize/objective.h"

namespace diverse {

class BatchEvaluator {
 public:
  virtual ~BatchEvaluator() = default;
  virtual std::vector<std::shared_ptr<const Outcome>> evaluate(
      const std::vector<Eigen::VectorXd>& xs) = 0;
};

}  // namespace diverse
