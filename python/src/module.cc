// The module `_diverse` (wrapped by the package python/diverse/): its exceptions and tasks.
#include <pybind11/stl.h>

#include <filesystem>
#include <sstream>

#include "binding.h"
#include "core/error.h"
#include "physics/model.h"
#include "task/task.h"

namespace diverse::python {

py::array_t<double> copy_array(const std::vector<double>& data, std::vector<py::ssize_t> shape) {
  py::array_t<double> out(shape);
  if (!data.empty()) std::copy(data.begin(), data.end(), out.mutable_data());
  return out;
}

py::object from_json(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

std::shared_ptr<const TaskData> load_task_data(const std::string& name_or_path, double strength) {
  if (!(strength >= kMinStrength && strength <= kMaxStrength))
    throw UserError("strength: expected a number in [0.1, 10], got " + std::to_string(strength));
  auto data = std::make_shared<TaskData>();
  data->path = std::filesystem::absolute(resolve_task_path(name_or_path)).lexically_normal().string();
  Task task = load_task(data->path);
  task.strength = strength;
  data->evaluator = std::make_unique<const TaskEvaluator>(std::move(task));
  const TaskEvaluator& ev = *data->evaluator;
  data->m0 = ev.parameters();
  data->has_m0 = std::filesystem::exists(ev.task().m0);
  if (data->has_m0) data->m0 = ev.load_parameters(ev.task().m0);
  // The task's metric; distance() takes any other by name.
  data->problem = std::make_unique<const MotionProblem>(
      ev, parse_distance(ev.task().metric, kDefaultShapeWeight, ev.task().file + ": metric"),
      data->m0.normalized(), 1, false);
  data->names = std::make_shared<const Names>(Names{ev.link_names(), ev.angle_names()});
  return data;
}

std::vector<double> parameter_values(const TaskData& task, const py::handle& values, const std::string& where) {
  const ParameterSet& like = task.m0;
  std::vector<double> v;
  try {
    const auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(values);
    if (!array || array.ndim() != 1) throw py::cast_error();
    v.assign(array.data(), array.data() + array.size());
  } catch (const py::error_already_set&) {
    throw UserError(where + ": expected a sequence of " + std::to_string(like.size()) + " numbers");
  } catch (const py::cast_error&) {
    throw UserError(where + ": expected a sequence of " + std::to_string(like.size()) + " numbers");
  }
  if (static_cast<int>(v.size()) != like.size())
    throw UserError(where + ": expected " + std::to_string(like.size()) + " values (the parameters of " +
                    task.evaluator->task().name + "), got " + std::to_string(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) {
    const ParamSpec& s = like.specs()[i];
    if (!(v[i] >= s.lower && v[i] <= s.upper)) {
      std::ostringstream out;
      out << where << ": " << s.name << ": expected a number in [" << s.lower << ", " << s.upper << "], got "
          << v[i];
      throw UserError(out.str());
    }
  }
  return v;
}

namespace {

std::vector<double> bound(const ParameterSet& p, bool upper) {
  std::vector<double> v;
  for (const ParamSpec& s : p.specs()) v.push_back(upper ? s.upper : s.lower);
  return v;
}

void bind_task(py::module_& m) {
  py::class_<PyTask>(m, "Task", "A task file loaded with load_task(): its character, controller, parameters")
      .def_property_readonly("name", [](const PyTask& t) { return t.data->evaluator->task().name; })
      .def_property_readonly("file", [](const PyTask& t) { return t.data->path; })
      .def_property_readonly("metric", [](const PyTask& t) { return t.data->evaluator->task().metric; },
                             "The task's own distance (hf, md or wja)")
      .def_property_readonly("variations", [](const PyTask& t) { return t.data->evaluator->task().variations; },
                             "N, the task's number of variations")
      .def_property_readonly("strength", [](const PyTask& t) { return t.data->evaluator->task().strength; })
      .def_property_readonly("parameter_names",
                             [](const PyTask& t) {
                               std::vector<std::string> names;
                               for (const ParamSpec& s : t.data->m0.specs()) names.push_back(s.name);
                               return names;
                             })
      .def_property_readonly("lower", [](const PyTask& t) {
        const auto v = bound(t.data->m0, false);
        return copy_array(v, {static_cast<py::ssize_t>(v.size())});
      })
      .def_property_readonly("upper", [](const PyTask& t) {
        const auto v = bound(t.data->m0, true);
        return copy_array(v, {static_cast<py::ssize_t>(v.size())});
      })
      .def_property_readonly(
          "m0",
          [](const PyTask& t) -> py::object {
            if (!t.data->has_m0) return py::none();
            const auto& v = t.data->m0.values();
            return copy_array(v, {static_cast<py::ssize_t>(v.size())});
          },
          "The input motion's parameters (None when its file does not exist yet)")
      .def_property_readonly("link_names", [](const PyTask& t) { return t.data->names->links; })
      .def_property_readonly("angle_names", [](const PyTask& t) { return t.data->names->angles; })
      .def_property_readonly("nq", [](const PyTask& t) { return t.data->evaluator->model().get()->nq; })
      .def_property_readonly("model_xml", [](const PyTask& t) { return t.data->evaluator->model().xml(); },
                             "The MJCF text of the task's scene")
      .def("normalize",
           [](const PyTask& t, const py::object& values) {
             ParameterSet p = t.data->m0;
             p.values() = parameter_values(*t.data, values, "params");
             const Eigen::VectorXd x = p.normalized();
             return copy_array(std::vector<double>(x.data(), x.data() + x.size()), {x.size()});
           },
           "Parameters in [0, 1] (lower bound 0, upper 1), as the optimizer sees them")
      .def("denormalize",
           [](const PyTask& t, const py::array_t<double, py::array::c_style | py::array::forcecast>& x) {
             if (x.ndim() != 1 || x.size() != t.data->m0.size())
               throw UserError("x: expected " + std::to_string(t.data->m0.size()) + " values in [0, 1]");
             ParameterSet p = t.data->m0;
             p.set_normalized(Eigen::Map<const Eigen::VectorXd>(x.data(), x.size()));
             return copy_array(p.values(), {x.size()});
           })
      .def("__repr__", [](const PyTask& t) {
        return "<diverse.Task " + t.data->evaluator->task().name + ": " + std::to_string(t.data->m0.size()) +
               " parameters>";
      });

  m.def(
      "joints",
      [](const std::string& model_path) {
        // Every joint of an MJCF and where it sits in qpos, as MuJoCo lays them out.
        const auto model = SharedModel::from_file(model_path);
        const mjModel* mm = model->get();
        static const char* kinds[] = {"free", "ball", "slide", "hinge"};
        py::list joints;
        for (int j = 0; j < mm->njnt; ++j) {
          const char* name = mj_id2name(mm, mjOBJ_JOINT, j);
          joints.append(py::make_tuple(name ? name : "", kinds[mm->jnt_type[j]], mm->jnt_qposadr[j]));
        }
        return joints;
      },
      py::arg("model"), "[(name, type, first qpos column)] of every joint of an MJCF file (a run's model/m<i>.xml)");
  m.def(
      "load_task",
      [](const std::string& name_or_path, double strength) {
        return PyTask{load_task_data(name_or_path, strength)};
      },
      py::arg("task"), py::arg("strength") = 1.0,
      "A task by name (tasks/<name>.toml) or task file; strength scales every joint's gains and torque limits");
}

}  // namespace

}  // namespace diverse::python

PYBIND11_MODULE(_diverse, m) {
  using namespace diverse::python;
  m.doc() = "diverse: many different simulated ways to perform a skill (the C++ library from Python)";
  m.attr("__version__") = DIVERSE_VERSION;
  // Bad input: the same one line the CLI prints after "diverse: error: ".
  static py::exception<diverse::UserError> user_error(m, "UserError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const diverse::UserError& e) {
      user_error(e.what());
    }
  });
  bind_task(m);
  bind_motion(m);
  bind_run(m);
}
