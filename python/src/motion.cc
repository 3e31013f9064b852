// Simulating a task's parameters from Python, one vector or a batch on several threads,
// and the distances between the motions.
#include <pybind11/stl.h>

#include <cmath>

#include "binding.h"
#include "core/error.h"
#include "core/thread_pool.h"
#include "metric/metric.h"

namespace diverse::python {

std::shared_ptr<MotionOutcome> outcome_of(const TaskData& task, const Evaluation& e) {
  // As MotionProblem builds the optimizer's outcomes (eval/motion_problem.cc), so that a
  // distance between simulated motions is the distance a run computes.
  auto o = std::make_shared<MotionOutcome>();
  const TaskEvaluator& ev = *task.evaluator;
  o->constraint = e.constraint;
  o->task_constraint = e.constraint;
  o->failed = e.failed || !std::isfinite(e.constraint);
  o->fell = e.fell;
  o->effort = e.stats.effort;
  o->positive_work = e.stats.positive_work;
  o->landing_x = e.summary.feet_x;
  o->peak_com_z = e.summary.peak_com_z;
  o->steps = e.stats.steps;
  if (ev.has_shape()) {
    o->scales = ev.shapes().identity();
    o->features.link_lengths = ev.shapes().base_link_lengths();
  }
  if (!o->failed) {
    const Eigen::VectorXd mass = ev.link_masses();
    for (const PoseSample& s : e.poses) o->features.poses.push_back(make_pose(s.link_com, mass, s.angles, s.root));
  }
  return o;
}

MotionData simulate(const std::shared_ptr<const TaskData>& task, const std::vector<double>& values,
                    SimWorker& worker, bool half_timestep) {
  MotionData d;
  d.task = task;
  d.params = values;
  StepRecorder record;
  EvaluationOptions options;
  options.recorder = &record;
  options.half_timestep_check = half_timestep;
  d.evaluation = task->evaluator->evaluate(values, worker, options);
  d.nq = record.nq;
  d.nu = record.nu;
  d.timestep = record.timestep;
  d.qpos = std::move(record.qpos0);
  d.qpos.insert(d.qpos.end(), record.qpos.begin(), record.qpos.end());
  d.ctrl = std::move(record.ctrl);
  d.outcome = outcome_of(*task, d.evaluation);
  return d;
}

namespace {

struct PyMotion {
  std::shared_ptr<const MotionData> data;
};

const MotionData& motion_of(const py::object& self) { return *self.cast<const PyMotion&>().data; }

// A read-only array over memory `owner` keeps alive (no copy).
py::array_t<double> view(const double* data, std::vector<py::ssize_t> shape, const py::object& owner) {
  std::vector<py::ssize_t> strides(shape.size(), sizeof(double));
  for (std::size_t k = shape.size(); k-- > 1;) strides[k - 1] = strides[k] * shape[k];
  py::array_t<double> a(shape, strides, data, owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

py::list terms_list(const ConstraintReport& report) {
  py::list terms;
  for (const ConstraintTerm& t : report.terms) {
    py::dict d;
    d["name"] = t.name;
    d["violation"] = t.violation;
    d["penalty"] = t.penalty;
    terms.append(d);
  }
  return terms;
}

// The pose samples of an outcome as arrays: (samples, links, 3), (samples, angles), (samples, 4).
py::array_t<double> link_com(const MotionOutcome& o) {
  const auto& poses = o.features.poses;
  const py::ssize_t links = poses.empty() ? 0 : poses[0].link_com.cols();
  py::array_t<double> a({static_cast<py::ssize_t>(poses.size()), links, py::ssize_t{3}});
  auto r = a.mutable_unchecked<3>();
  for (std::size_t s = 0; s < poses.size(); ++s)
    for (py::ssize_t l = 0; l < links; ++l)
      for (int k = 0; k < 3; ++k) r(static_cast<py::ssize_t>(s), l, k) = poses[s].link_com(k, l);
  return a;
}
py::array_t<double> angles(const MotionOutcome& o) {
  const auto& poses = o.features.poses;
  const py::ssize_t n = poses.empty() ? 0 : poses[0].angles.size();
  py::array_t<double> a({static_cast<py::ssize_t>(poses.size()), n});
  auto r = a.mutable_unchecked<2>();
  for (std::size_t s = 0; s < poses.size(); ++s)
    for (py::ssize_t k = 0; k < n; ++k) r(static_cast<py::ssize_t>(s), k) = poses[s].angles[k];
  return a;
}
py::array_t<double> roots(const MotionOutcome& o) {
  const auto& poses = o.features.poses;
  py::array_t<double> a({static_cast<py::ssize_t>(poses.size()), py::ssize_t{4}});
  auto r = a.mutable_unchecked<2>();
  for (std::size_t s = 0; s < poses.size(); ++s) {
    const auto i = static_cast<py::ssize_t>(s);
    r(i, 0) = poses[s].root.w();
    r(i, 1) = poses[s].root.x();
    r(i, 2) = poses[s].root.y();
    r(i, 3) = poses[s].root.z();
  }
  return a;
}
py::array_t<double> vector(const Eigen::VectorXd& v) {
  return copy_array(std::vector<double>(v.data(), v.data() + v.size()), {v.size()});
}

// The outcome and the task (for the metric layout) of a Motion or an Outcome.
struct Compared {
  std::shared_ptr<const MotionOutcome> outcome;
  const TaskData* task = nullptr;
};
Compared compared(const py::handle& h, const char* which) {
  if (py::isinstance<PyMotion>(h)) {
    const auto& d = *h.cast<const PyMotion&>().data;
    return {d.outcome, d.task.get()};
  }
  throw UserError(std::string(which) + ": expected a Motion (Task.simulate), got " +
                  py::str(py::type::of(h).attr("__name__")).cast<std::string>());
}

double distance_between(const Compared& a, const Compared& b, const DistanceSpec& spec) {
  if (a.task != b.task)
    throw UserError("distance: the motions are of different tasks (" + a.task->evaluator->task().name + ", " +
                    b.task->evaluator->task().name + "); simulate both with one Task");
  // As the objective scores them (optimize/objective.h): a failed motion is at distance 0.
  if (is_failure(*a.outcome) || is_failure(*b.outcome)) return 0.0;
  return a.task->problem->distance(*a.outcome, *b.outcome, spec);
}

DistanceSpec metric_spec(const std::string& name, double shape_weight) {
  return parse_distance(name, shape_weight, "metric", "shape_weight");
}

}  // namespace

void bind_motion(py::module_& m) {
  py::class_<OutcomeView>(m, "Outcome",
                          "One sampled motion as the optimizer sees it: what a Python distance or "
                          "constraint term is given")
      .def_property_readonly("constraint", [](const OutcomeView& v) { return v.outcome->constraint; },
                             "C so far (0 = meets the task)")
      .def_property_readonly("task_constraint", [](const OutcomeView& v) { return v.outcome->task_constraint; })
      .def_property_readonly("failed", [](const OutcomeView& v) { return v.outcome->failed; })
      .def_property_readonly("fell", [](const OutcomeView& v) { return v.outcome->fell; })
      .def_property_readonly("landing_x", [](const OutcomeView& v) { return v.outcome->landing_x; },
                             "m, the feet's mean x at rest (or at the end)")
      .def_property_readonly("peak_com_z", [](const OutcomeView& v) { return v.outcome->peak_com_z; }, "m")
      .def_property_readonly("effort", [](const OutcomeView& v) { return v.outcome->effort; }, "N^2 m^2 s")
      .def_property_readonly("positive_work", [](const OutcomeView& v) { return v.outcome->positive_work; }, "J")
      .def_property_readonly("link_com", [](const OutcomeView& v) { return link_com(*v.outcome); },
                             "(samples, links, 3): each link's centre of mass relative to the body's (m)")
      .def_property_readonly("angles", [](const OutcomeView& v) { return angles(*v.outcome); },
                             "(samples, angles): the joint angles (rad)")
      .def_property_readonly("root", [](const OutcomeView& v) { return roots(*v.outcome); },
                             "(samples, 4): the root's orientation, w x y z")
      .def_property_readonly("link_mass",
                             [](const OutcomeView& v) {
                               const auto& poses = v.outcome->features.poses;
                               return vector(poses.empty() ? Eigen::VectorXd() : poses[0].link_mass);
                             },
                             "kg, one per link (empty without pose samples)")
      .def_property_readonly("link_lengths",
                             [](const OutcomeView& v) { return vector(v.outcome->features.link_lengths); })
      .def_property_readonly("link_names", [](const OutcomeView& v) { return v.names->links; })
      .def_property_readonly("angle_names", [](const OutcomeView& v) { return v.names->angles; });

  py::class_<PyMotion>(m, "Motion", "One simulated motion of a task (Task.simulate)")
      .def_property_readonly("params", [](const py::object& self) {
        const MotionData& d = motion_of(self);
        return view(d.params.data(), {static_cast<py::ssize_t>(d.params.size())}, self);
      })
      .def_property_readonly("constraint", [](const PyMotion& p) { return p.data->evaluation.constraint; },
                             "C >= 0; 0 when the motion meets the task")
      .def_property_readonly("met", [](const PyMotion& p) {
        return !p.data->evaluation.failed && p.data->evaluation.constraint == 0.0;
      })
      .def_property_readonly("terms", [](const PyMotion& p) { return terms_list(p.data->evaluation.report); },
                             "The constraint's terms: [{name, violation, penalty}]")
      .def_property_readonly(
          "half_timestep",
          [](const PyMotion& p) -> py::object {
            for (const ConstraintTerm& t : p.data->evaluation.report.terms)
              if (t.name == "half_timestep") return py::bool_(t.penalty == 0);
            return py::none();
          },
          "Whether the motion holds at half the timestep (None: not checked)")
      .def_property_readonly("fell", [](const PyMotion& p) { return p.data->evaluation.fell; })
      .def_property_readonly("failed", [](const PyMotion& p) { return p.data->evaluation.failed; })
      .def_property_readonly("failure", [](const PyMotion& p) { return p.data->evaluation.failure; })
      .def_property_readonly("effort", [](const PyMotion& p) { return p.data->evaluation.stats.effort; })
      .def_property_readonly("positive_work",
                             [](const PyMotion& p) { return p.data->evaluation.stats.positive_work; })
      .def_property_readonly("peak_com_z", [](const PyMotion& p) { return p.data->evaluation.summary.peak_com_z; })
      .def_property_readonly("landing_x", [](const PyMotion& p) { return p.data->evaluation.summary.feet_x; })
      .def_property_readonly("steps", [](const PyMotion& p) { return p.data->evaluation.stats.steps; })
      .def_property_readonly("timestep", [](const PyMotion& p) { return p.data->timestep; })
      .def_property_readonly("qpos",
                             [](const py::object& self) {
                               const MotionData& d = motion_of(self);
                               const auto rows = static_cast<py::ssize_t>(d.nq ? d.qpos.size() / d.nq : 0);
                               return view(d.qpos.data(), {rows, d.nq}, self);
                             },
                             "(steps + 1, nq): the state at the start and after every step (read-only view)")
      .def_property_readonly("ctrl",
                             [](const py::object& self) {
                               const MotionData& d = motion_of(self);
                               const auto rows = static_cast<py::ssize_t>(d.nu ? d.ctrl.size() / d.nu : 0);
                               return view(d.ctrl.data(), {rows, d.nu}, self);
                             })
      .def_property_readonly("times",
                             [](const PyMotion& p) {
                               const MotionData& d = *p.data;
                               const std::size_t rows = d.nq ? d.qpos.size() / d.nq : 0;
                               std::vector<double> t(rows);
                               for (std::size_t k = 0; k < rows; ++k) t[k] = static_cast<double>(k) * d.timestep;
                               return copy_array(t, {static_cast<py::ssize_t>(rows)});
                             },
                             "s, one per row of qpos")
      .def_property_readonly("phases",
                             [](const PyMotion& p) {
                               py::dict phases;
                               const PhaseTimes& ph = p.data->evaluation.phases;
                               for (std::size_t k = 0; k < ph.names.size(); ++k) phases[py::str(ph.names[k])] = ph.begin[k];
                               return phases;
                             },
                             "Phase name to its begin time (s), -1 if never reached")
      .def_property_readonly("outcome",
                             [](const PyMotion& p) { return OutcomeView{p.data->outcome, p.data->task->names}; })
      .def("__repr__", [](const PyMotion& p) {
        const Evaluation& e = p.data->evaluation;
        return "<diverse.Motion of " + p.data->task->evaluator->task().name + ": C = " + std::to_string(e.constraint) +
               (e.fell ? ", fell" : "") + ", " + std::to_string(e.stats.steps) + " steps>";
      });

  auto task = py::reinterpret_borrow<py::class_<PyTask>>(m.attr("Task"));
  task.def(
      "simulate",
      [](const PyTask& t, const py::object& params, bool half_timestep) {
        const std::vector<double> values =
            params.is_none() ? t.data->m0.values() : parameter_values(*t.data, params, "params");
        std::shared_ptr<MotionData> d;
        {
          py::gil_scoped_release release;
          const auto worker = t.data->evaluator->make_worker();
          d = std::make_shared<MotionData>(simulate(t.data, values, *worker, half_timestep));
        }
        return PyMotion{d};
      },
      py::arg("params") = py::none(), py::arg("half_timestep") = true,
      "Simulates the controller's parameters (task units; None: the input motion M0)");
  task.def(
      "simulate_batch",
      [](const PyTask& t, const py::object& params, int threads, bool half_timestep) {
        const auto rows = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(params);
        if (!rows || rows.ndim() != 2)
          throw UserError("params: expected a 2-D array, one row of " + std::to_string(t.data->m0.size()) +
                          " parameters per motion");
        std::vector<std::vector<double>> values;
        for (py::ssize_t i = 0; i < rows.shape(0); ++i)
          values.push_back(parameter_values(*t.data, rows[py::int_(i)], "params[" + std::to_string(i) + "]"));
        if (threads < 0) throw UserError("threads: expected an integer >= 0 (0 = one per core)");
        std::vector<std::shared_ptr<MotionData>> out(values.size());
        {
          py::gil_scoped_release release;
          ThreadPool pool(threads > 0 ? threads : ThreadPool::hardware_threads());
          std::vector<std::unique_ptr<SimWorker>> workers;
          for (int w = 0; w < pool.size(); ++w) workers.push_back(t.data->evaluator->make_worker());
          pool.parallel_for(values.size(), [&](std::size_t k, int w) {
            out[k] = std::make_shared<MotionData>(simulate(t.data, values[k], *workers[static_cast<std::size_t>(w)],
                                                           half_timestep));
          });
        }
        std::vector<PyMotion> motions;
        for (auto& d : out) motions.push_back(PyMotion{std::move(d)});
        return motions;
      },
      py::arg("params"), py::arg("threads") = 0, py::arg("half_timestep") = true,
      "Simulates every row of a 2-D array on `threads` threads (0 = one per core), the GIL released");

  m.def(
      "distance",
      [](const py::object& a, const py::object& b, const std::string& metric, double shape_weight) {
        const Compared ca = compared(a, "a"), cb = compared(b, "b");
        const DistanceSpec spec = metric_spec(metric, shape_weight);
        return distance_between(ca, cb, spec);
      },
      py::arg("a"), py::arg("b"), py::arg("metric") = "md", py::arg("shape_weight") = kDefaultShapeWeight,
      "The distance between two motions of one task: hf, md, wja, shape, or md+shape, ...");
  m.def(
      "distances",
      [](const py::sequence& motions, const std::string& metric, double shape_weight) {
        std::vector<Compared> c;
        for (std::size_t i = 0; i < motions.size(); ++i)
          c.push_back(compared(motions[i], ("motions[" + std::to_string(i) + "]").c_str()));
        const DistanceSpec spec = metric_spec(metric, shape_weight);
        const auto n = static_cast<py::ssize_t>(c.size());
        std::vector<double> d(c.size() * c.size(), 0.0);
        for (std::size_t i = 0; i < c.size(); ++i)
          for (std::size_t j = i + 1; j < c.size(); ++j)
            d[i * c.size() + j] = d[j * c.size() + i] = distance_between(c[i], c[j], spec);
        return copy_array(d, {n, n});
      },
      py::arg("motions"), py::arg("metric") = "md", py::arg("shape_weight") = kDefaultShapeWeight,
      "The pairwise distance matrix of motions of one task");
}

}  // namespace diverse::python
