// The Python module `diverse` over the core library (docs/guide/python.md).
//
//   module.cc          the module, its exceptions (UserError carries the CLI's one-line
//                      message), tasks: load_task, names and ranges, the input motion
//   motion.cc          simulate one parameter vector or a batch on several threads with
//                      the GIL released; Motion and Outcome as numpy arrays; distances
//   python_problem.cc  a distance and a constraint term written in Python, as the problem
//                      a run optimizes (RunHooks::wrap_problem, run/run.h)
//   run_binding.cc     run, resume (the CLI's run directory, progress callback, stop) and
//                      load_run
//
// Everything here is a thin layer: what a motion, a distance or a run is comes from the
// library (task/evaluate.h, eval/motion_problem.h, run/run.h), so a Python run and the CLI
// give the same result for the same task and seed.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <string>
#include <vector>

#include "eval/motion_problem.h"
#include "params/parameters.h"
#include "physics/rollout.h"
#include "task/evaluate.h"

namespace diverse::python {
namespace py = pybind11;

// What an outcome's arrays are named by: the links and the angles of the pose samples.
struct Names {
  std::vector<std::string> links, angles;
};

// A loaded task: shared, read-only, by every motion simulated from it.
struct TaskData {
  std::string path;                                // the task file, resolved
  std::unique_ptr<const TaskEvaluator> evaluator;
  std::unique_ptr<const MotionProblem> problem;    // the distances (one worker, never simulated on)
  ParameterSet m0;                                 // the input motion, or all lower bounds without one
  bool has_m0 = false;
  std::shared_ptr<const Names> names;
};

// The Python objects: a Task and a Motion hold their shared data.
struct PyTask {
  std::shared_ptr<const TaskData> data;
};

// Loads a task by name (tasks/<name>.toml) or file at a strength. UserError as the CLI.
std::shared_ptr<const TaskData> load_task_data(const std::string& name_or_path, double strength);

// What a Python distance or constraint term sees of one sampled motion.
struct OutcomeView {
  std::shared_ptr<const MotionOutcome> outcome;
  std::shared_ptr<const Names> names;
};

// One simulated motion.
struct MotionData {
  std::shared_ptr<const TaskData> task;
  std::vector<double> params;    // the controller's parameters (task units)
  Evaluation evaluation;
  std::vector<double> qpos;      // (steps + 1) x nq, row-major: qpos0, then after every step
  std::vector<double> ctrl;      // steps x nu
  int nq = 0, nu = 0;
  double timestep = 0;           // s
  std::shared_ptr<const MotionOutcome> outcome;  // pose samples as the metrics compare them
};

// Simulates `values` (checked against the task's names and ranges: UserError naming
// `where`) on `worker`; thread-safe.
MotionData simulate(const std::shared_ptr<const TaskData>& task, const std::vector<double>& values,
                    SimWorker& worker, bool half_timestep);
// The controller's values of a Python vector, checked: "WHERE: expected N values ...".
std::vector<double> parameter_values(const TaskData& task, const py::handle& values, const std::string& where);

// A MotionOutcome as the optimizer builds it, from an evaluation of `task`.
std::shared_ptr<MotionOutcome> outcome_of(const TaskData& task, const Evaluation& e);

// A new float64 array holding a copy of `data`.
py::array_t<double> copy_array(const std::vector<double>& data, std::vector<py::ssize_t> shape);
// Python's value of a JSON value (through the json module).
py::object from_json(const nlohmann::json& j);

// The problem of a run whose distance (`metric`: f(a, b) -> float >= 0) or constraint
// term (`term`: g(outcome) -> float >= 0, added to C) is a Python callable (None: the
// task's own). Calls take the GIL; a Python exception ends the run with it.
std::unique_ptr<DiversityProblem> python_problem(const MotionProblem& task_problem, py::object metric,
                                                 py::object term);

void bind_motion(py::module_& m);
void bind_run(py::module_& m);

}  // namespace diverse::python
