// Runs from Python (run/run.h with RunHooks) and finished runs read back (finished/run_view.h).
#include <pybind11/stl.h>

#include "binding.h"
#include "core/error.h"
#include "finished/run_view.h"
#include "io/files.h"
#include "run/run.h"

namespace diverse::python {
namespace {

// The hooks of a run from Python: the progress callback (stops the run when it returns
// False), Ctrl-C (a KeyboardInterrupt between generations, the checkpoint intact) and the
// Python distance and constraint term. `hooks` owns copies of the callables.
RunHooks python_hooks(const py::object& on_generation, const py::object& metric, const py::object& term) {
  RunHooks hooks;
  hooks.on_generation = [on_generation](const DiversityOptimizer& optimizer) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (on_generation.is_none() || optimizer.log().empty()) return true;
    const DiversityRecord& r = optimizer.log().back();
    py::dict record;
    record["generation"] = r.generation;
    record["D"] = r.D;
    record["best_D"] = r.best_D;
    record["constraint"] = copy_array(std::vector<double>(r.constraint.data(), r.constraint.data() + r.constraint.size()),
                                      {r.constraint.size()});
    record["dmin"] = copy_array(std::vector<double>(r.dmin.data(), r.dmin.data() + r.dmin.size()), {r.dmin.size()});
    record["evaluations"] = r.evaluations;
    record["simulation_steps"] = r.simulation_steps;
    const py::object answer = on_generation(record);
    return !(py::isinstance<py::bool_>(answer) && !answer.cast<bool>());
  };
  if (!metric.is_none() || !term.is_none()) {
    hooks.wrap_problem = [metric, term](const MotionProblem& problem) {
      py::gil_scoped_acquire gil;
      return python_problem(problem, metric, term);
    };
    hooks.custom = nlohmann::json::object();
    auto name = [](const py::object& f) {
      return py::str(py::getattr(f, "__name__", py::str(py::repr(f)))).cast<std::string>();
    };
    if (!metric.is_none()) hooks.custom["metric"] = "python: " + name(metric);
    if (!term.is_none()) hooks.custom["constraint"] = "python: " + name(term);
  }
  return hooks;
}

void check_callable(const py::object& f, const char* what) {
  if (!f.is_none() && !PyCallable_Check(f.ptr()))
    throw UserError(std::string(what) + ": expected a function or None");
}

// True when the run finished (summary.json written), false when the callback stopped it.
bool finished(const std::filesystem::path& dir) { return std::filesystem::exists(dir / "summary.json"); }

py::dict motion_dict(const RunMotion& m, const nlohmann::json& file) {
  py::dict d;
  d["index"] = m.index;
  d["label"] = m.label;
  d["file"] = m.file.string();
  d["model"] = m.model_path.string();
  d["constraint"] = m.constraint;
  d["dmin"] = m.dmin;
  d["fell"] = m.fell;
  d["failed"] = m.failed;
  const StepRecorder& r = m.record;
  std::vector<double> qpos = r.qpos0;
  qpos.insert(qpos.end(), r.qpos.begin(), r.qpos.end());
  const auto rows = static_cast<py::ssize_t>(r.nq ? qpos.size() / static_cast<std::size_t>(r.nq) : 0);
  d["qpos"] = copy_array(qpos, {rows, r.nq});
  std::vector<double> t(static_cast<std::size_t>(rows));
  for (std::size_t k = 0; k < t.size(); ++k) t[k] = static_cast<double>(k) * r.timestep;
  d["times"] = copy_array(t, {rows});
  d["timestep"] = r.timestep;
  py::dict phases;
  for (std::size_t k = 0; k < m.phases.names.size(); ++k) phases[py::str(m.phases.names[k])] = m.phases.begin[k];
  d["phases"] = phases;
  d["parameters"] = from_json(file.value("parameters", nlohmann::json::object()));
  const nlohmann::json constraint = file.value("constraint", nlohmann::json::object());
  d["terms"] = from_json(constraint.value("terms", nlohmann::json::array()));
  d["pose_samples"] = from_json(file.value("pose_samples", nlohmann::json()));
  return d;
}

}  // namespace

void bind_run(py::module_& m) {
  m.def(
      "_run",
      [](const py::object& task, const std::string& out, long long generations, std::uint64_t seed,
         const std::string& strategy, int variations, int popsize, double sigma0, double k, const std::string& metric,
         int threads, bool force, bool render, bool quiet, double checkpoint_seconds, double strength,
         const py::object& on_generation, const py::object& py_metric, const py::object& py_constraint) {
        check_callable(on_generation, "on_generation");
        check_callable(py_metric, "metric");
        check_callable(py_constraint, "constraint");
        RunRequest request;
        if (py::isinstance<PyTask>(task)) {
          const TaskData& t = *task.cast<const PyTask&>().data;
          request.task = t.path;
          request.strength = t.evaluator->task().strength;
        } else {
          request.task = py::str(task).cast<std::string>();
          request.strength = strength;
        }
        if (out.empty()) throw UserError("out: expected the run directory");
        request.out = out;
        request.metric = metric;
        request.options.variations = variations;
        request.options.max_generations = generations;
        request.options.strategy = parse_strategy(strategy, "strategy");
        request.options.seed = seed;
        request.options.popsize = popsize;
        request.options.sigma0 = sigma0;
        request.options.k = k;
        request.options.window = 100;  // the CLI's --window
        request.threads = threads;
        request.force = force;
        request.render = render;
        request.quiet = quiet;
        request.checkpoint_seconds = checkpoint_seconds;
        request.hooks = python_hooks(on_generation, py_metric, py_constraint);
        {
          py::gil_scoped_release release;
          start_run(request);
        }
        return finished(request.out);  // (the hooks' callables are released with the GIL held)
      },
      py::arg("task"), py::arg("out"), py::arg("generations"), py::arg("seed"), py::arg("strategy"),
      py::arg("variations"), py::arg("popsize"), py::arg("sigma0"), py::arg("k"), py::arg("metric"),
      py::arg("threads"), py::arg("force"), py::arg("render"), py::arg("quiet"), py::arg("checkpoint_seconds"),
      py::arg("strength"), py::arg("on_generation"), py::arg("py_metric"), py::arg("py_constraint"));

  m.def(
      "_resume",
      [](const std::string& dir, int threads, bool render, bool quiet, double checkpoint_seconds,
         const py::object& on_generation, const py::object& py_metric, const py::object& py_constraint) {
        check_callable(on_generation, "on_generation");
        const RunHooks hooks = python_hooks(on_generation, py_metric, py_constraint);
        {
          py::gil_scoped_release release;
          resume_run(dir, threads, quiet, checkpoint_seconds, render, nullptr, hooks);
        }
        return finished(dir);
      },
      py::arg("dir"), py::arg("threads"), py::arg("render"), py::arg("quiet"), py::arg("checkpoint_seconds"),
      py::arg("on_generation"), py::arg("py_metric"), py::arg("py_constraint"));

  m.def(
      "_load_run",
      [](const std::string& dir) {
        RunView view;
        std::vector<nlohmann::json> files;
        {
          py::gil_scoped_release release;
          view = load_run_view(dir);
          for (const RunMotion& motion : view.motions) files.push_back(read_json(motion.file));
        }
        py::dict d;
        d["dir"] = view.dir.string();
        d["run"] = from_json(view.run);
        d["summary"] = from_json(view.summary);
        py::list motions;
        for (std::size_t i = 0; i < view.motions.size(); ++i) motions.append(motion_dict(view.motions[i], files[i]));
        d["motions"] = motions;
        return d;
      },
      py::arg("dir"));
}

}  // namespace diverse::python
