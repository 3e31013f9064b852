// A run's problem with a distance or a constraint term written in Python (binding.h).
//
// Every call into Python takes the GIL, so the rollouts still run on every thread but the
// Python code runs on one at a time; a run with a Python distance is slower than with the
// built-in ones by the time the Python code takes (docs/guide/python.md has the figures).
#include <cmath>
#include <sstream>

#include "binding.h"
#include "core/error.h"

namespace diverse::python {
namespace {

std::string name_of(const py::object& f) {
  return py::str(py::getattr(f, "__name__", py::str(py::repr(f))));
}

double checked(const py::object& value, const std::string& what, const py::object& f) {
  double v = NAN;
  try {
    v = value.cast<double>();
  } catch (const py::cast_error&) {
  }
  if (!(std::isfinite(v) && v >= 0.0)) {
    std::ostringstream out;
    out << what << ": expected a finite number >= 0 from " << name_of(f) << ", got "
        << py::str(py::repr(value)).cast<std::string>();
    throw UserError(out.str());
  }
  return v;
}

class PythonProblem : public DiversityProblem {
 public:
  PythonProblem(const MotionProblem& inner, py::object metric, py::object term)
      : inner_(inner),
        metric_(std::move(metric)),
        term_(std::move(term)),
        names_(std::make_shared<const Names>(
            Names{inner.evaluator().link_names(), inner.evaluator().angle_names()})) {}

  ~PythonProblem() override {
    py::gil_scoped_acquire gil;
    metric_ = py::object();
    term_ = py::object();
  }

  int dim() const override { return inner_.dim(); }
  Eigen::VectorXd reference() const override { return inner_.reference(); }

  std::shared_ptr<const Outcome> evaluate(const Eigen::VectorXd& x, int worker) const override {
    return with_term(inner_.evaluate(x, worker));
  }

  // A provisional outcome kept its Python term at 0 (with_term), so the task problem's
  // check adds only the half-timestep term to it.
  std::shared_ptr<const Outcome> confirm(const Eigen::VectorXd& x, const Outcome& outcome,
                                         int worker) const override {
    return inner_.confirm(x, outcome, worker);
  }

  void tally(const Outcome& outcome, nlohmann::json& ledger) const override { inner_.tally(outcome, ledger); }

  double distance(const Outcome& a, const Outcome& b) const override {
    if (metric_.is_none()) return inner_.distance(a, b);
    py::gil_scoped_acquire gil;
    const py::object d = metric_(view(a), view(b));
    return checked(d, "metric", metric_);
  }

 private:
  OutcomeView view(const Outcome& o) const {
    // The outcome outlives this call only if Python keeps it: a copy then owns it.
    return OutcomeView{std::make_shared<const MotionOutcome>(static_cast<const MotionOutcome&>(o)), names_};
  }

  std::shared_ptr<const Outcome> with_term(std::shared_ptr<const Outcome> o) const {
    if (term_.is_none() || is_failure(*o)) return o;
    double term = 0;
    {
      py::gil_scoped_acquire gil;
      term = checked(term_(view(*o)), "constraint", term_);
    }
    if (term == 0.0) return o;
    auto changed = std::make_shared<MotionOutcome>(static_cast<const MotionOutcome&>(*o));
    changed->constraint += term;
    changed->task_constraint += term;
    // It misses the task already: the dearer check would decide nothing.
    changed->provisional = false;
    return changed;
  }

  const MotionProblem& inner_;
  py::object metric_, term_;
  std::shared_ptr<const Names> names_;
};

}  // namespace

std::unique_ptr<DiversityProblem> python_problem(const MotionProblem& task_problem, py::object metric,
                                                 py::object term) {
  return std::make_unique<PythonProblem>(task_problem, std::move(metric), std::move(term));
}

}  // namespace diverse::python
