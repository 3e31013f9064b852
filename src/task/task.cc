#include "task/task.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <regex>
#include <sstream>
#include <toml++/toml.h>

#include "core/error.h"
#include "core/text_file.h"
#include "core/toml_reader.h"
#include "task/term_fall.h"
#include "task/term_landing.h"

namespace diverse {
namespace fs = std::filesystem;
namespace {

std::string resolve(const std::string& task_file, const std::string& relative) {
  fs::path p(relative);
  if (p.is_absolute()) return p.lexically_normal().string();
  return (fs::path(task_file).parent_path() / p).lexically_normal().string();
}

std::string existing_file(const TomlReader& r, const char* key) {
  const std::string path = resolve(r.file(), r.string(key));
  if (!fs::is_regular_file(path)) {
    r.fail(key, "expected an existing file (relative to the task file), but " + path +
                    " does not exist");
  }
  return path;
}

void read_controller(const TomlReader& r, Task& task) {
  // The planar jump controller "jump2d" became the skill file skills/jump2d.toml: a task
  // that still names it is told the line to write instead, relative to the task file.
  if (r.has("type") && r.string("type") == "jump2d") {
    const fs::path skill = fs::path(DIVERSE_SOURCE_DIR) / "skills" / "jump2d.toml";
    const fs::path from = fs::absolute(r.file()).lexically_normal().parent_path();
    std::string relative = skill.lexically_normal().lexically_relative(from).string();
    if (relative.empty()) relative = skill.lexically_normal().string();
    r.fail("type", "expected skill = \"" + relative +
                       "\" in place of type = \"jump2d\" (that controller is this skill file now, its keys the "
                       "settings of the skill's modules: docs/reference/skills.md)");
  }
  // A skill file names the skill engine ("skill"); otherwise a controller type by name.
  task.controller = r.has("skill") && !r.has("type") ? "skill" : r.string("type");
  task.controller_type = &find_controller(task.controller, r.file() + ": " + r.field("type"));
  task.controller_config = task.controller_type->read_config(r);
}

void read_objects(const TomlReader& r, const toml::node* node, Task& task) {
  if (node == nullptr) return;
  const toml::array* list = node->as_array();
  if (list == nullptr) r.fail("objects", "expected an array of tables ([[objects]])");
  for (size_t i = 0; i < list->size(); ++i) {
    const std::string where = "objects[" + std::to_string(i) + "]";
    const toml::table* t = list->get(i)->as_table();
    if (t == nullptr) r.fail(where, "expected a table");
    TomlReader o(r.file(), *t, where);
    o.only({"name", "kind", "x_min", "x_max", "height"});
    SceneObject obj;
    obj.name = o.string("name");
    // The name goes into the scene's MJCF as an attribute: letters, digits, '_', '-' and
    // '.' only, so that no name can break out of it.
    if (obj.name.empty() || obj.name.size() > 64 ||
        obj.name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-.") !=
            std::string::npos)
      o.fail("name", "expected 1 to 64 letters, digits, '_', '-' or '.', got \"" + obj.name + "\"");
    for (const SceneObject& other : task.objects) {
      if (other.name == obj.name) o.fail("name", "expected a unique name, \"" + obj.name + "\" repeats");
    }
    obj.kind = o.string("kind");
    if (obj.kind != "box" && obj.kind != "obstacle") {
      o.fail("kind", "expected \"box\" or \"obstacle\", got \"" + obj.kind + "\"");
    }
    obj.x_min = o.number("x_min", -20, 20);
    obj.x_max = o.number("x_max", -20, 20);
    if (obj.x_max <= obj.x_min) o.fail("x_max", "expected a number greater than x_min");
    obj.height = o.number("height", 0, 3);
    task.objects.push_back(obj);
  }
}

// Reads one constraint of `kind` from `r` (its keys only) into the task's constraints.
void read_term(const ConstraintKind& kind, const TomlReader& r, Task& task, bool walks) {
  if (walks && !kind.walks) {
    std::string known;
    for (const ConstraintKind& k : builtin_constraint_kinds())
      if (k.walks) known += std::string(known.empty() ? "" : ", ") + k.name;
    throw UserError(r.file() + ": " + r.path() + ": expected a constraint a walk can meet (" + known +
                    "), got \"" + kind.name + "\"");
  }
  kind.read(r, task, task.constraints);
}

// The table form: [constraints] with one table per constraint, in the order their terms
// add to C.
void read_constraint_table(const TomlReader& r, Task& task, bool walks) {
  r.only({"weight", "fall_penalty", "allow_contact", "landing", "on_box", "clearance", "min_length",
          "peak_height", "rotation", "pitch", "half_timestep", "foot_slip"});
  TaskConstraints& c = task.constraints;
  c.weight = r.number("weight", 1e-6, 1e9);
  c.fall_penalty = r.number("fall_penalty", 1e-6, 1e12);
  for (const char* name : {"landing", "on_box", "clearance", "min_length", "peak_height", "rotation", "pitch", "foot_slip"}) {
    if (auto t = r.table(name, false)) read_term(find_constraint_kind(name, r.file()), r.sub(name, *t), task, walks);
  }
  c.half_timestep = r.boolean("half_timestep", false);
  read_allow_contact(r, c);
}

// The list form: [[constraints]], one entry per constraint, `kind` and the kind's keys,
// in the order their terms add to C.
void read_constraint_list(const TomlReader& r, Task& task, bool walks) {
  const std::vector<const toml::table*> entries = r.tables("constraints", true);
  std::vector<std::string> seen;
  for (size_t i = 0; i < entries.size(); ++i) {
    const TomlReader e = r.element("constraints", i, *entries[i]);
    const std::string name = e.string("kind");
    const ConstraintKind& kind = find_constraint_kind(name, e.file() + ": " + e.field("kind"));
    if (!kind.repeats && std::find(seen.begin(), seen.end(), name) != seen.end())
      e.fail("kind", "expected each kind once, \"" + name + "\" is listed twice");
    seen.push_back(name);
    toml::table keys = *entries[i];
    keys.erase("kind");
    read_term(kind, e.with_table(keys), task, walks);
  }
}

void read_simulation(const TomlReader& r, Task& task) {
  r.only({"settle_time", "settle_speed", "settle_max", "max_time", "fall_com_height",
          "fall_tilt", "clearance_range", "timestep", "balanced_rest",
          "rest_hold", "hop_is_fall", "topple_distance",
          "topple_after", "saturated_drive", "damping", "friction_cone"});
  TaskSimulation& s = task.simulation;
  s.settle_time = r.number("settle_time", 1.0, 10, s.settle_time);
  s.settle_speed = r.number("settle_speed", 0.01, 5, s.settle_speed);
  s.settle_max = r.number("settle_max", s.settle_time, 20, std::max(s.settle_max, s.settle_time));
  s.balanced_rest = r.boolean("balanced_rest", s.balanced_rest);
  s.rest_hold = r.number("rest_hold", 0, 5, s.rest_hold);
  s.hop_is_fall = r.boolean("hop_is_fall", s.hop_is_fall);
  s.topple_distance = r.number("topple_distance", 0, 1, s.topple_distance);
  s.topple_after = r.number("topple_after", 0, 5, s.topple_after);
  if (r.has("saturated_drive")) {
    const std::string way = r.string("saturated_drive");
    if (way == "explicit") {
      s.saturated_drive = SaturatedDrive::kExplicit;
    } else if (way == "stable_pd") {
      s.saturated_drive = SaturatedDrive::kStablePd;
    } else {
      r.fail("saturated_drive", "expected \"explicit\" or \"stable_pd\", got \"" + way + "\"");
    }
  }
  if (r.has("damping")) {
    const std::string way = r.string("damping");
    if (way == "mujoco") {
      s.damping = Damping::kMujoco;
    } else if (way == "constrained") {
      s.damping = Damping::kConstrained;
      if (r.has("saturated_drive"))
        r.fail("saturated_drive", "has no effect with damping = \"constrained\" (every joint is driven that way); remove it");
    } else {
      r.fail("damping", "expected \"mujoco\" or \"constrained\", got \"" + way + "\"");
    }
  }
  if (r.has("friction_cone")) {
    s.friction_cone = r.string("friction_cone");
    if (s.friction_cone != "elliptic" && s.friction_cone != "pyramidal")
      r.fail("friction_cone", "expected \"elliptic\" or \"pyramidal\", got \"" + s.friction_cone + "\"");
  }
  s.max_time = r.number("max_time", 0.5, 60, s.max_time);
  s.fall_com_height = r.number("fall_com_height", 0, 1.5, s.fall_com_height);
  s.fall_tilt = r.number("fall_tilt", 0, 3.14, s.fall_tilt);
  s.clearance_range = r.number("clearance_range", 0.01, 2, s.clearance_range);
  s.timestep = r.number("timestep", 0, 0.01, s.timestep);
  if (s.timestep != 0 && s.timestep < 1e-5)
    r.fail("timestep", "expected 0 (the model's) or a number in [1e-05, 0.01], got " + num(s.timestep));
}

void read_seed(const TomlReader& r, Task& task) {
  r.only({"base", "object", "heights", "distances", "generations", "sigma", "popsize", "seed", "robustness"});
  TaskSeed& s = task.seed;
  s.base = existing_file(r, "base");
  s.object = r.string("object", "");
  if (!s.object.empty() && task.find_object(s.object) == nullptr) {
    r.fail("object", "expected the name of a scene object, got \"" + s.object + "\"");
  }
  if (r.has("heights")) {
    const toml::array* a = r.raw().get("heights")->as_array();
    if (a == nullptr) r.fail("heights", "expected an array of numbers in [0, 3]");
    for (const toml::node& n : *a) {
      double v = -1;
      if (auto f = n.as_floating_point()) v = f->get();
      if (auto i = n.as_integer()) v = static_cast<double>(i->get());
      if (!(v >= 0 && v <= 3)) r.fail("heights", "expected an array of numbers in [0, 3]");
      s.heights.push_back(v);
    }
  }
  if (!s.object.empty() && s.heights.empty()) {
    r.fail("heights", "expected continuation heights for the object (missing)");
  }
  if (r.has("distances")) {
    const toml::array* a = r.raw().get("distances")->as_array();
    if (a == nullptr || a->empty()) r.fail("distances", "expected a non-empty array of numbers in [-20, 20]");
    for (const toml::node& n : *a) {
      double v = 1e9;
      if (auto f = n.as_floating_point()) v = f->get();
      if (auto i = n.as_integer()) v = static_cast<double>(i->get());
      if (!(v >= -20 && v <= 20)) r.fail("distances", "expected a non-empty array of numbers in [-20, 20]");
      s.distances.push_back(v);
    }
    if (!s.object.empty()) r.fail("distances", "expected either an object's heights or landing distances, not both");
    const LandingConstraint* landing = task.constraints.find<LandingConstraint>();
    if (landing == nullptr) r.fail("distances", "expected a landing constraint to move (constraints.landing)");
    if (s.distances.back() != landing->center) {
      r.fail("distances", "expected the last distance to be the task's landing centre (" +
                              std::to_string(landing->center) + ")");
    }
  }
  s.generations = static_cast<int>(r.integer("generations", 1, 100000, s.generations));
  s.sigma = r.number("sigma", 1e-4, 1, s.sigma);
  s.popsize = static_cast<int>(r.integer("popsize", 2, 1000, s.popsize));
  s.seed = static_cast<std::uint64_t>(r.integer("seed", 0, (1LL << 62), 1));
  s.robustness = r.number("robustness", 0, 1e6, s.robustness);
}

void read_diversity(const TomlReader& r, Task& task) {
  r.only({"sigma0", "generations"});
  task.diversity.sigma0 = r.number("sigma0", 1e-4, 1, task.diversity.sigma0);
  task.diversity.generations = r.integer("generations", 1, 1000000, task.diversity.generations);
}

}  // namespace

const SceneObject* Task::find_object(const std::string& object_name) const {
  for (const SceneObject& o : objects) {
    if (o.name == object_name) return &o;
  }
  return nullptr;
}

Task load_task(const std::string& path) {
  const toml::table root = parse_toml_file(path, "task");
  Task task;
  task.file = path;
  TomlReader r(path, root, "");
  r.only({"name", "description", "character", "metric", "variations", "m0", "controller",
          "simulation", "objects", "constraints", "seed", "diversity", "walk"});
  task.name = r.string("name");
  if (task.name.empty()) r.fail("name", "expected a non-empty string");
  task.description = r.string("description", "");
  task.character = resolve_character_file(existing_file(r, "character"));
  task.character_spec = std::make_shared<const CharacterSpec>(load_character_file(task.character));
  task.model = task.character_spec->model;
  task.metric = r.string("metric");
  if (task.metric != "hf" && task.metric != "md" && task.metric != "wja") {
    r.fail("metric", "expected \"hf\", \"md\" or \"wja\", got \"" + task.metric + "\"");
  }
  task.variations = static_cast<int>(r.integer("variations", 1, 100));
  task.m0 = resolve(path, r.string("m0"));
  read_controller(r.sub("controller", *r.table("controller", true)), task);
  const bool walks = std::string(task.controller_type->skill(*task.controller_config)) == "walk";
  read_objects(r, root.get("objects"), task);
  if (auto t = r.table("simulation", false)) read_simulation(r.sub("simulation", *t), task);
  // [constraints] (a table of constraints) or [[constraints]] (a list of them).
  if (const toml::node* n = root.get("constraints"); n != nullptr && n->is_array()) {
    read_constraint_list(r, task, walks);
  } else {
    read_constraint_table(r.sub("constraints", *r.table("constraints", true)), task, walks);
  }
  if (auto t = r.table("seed", false)) read_seed(r.sub("seed", *t), task);
  if (auto t = r.table("diversity", false)) read_diversity(r.sub("diversity", *t), task);
  if (auto t = r.table("walk", false)) read_walk(r.sub("walk", *t), task.walk);
  if (walks != task.walk.enabled) {
    r.fail("walk", walks ? "expected a [walk] table for the walk controller \"" + task.controller + "\" (missing)"
                         : "expected no [walk] table: the controller \"" + task.controller + "\" does not walk");
  }
  return task;
}

std::string resolve_task_path(const std::string& name_or_path) {
  if (fs::is_regular_file(name_or_path)) return name_or_path;
  for (const std::string& dir : {std::string("tasks"), std::string(DIVERSE_SOURCE_DIR) + "/tasks"}) {
    const std::string candidate = dir + "/" + name_or_path + ".toml";
    if (fs::is_regular_file(candidate)) return candidate;
  }
  throw UserError(name_or_path +
                  ": expected a task file or the name of one in tasks/ (no such task)");
}

namespace {

// Every forcerange="lo hi" attribute of an MJCF text times `factor` (actuators and the
// defaults they inherit from alike: in MuJoCo 2.2 only actuators have one).
std::string scale_force_ranges(const std::string& xml, double factor, const std::string& origin) {
  static const std::regex attribute(R"((forcerange\s*=\s*)(["'])([^"']*)\2)");
  std::string out;
  auto last = xml.cbegin();
  for (std::sregex_iterator it(xml.begin(), xml.end(), attribute), end; it != end; ++it) {
    const std::smatch& m = *it;
    std::istringstream in(m[3].str());
    std::ostringstream scaled;
    scaled.precision(17);
    double value = 0;
    int count = 0;
    while (in >> value) scaled << (count++ > 0 ? " " : "") << value * factor;
    if (count != 2 || !(in >> std::ws).eof())
      throw UserError(origin + ": forcerange: expected two numbers, got \"" + m[3].str() + "\"");
    out.append(last, m[0].first);
    out += m[1].str() + m[2].str() + scaled.str() + m[2].str();
    last = m[0].second;
  }
  out.append(last, xml.cend());
  return out;
}

// Sets attribute `name` of the model's <option> element to `value`, replacing the model's
// own or adding it (and the element, if the model has none).
void set_option_attribute(std::string& xml, const std::string& name, const std::string& value) {
  const size_t option = xml.find("<option");
  if (option == std::string::npos) {
    const size_t root = xml.find('>', xml.find("<mujoco"));
    xml.insert(root + 1, "\n  <option " + name + "=\"" + value + "\"/>");
    return;
  }
  const size_t end = xml.find('>', option);
  size_t attr = xml.find(" " + name + "=\"", option);
  if (attr == std::string::npos || attr > end) attr = xml.find("\t" + name + "=\"", option);
  if (attr != std::string::npos && attr < end) {
    const size_t begin = attr + name.size() + 3;
    xml.replace(begin, xml.find('"', begin) - begin, value);
  } else {
    xml.insert(option + 7, " " + name + "=\"" + value + "\"");
  }
}

}  // namespace

std::string scene_xml(const Task& task) {
  std::string xml = read_text_file(task.model, "model");
  if (task.strength != 1.0) xml = scale_force_ranges(xml, task.strength, task.model);
  std::ostringstream geoms;
  geoms.precision(17);
  for (const SceneObject& o : task.objects) {
    const double hx = 0.5 * (o.x_max - o.x_min), hz = 0.5 * std::max(o.height, 1e-3);
    geoms << "    <geom name=\"" << o.name << "\" type=\"box\" pos=\"" << o.x_min + hx << " 0 " << hz
          << "\" size=\"" << hx << " 1 " << hz << "\" contype=\"0\" conaffinity=\"1\"";
    if (o.kind == "obstacle") {
      // Near-contacts in the gap are reported (exclude = 1) but exert no force.
      geoms << " margin=\"" << task.simulation.clearance_range << "\" gap=\""
            << task.simulation.clearance_range << "\" rgba=\"0.8 0.3 0.3 1\"";
    } else {
      geoms << " rgba=\"0.4 0.5 0.8 1\"";
    }
    geoms << "/>\n";
  }
  const size_t at = xml.rfind("</worldbody>");
  if (at == std::string::npos) {
    throw UserError(task.model + ": expected a <worldbody> element in the model");
  }
  xml.insert(at, geoms.str());
  if (task.simulation.timestep > 0) {
    std::ostringstream value;
    value.precision(17);
    value << task.simulation.timestep;
    set_option_attribute(xml, "timestep", value.str());
  }
  if (!task.simulation.friction_cone.empty()) set_option_attribute(xml, "cone", task.simulation.friction_cone);
  return xml;
}

}  // namespace diverse
