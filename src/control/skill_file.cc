#include "control/skill_file.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>

#include "core/error.h"
#include "core/toml_reader.h"

namespace diverse {
namespace {

int line_of(const toml::node& n) { return static_cast<int>(n.source().begin.line); }

// A number node as double; false when it is not a number.
bool as_number(const toml::node& n, double* v) {
  if (auto f = n.as_floating_point()) {
    *v = f->get();
  } else if (auto i = n.as_integer()) {
    *v = static_cast<double>(i->get());
  } else if (auto b = n.as_boolean()) {
    *v = b->get() ? 1.0 : 0.0;
  } else {
    return false;
  }
  return std::isfinite(*v);
}

constexpr const char* kValueForms =
    "expected a number, \"standing\", { param = \"NAME\", range = [LOWER, UPPER] } or { curve = [[s, value], ...] }";

// `range = [lower, upper]`, lower < upper.
void read_range(const TomlReader& r, SkillValue& v) {
  const toml::node* n = r.raw().get("range");
  if (n == nullptr) return;
  const toml::array* a = n->as_array();
  double lo = 0, hi = 0;
  if (a == nullptr || a->size() != 2 || !as_number(*a->get(0), &lo) || !as_number(*a->get(1), &hi)) {
    r.fail("range", "expected [LOWER, UPPER], two numbers");
  }
  if (!(lo < hi)) r.fail("range", "expected a range that is not empty (LOWER < UPPER), got [" + num(lo) + ", " + num(hi) + "]");
  v.has_range = true;
  v.lower = lo;
  v.upper = hi;
}

// A value: a number, or a table with exactly one of param, value, curve (`extra` keys
// are the caller's: world, left, right).
SkillValue read_value(const TomlReader& parent, const std::string& key, const toml::node& n,
                      std::initializer_list<const char*> extra = {}) {
  SkillValue v;
  v.line = line_of(n);
  if (as_number(n, &v.number)) return v;
  if (const auto str = n.as_string(); str != nullptr && str->get() == "standing") {
    v.kind = SkillValue::Kind::kStanding;
    return v;
  }
  const toml::table* t = n.as_table();
  if (t == nullptr) parent.fail(key, kValueForms);
  const TomlReader r = parent.sub(key.c_str(), *t);
  std::vector<const char*> known = {"param", "value", "curve", "range", "unit", "sides"};
  known.insert(known.end(), extra.begin(), extra.end());
  for (const auto& [k, node] : *t) {
    // A named copy: clang before 16 does not let a lambda capture a structured binding.
    const std::string_view key_name = k.str();
    if (std::find_if(known.begin(), known.end(), [&](const char* s) { return key_name == s; }) == known.end()) {
      std::string list;
      for (const char* s : known) list += std::string(list.empty() ? "" : ", ") + s;
      r.fail(std::string(k.str()), "expected no such key (unknown key; known keys: " + list + ")");
    }
  }
  const int forms = (r.has("param") ? 1 : 0) + (r.has("value") ? 1 : 0) + (r.has("curve") ? 1 : 0);
  if (forms != 1) {
    // left/right (swing/stance, root pitch/roll) tables carry their values themselves.
    if (forms == 0 && (r.has("left") || r.has("right") || r.has("swing") || r.has("stance") || r.has("pitch") || r.has("roll"))) return v;
    parent.fail(key, std::string(kValueForms) + (forms == 0 ? " (none given)" : " (only one of param, value, curve)"));
  }
  if (r.has("param")) {
    v.kind = SkillValue::Kind::kParam;
    v.param = r.string("param");
    if (v.param.empty()) r.fail("param", "expected a parameter name");
    read_range(r, v);
    v.unit = r.string("unit", "");
    v.sides = r.boolean("sides", false);
  } else if (r.has("sides")) {
    r.fail("sides", "expected it only with a parameter (param = \"NAME\")");
  } else if (r.has("value")) {
    if (!as_number(*t->get("value"), &v.number)) r.fail("value", "expected a number");
  } else {
    v.kind = SkillValue::Kind::kCurve;
    const toml::array* a = t->get("curve")->as_array();
    const std::string expect = "expected knots [[s, value], ...] with s rising from 0 to 1";
    if (a == nullptr || a->size() < 2) r.fail("curve", expect);
    for (const toml::node& k : *a) {
      const toml::array* knot = k.as_array();
      double s = 0, y = 0;
      if (knot == nullptr || knot->size() != 2 || !as_number(*knot->get(0), &s) || !as_number(*knot->get(1), &y)) {
        r.fail("curve", expect);
      }
      if (!v.curve.empty() && !(s > v.curve.back()[0])) r.fail("curve", expect + ", got s = " + num(s) + " after " + num(v.curve.back()[0]));
      v.curve.push_back({s, y});
    }
    if (v.curve.front()[0] != 0 || v.curve.back()[0] != 1) r.fail("curve", expect);
  }
  if (r.has("mirror")) v.mirror = r.boolean("mirror", false);
  return v;
}

SkillTarget::World read_world(const TomlReader& r) {
  const std::string world = r.string("world", "joint");
  if (world == "parent") return SkillTarget::World::kParent;
  if (world == "child") return SkillTarget::World::kChild;
  if (world == "heading") return SkillTarget::World::kHeading;
  if (world == "root") return SkillTarget::World::kRoot;
  if (world == "torso") return SkillTarget::World::kTorso;
  if (world == "sole") return SkillTarget::World::kSole;
  if (world != "joint") {
    r.fail("world", "expected \"joint\", \"parent\", \"child\", \"heading\", \"root\", \"torso\" or \"sole\", got \"" + world + "\"");
  }
  return SkillTarget::World::kJoint;
}

// One side's value (left, right, swing, stance), which may name its own `world`.
SkillValue read_side(const TomlReader& er, const toml::table& e, const char* key) {
  SkillValue v = read_value(er, key, *e.get(key), {"world", "mirror"});
  if (const toml::table* t = e.get(key)->as_table(); t != nullptr && t->contains("world")) {
    v.world = static_cast<int>(read_world(er.sub(key, *t)));
  }
  return v;
}

void read_target_set(const TomlReader& sets, const std::string& name, const toml::table& t,
                     std::vector<SkillTarget>& out) {
  const TomlReader r = sets.sub(name.c_str(), t);
  for (const auto& [k, node] : t) {
    SkillTarget target;
    target.selector = std::string(k.str());
    target.line = line_of(node);
    if (target.selector == "root") {
      // The free root's orientation in the heading frame: { pitch = VALUE, roll = VALUE }.
      const toml::table* e = node.as_table();
      if (e == nullptr) r.fail("root", "expected a table { pitch = VALUE, roll = VALUE }");
      const TomlReader er = r.sub("root", *e);
      er.only({"pitch", "roll"});
      if (!er.has("pitch") || !er.has("roll")) er.fail(er.has("pitch") ? "roll" : "pitch", std::string(kValueForms) + " (missing)");
      target.world = SkillTarget::World::kHeading;
      target.pitch = read_value(er, "pitch", *e->get("pitch"), {"mirror"});
      target.roll = read_value(er, "roll", *e->get("roll"), {"mirror"});
      for (const SkillValue* v : {&target.pitch, &target.roll}) {
        if (v->kind == SkillValue::Kind::kCurve) er.fail(v == &target.pitch ? "pitch" : "roll", "expected a number or a parameter (the root takes no curve)");
      }
      out.push_back(target);
      continue;
    }
    target.both = read_value(r, target.selector, node, {"world", "left", "right", "swing", "stance", "mirror", "relative"});
    if (const toml::table* e = node.as_table()) {
      const TomlReader er = r.sub(target.selector.c_str(), *e);
      target.world = read_world(er);
      const std::string relative = er.string("relative", "zero");
      if (relative != "zero" && relative != "standing") er.fail("relative", "expected \"standing\" (an offset from the standing pose), got \"" + relative + "\"");
      target.from_standing = relative == "standing";
      if (target.from_standing && target.world != SkillTarget::World::kJoint) er.fail("relative", "expected it only with joint targets (world = \"joint\")");
      const bool lr = er.has("left") || er.has("right"), roles = er.has("swing") || er.has("stance");
      if (lr || roles) {
        const char* a = lr ? "left" : "swing";
        const char* b = lr ? "right" : "stance";
        if (er.has("param") || er.has("value") || er.has("curve")) {
          er.fail(a, std::string("expected either one value for both sides or ") + a + " and " + b + ", not both");
        }
        if (lr && roles) er.fail("swing", "expected either left and right or swing and stance, not both");
        if (!er.has(a) || !er.has(b)) er.fail(er.has(a) ? b : a, std::string("expected both ") + a + " and " + b + " (missing)");
        target.sided = true;
        target.by_role = roles;
        target.left = read_side(er, *e, a);
        target.right = read_side(er, *e, b);
      }
    }
    out.push_back(target);
  }
}

void read_gain_set(const TomlReader& sets, const std::string& name, const toml::table& t, std::vector<SkillGain>& out) {
  const TomlReader r = sets.sub(name.c_str(), t);
  for (const auto& [k, node] : t) {
    const std::string selector(k.str());
    const toml::table* e = node.as_table();
    if (e == nullptr) r.fail(selector, "expected a table { kp = ..., kd = ... }");
    const TomlReader er = r.sub(selector.c_str(), *e);
    er.only({"kp", "kd"});
    if (!er.has("kp") || !er.has("kd")) er.fail(er.has("kp") ? "kd" : "kp", std::string(kValueForms) + " (missing)");
    SkillGain g;
    g.selector = selector;
    g.line = line_of(node);
    g.kp = read_value(er, "kp", *e->get("kp"));
    g.kd = read_value(er, "kd", *e->get("kd"));
    for (const SkillValue* v : {&g.kp, &g.kd}) {
      if (v->kind == SkillValue::Kind::kCurve || v->kind == SkillValue::Kind::kStanding) er.fail(v == &g.kp ? "kp" : "kd", "expected a number or a parameter (gains take no curve)");
      if (v->kind == SkillValue::Kind::kParam && !v->has_range) er.fail(v == &g.kp ? "kp" : "kd", "expected a range = [LOWER, UPPER] for a gain parameter");
    }
    out.push_back(g);
  }
}

const std::vector<std::string> kConditions = {"duration", "time",         "contact",      "touchdown",
                                              "liftoff",  "contact_made", "contact_lost", "peak",
                                              "turned",   "spotted",      "feature"};

SkillCondition::Type condition_type(const std::string& kind) {
  using T = SkillCondition::Type;
  if (kind == "duration") return T::kDuration;
  if (kind == "time") return T::kTime;
  if (kind == "contact" || kind == "touchdown") return T::kContact;
  if (kind == "liftoff") return T::kLiftoff;
  if (kind == "contact_made") return T::kContactMade;
  if (kind == "contact_lost") return T::kContactLost;
  if (kind == "peak") return T::kPeak;
  if (kind == "turned") return T::kTurned;
  if (kind == "spotted") return T::kSpotted;
  return T::kFeature;
}

std::string quoted_list(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += std::string(s.empty() ? "\"" : ", \"") + n + "\"";
  return s;
}

SkillTransition read_transition(const TomlReader& r, const toml::table& t) {
  r.only({"to", "on", "passes", "gave_up", "after", "for", "angle", "body", "foot", "feature", "above", "below"});
  SkillTransition tr;
  tr.line = line_of(t);
  tr.to = r.string("to");
  std::vector<std::string> kinds;
  if (const toml::node* on = t.get("on"); on != nullptr && on->is_string()) {
    kinds.push_back(r.string("on"));
  } else {
    kinds = r.strings("on", 1);
  }
  tr.gave_up = r.boolean("gave_up", false);
  if (r.has("passes")) tr.passes = r.strings("passes");
  std::set<std::string> used;
  for (const std::string& kind : kinds) {
    if (std::find(kConditions.begin(), kConditions.end(), kind) == kConditions.end()) {
      r.fail("on", "expected one of " + quoted_list(kConditions) + ", got \"" + kind + "\"");
    }
    SkillCondition c;
    c.kind = kind;
    auto need = [&](const char* key) {
      if (!r.has(key)) r.fail(key, "expected a setting for the \"" + kind + "\" condition (missing)");
      used.insert(key);
    };
    if (kind == "time") {
      need("after");
      c.after = r.number("after", 0, 100);
    } else if (kind == "liftoff") {
      c.airborne = r.number("for", 0, 1, c.airborne);
      used.insert("for");
    } else if (kind == "turned") {
      need("angle");
      c.angle = r.number("angle", 0, 8 * M_PI);
    } else if (kind == "contact_made" || kind == "contact_lost") {
      // A body by name, or a foot by side or by its role in the phase.
      if (r.has("foot") == r.has("body")) r.fail("body", "expected exactly one of body = \"NAME\" or foot = \"swing\", \"stance\", \"left\" or \"right\"");
      if (r.has("body")) {
        need("body");
        c.body = r.string("body");
      } else {
        need("foot");
        c.foot = r.string("foot");
        if (c.foot != "swing" && c.foot != "stance" && c.foot != "left" && c.foot != "right") {
          r.fail("foot", "expected \"swing\", \"stance\", \"left\" or \"right\", got \"" + c.foot + "\"");
        }
      }
    } else if (kind == "feature") {
      need("feature");
      c.feature = r.string("feature");
      if (!skill_feature_of(c.feature, &c.which)) {
        r.fail("feature", "expected one of " + quoted_list(skill_feature_names()) + ", got \"" + c.feature + "\"");
      }
      if (r.has("above") == r.has("below")) r.fail("above", "expected exactly one of above = NUMBER or below = NUMBER");
      c.above = r.has("above");
      c.threshold = r.number(c.above ? "above" : "below", -1e6, 1e6);
      used.insert(c.above ? "above" : "below");
    }
    c.type = condition_type(c.kind);
    tr.on.push_back(c);
  }
  for (const char* key : {"after", "for", "angle", "body", "foot", "feature", "above", "below"}) {
    if (r.has(key) && used.count(key) == 0) r.fail(key, "expected no such setting for the conditions " + quoted_list(kinds));
  }
  return tr;
}

SkillDuration read_duration(const TomlReader& r, const toml::table& phase) {
  SkillDuration d;
  const toml::node* n = phase.get("duration");
  if (n == nullptr) return d;
  d.line = line_of(*n);
  const toml::table* t = n->as_table();
  if (t != nullptr && t->contains("predict")) {
    const TomlReader pr = r.sub("duration", *t);
    pr.only({"predict", "at_most"});
    d.kind = SkillDuration::Kind::kPredict;
    d.predict = pr.string("predict");
    if (d.predict != "rise" && d.predict != "fall" && d.predict != "touchdown") {
      pr.fail("predict", "expected \"rise\", \"fall\" or \"touchdown\", got \"" + d.predict + "\"");
    }
    d.at_most = pr.number("at_most", 0, 10, 0);
    return d;
  }
  d.kind = SkillDuration::Kind::kValue;
  d.value = read_value(r, "duration", *n);
  if (d.value.kind == SkillValue::Kind::kCurve || d.value.kind == SkillValue::Kind::kStanding) r.fail("duration", "expected a number or a parameter (a duration takes no curve)");
  if (d.value.kind == SkillValue::Kind::kParam && !d.value.has_range) r.fail("duration", "expected a range = [LOWER, UPPER] for a duration parameter");
  if (d.value.kind == SkillValue::Kind::kNumber && !(d.value.number > 0)) r.fail("duration", "expected a duration > 0 s, got " + num(d.value.number));
  return d;
}

// A module setting's number: in range for its name. Gains, forces, times and the lean are
// not negative; stand_after is -1 (never) or more; a stand-up takes 50 ms or more (the
// stance module divides by its duration); offsets and gains on a velocity take any finite
// value.
void check_setting(const TomlReader& r, const std::string& key, double v) {
  double lo = 0, hi = 1e9;
  if (key.rfind("offset", 0) == 0 || key.rfind("velocity_gain", 0) == 0 || key == "speed") lo = -1e9;
  if (key == "stand_after") lo = -1;
  if (key == "stand_duration") lo = 0.05;
  if (key == "at_touchdown" || key == "push" || key == "take_footing") hi = 1;
  if (key == "turn") hi = 8 * M_PI;
  if (key == "gain" || key == "reference") lo = -1e9;
  if (key == "sample") hi = 1;
  if (key == "limit") lo = 1e-6;
  if (!(v >= lo && v <= hi)) r.fail(key, "expected a number in [" + num(lo) + ", " + num(hi) + "], got " + num(v));
}

}  // namespace

namespace {

// The features a linear_feedback module may read: skill_feature_names(), as words.
std::vector<const char*> feature_words() {
  std::vector<const char*> words;
  for (const std::string& name : skill_feature_names()) words.push_back(name.c_str());  // static strings
  return words;
}

}  // namespace

const SkillModuleKind* find_module_kind(const std::string& kind) {
  for (const SkillModuleKind& k : skill_module_kinds())
    if (kind == k.kind) return &k;
  return nullptr;
}

const std::vector<SkillModuleKind>& skill_module_kinds() {
  static const std::vector<SkillModuleKind> kinds = {
      {"balance", {"kp", "kd", "max_force"}, {"gravity_compensation", "offset", "lean"},
       "J^T balance: a virtual force on the COM through the stance legs (Pratt et al. 2001)"},
      {"foot_placement", {"offset", "velocity_gain"}, {"reach", "at_touchdown"},
       "landing: the hips place the ankles where the COM comes down (paper section 6)"},
      {"spotting", {"turn", "open_time"}, {},
       "spotting the landing: the `spotted` condition holds when the body, opened now, turns `turn` by touch-down"},
      {"stance", {}, {"offset", "stand_after", "stand_duration"},
       "stance control: COM force kept inside the soles, pelvis, chest and feet in world pitch"},
      {"simbicon", {"cd", "cv"}, {},
       "SIMBICON balance: the swing hip's target in one plane plus cd d + cv v (Yin, Loken, van de Panne 2007)",
       {{"plane", {"sagittal", "coronal"}}}},
      {"gravity_compensation", {}, {},
       "every joint off the legs in stance holds the links it carries against gravity"},
      {"stance_support", {"support"}, {},
       "the stance leg's knee and the joints below it carry `support` times the weight, J^T of an upward force on the COM"},
      {"stance_hip", {}, {"root_kp", "root_kd"},
       "the root's pitch and roll held by the stance hip, whose torque is the remainder (SIMBICON; Coros et al. 2010)"},
      {"stance3d", {}, {"offset", "speed", "push", "take_footing", "com_kp", "com_kd", "yaw_kp", "yaw_kd"},
       "stance control of a free root: J^T COM force, the root, torso and soles at their world pitches"},
      {"aim_legs", {"offset_left", "offset_right", "velocity_gain_left", "velocity_gain_right"}, {},
       "landing of a free root: the hips point each leg where the COM comes down (paper section 6)"},
      {"root_damping", {"kd"}, {},
       "push-off turn damping: the hip hinges damp the root's rotation about their axes"},
      {"linear_feedback", {"gain"}, {"reference", "limit", "sample"},
       "linear feedback: the targets of `target`'s joints offset by gain (feature - reference), within +-limit",
       {{"feature", feature_words()}},
       {"target"}},
  };
  return kinds;
}

int SkillFile::phase_index(const std::string& n) const {
  for (size_t i = 0; i < phases.size(); ++i)
    if (phases[i].name == n) return static_cast<int>(i);
  return -1;
}

int SkillFile::module_index(const std::string& n) const {
  for (size_t i = 0; i < modules.size(); ++i)
    if (modules[i].name == n) return static_cast<int>(i);
  return -1;
}

SkillFile load_skill_file(const std::string& path) {
  const toml::table root = parse_toml_file(path, "skill");
  const TomlReader r = TomlReader(path, root, "").with_lines();
  r.only({"name", "description", "kind", "root", "pairs", "start", "events", "targets", "gains", "modules", "phases"});
  SkillFile s;
  s.file = path;
  s.name = r.string("name");
  s.description = r.string("description", "");
  const std::string root_kind = r.string("root", "planar");
  if (root_kind == "free") s.root = RootKind::kFree;
  else if (root_kind != "planar") r.fail("root", "expected \"planar\" or \"free\", got \"" + root_kind + "\"");
  if (r.has("pairs")) s.pairs = r.strings("pairs");
  if (r.has("root")) s.root_line = line_of(*root.get("root"));
  if (r.has("pairs")) s.pairs_line = line_of(*root.get("pairs"));
  const std::string motion = r.string("kind", "jump");
  if (motion != "jump" && motion != "walk") r.fail("kind", "expected \"jump\" or \"walk\", got \"" + motion + "\"");
  s.walk = motion == "walk";
  const std::string start = r.string("start", "standing");
  if (start != "standing" && start != "first_phase") r.fail("start", "expected \"standing\" or \"first_phase\", got \"" + start + "\"");
  s.start_pose = start == "first_phase";
  if (s.start_pose && s.root != RootKind::kFree) r.fail("start", "expected \"standing\": a start in the first phase's pose needs root = \"free\"");

  if (const toml::table* t = r.table("targets", true)) {
    const TomlReader tr = r.sub("targets", *t);
    for (const auto& [k, node] : *t) {
      if (!node.is_table()) tr.fail(std::string(k.str()), "expected a table of targets [targets.NAME]");
      read_target_set(tr, std::string(k.str()), *node.as_table(), s.target_sets[std::string(k.str())]);
    }
  }
  if (const toml::table* t = r.table("gains", false)) {
    const TomlReader gr = r.sub("gains", *t);
    for (const auto& [k, node] : *t) {
      if (!node.is_table()) gr.fail(std::string(k.str()), "expected a table of gains [gains.NAME]");
      read_gain_set(gr, std::string(k.str()), *node.as_table(), s.gain_sets[std::string(k.str())]);
    }
  }

  // Modules: a kind the engine knows, its required settings, no others.
  const auto modules = r.tables("modules", false);
  for (size_t i = 0; i < modules.size(); ++i) {
    const TomlReader mr = r.element("modules", i, *modules[i]);
    SkillModuleSpec m;
    m.line = line_of(*modules[i]);
    m.name = mr.string("name");
    m.kind = mr.string("kind");
    if (s.module_index(m.name) >= 0) mr.fail("name", "expected a name no other module has, got \"" + m.name + "\" twice");
    const SkillModuleKind* kind = nullptr;
    std::vector<std::string> kinds;
    for (const SkillModuleKind& k : skill_module_kinds()) {
      kinds.emplace_back(k.kind);
      if (m.kind == k.kind) kind = &k;
    }
    if (kind == nullptr) mr.fail("kind", "expected one of " + quoted_list(kinds) + ", got \"" + m.kind + "\"");
    for (const auto& [word, choices] : kind->words) {
      if (!mr.has(word)) mr.fail(word, "expected a setting of the \"" + m.kind + "\" module (missing)");
      const std::string value = mr.string(word);
      if (std::none_of(choices.begin(), choices.end(), [&](const char* c) { return value == c; })) {
        std::vector<std::string> list(choices.begin(), choices.end());
        mr.fail(word, "expected one of " + quoted_list(list) + ", got \"" + value + "\"");
      }
      m.words[word] = value;
    }
    // Settings that name joint groups (a selector, as a target set's keys): bound to the
    // character's groups with the skill.
    for (const char* word : kind->selectors) {
      if (!mr.has(word)) mr.fail(word, "expected a setting of the \"" + m.kind + "\" module (missing)");
      m.words[word] = mr.string(word);
      if (m.words[word].empty()) mr.fail(word, "expected a joint group, role or ROLE.plane (a selector), got \"\"");
    }
    for (const auto& [k, node] : *modules[i]) {
      const std::string key(k.str());
      if (key == "name" || key == "kind" || m.words.count(key) > 0) continue;
      const bool known = std::any_of(kind->required.begin(), kind->required.end(), [&](const char* x) { return key == x; }) ||
                         std::any_of(kind->optional.begin(), kind->optional.end(), [&](const char* x) { return key == x; });
      if (!known) {
        std::string list;
        for (const auto* group : {&kind->required, &kind->optional})
          for (const char* x : *group) list += std::string(list.empty() ? "" : ", ") + x;
        mr.fail(key, "expected no such setting for a \"" + m.kind + "\" module (known: " + list + ")");
      }
      SkillValue v = read_value(mr, key, node);
      if (v.kind == SkillValue::Kind::kCurve || v.kind == SkillValue::Kind::kStanding) mr.fail(key, "expected a number or a parameter (a setting takes no curve)");
      if (v.kind == SkillValue::Kind::kParam && !v.has_range) mr.fail(key, "expected a range = [LOWER, UPPER] for a module parameter");
      if (v.kind == SkillValue::Kind::kNumber) check_setting(mr, key, v.number);
      m.settings[key] = v;
    }
    for (const char* key : kind->required) {
      if (m.settings.count(key) == 0) mr.fail(key, "expected a setting of the \"" + m.kind + "\" module (missing)");
    }
    s.modules.push_back(m);
  }

  // Phases.
  const auto phases = r.tables("phases", true);
  if (phases.empty()) r.fail("phases", "expected at least one [[phases]]");
  std::vector<TomlReader> readers;
  for (size_t i = 0; i < phases.size(); ++i) {
    readers.push_back(r.element("phases", i, *phases[i]));
    const TomlReader& pr = readers.back();
    pr.only({"name", "parameters", "swing", "targets", "gains", "duration", "interpolate", "from", "modules", "next"});
    SkillPhase p;
    p.line = line_of(*phases[i]);
    p.name = pr.string("name");
    p.parameters = pr.string("parameters", "");
    if (pr.has("swing")) {
      const std::string swing = pr.string("swing");
      if (swing != "left" && swing != "right") pr.fail("swing", "expected \"left\" or \"right\", got \"" + swing + "\"");
      if (s.root != RootKind::kFree) pr.fail("swing", "expected no swing leg: a phase with a swing leg needs root = \"free\"");
      p.swing = swing == "left" ? 0 : 1;
    }
    if (s.phase_index(p.name) >= 0) pr.fail("name", "expected a name no other phase has, got \"" + p.name + "\" twice");
    p.targets = pr.string("targets");
    if (s.target_sets.count(p.targets) == 0) pr.fail("targets", "expected a target set [targets." + p.targets + "] (none in the file)");
    p.gains = pr.string("gains", "");
    if (!p.gains.empty() && s.gain_sets.count(p.gains) == 0) pr.fail("gains", "expected a gain set [gains." + p.gains + "] (none in the file)");
    p.interpolate = pr.boolean("interpolate", true);
    const std::string from = pr.string("from", "targets");
    if (from == "goals") p.from = SkillPhase::From::kGoals;
    else if (from == "pose") p.from = SkillPhase::From::kPose;
    else if (from == "none") p.from = SkillPhase::From::kNone;
    else if (from != "targets") pr.fail("from", "expected \"targets\", \"goals\", \"pose\" or \"none\", got \"" + from + "\"");
    p.duration = read_duration(pr, *phases[i]);
    if (pr.has("modules")) p.modules = pr.strings("modules");
    for (const std::string& m : p.modules) {
      if (s.module_index(m) < 0) pr.fail("modules", "expected modules the file declares in [[modules]], got \"" + m + "\"");
    }
    for (const toml::table* t : pr.tables("next", false)) {
      p.next.push_back(read_transition(pr.element("next", p.next.size(), *t), *t));
    }
    s.phases.push_back(p);
  }

  // Transitions lead to phases that exist; every phase but the last can be left.
  for (size_t i = 0; i < s.phases.size(); ++i) {
    const SkillPhase& p = s.phases[i];
    const TomlReader& pr = readers[i];
    for (size_t k = 0; k < p.next.size(); ++k) {
      const SkillTransition& tr = p.next[k];
      const auto& elements = pr.tables("next", false);
      const TomlReader er = pr.element("next", k, *elements[k]);
      if (s.phase_index(tr.to) < 0) er.fail("to", "expected the name of a phase, got \"" + tr.to + "\" (no such phase)");
      for (const std::string& passed : tr.passes) {
        if (s.phase_index(passed) < 0) er.fail("passes", "expected names of phases, got \"" + passed + "\" (no such phase)");
      }
      for (const SkillCondition& c : tr.on) {
        if (c.kind == "duration" && p.duration.kind != SkillDuration::Kind::kValue &&
            p.duration.kind != SkillDuration::Kind::kPredict) {
          er.fail("on", "expected the phase to have a duration for an \"duration\" transition (phase \"" + p.name + "\" has none)");
        }
        if (c.kind == "spotted" &&
            std::none_of(p.modules.begin(), p.modules.end(), [&](const std::string& m) { return s.modules[static_cast<size_t>(s.module_index(m))].kind == "spotting"; })) {
          er.fail("on", "expected the phase to switch on a \"spotting\" module for a \"spotted\" transition");
        }
      }
    }
    if (p.next.empty() && i + 1 != s.phases.size()) {
      pr.fail("next", "expected at least one transition: phase \"" + p.name + "\" can never be left (only the last phase may end the skill)");
    }
  }

  // Events name phases.
  if (const toml::table* t = r.table("events", false)) {
    const TomlReader er = r.sub("events", *t);
    er.only({"push", "takeoff", "peak", "landing", "film_strip"});
    for (auto [key, field] : {std::pair{"push", &s.push}, {"takeoff", &s.takeoff}, {"peak", &s.peak}, {"landing", &s.landing}}) {
      *field = er.string(key, "");
      if (!field->empty() && s.phase_index(*field) < 0) er.fail(key, "expected the name of a phase, got \"" + *field + "\" (no such phase)");
    }
    if (er.has("film_strip")) {
      s.film_strip = er.strings("film_strip");
      for (const std::string& e : s.film_strip) {
        const std::string* phase = e == "push" ? &s.push : e == "takeoff" ? &s.takeoff : e == "peak" ? &s.peak : e == "landing" ? &s.landing : nullptr;
        if (phase == nullptr) er.fail("film_strip", "expected events among \"push\", \"takeoff\", \"peak\", \"landing\", got \"" + e + "\"");
        if (phase->empty()) er.fail("film_strip", "expected events [events] names a phase for, got \"" + e + "\"");
      }
    }
  }
  return s;
}

void override_skill_settings(SkillFile& skill, const TomlReader& r, const std::vector<std::string>& own_keys) {
  for (const auto& [k, node] : r.raw()) {
    const std::string key(k.str());
    if (std::find(own_keys.begin(), own_keys.end(), key) != own_keys.end()) continue;
    const int m = skill.module_index(key);
    if (m < 0 || !node.is_table()) {
      std::string known;
      for (const auto& own : own_keys) known += std::string(known.empty() ? "" : ", ") + own;
      for (const auto& mod : skill.modules) known += ", " + mod.name;
      r.fail(key, "expected no such key (unknown key; known keys: " + known + ", the last the skill's modules as tables)");
    }
    SkillModuleSpec& spec = skill.modules[static_cast<size_t>(m)];
    const TomlReader mr = r.sub(key.c_str(), *node.as_table());
    for (const auto& [sk, sn] : *node.as_table()) {
      const std::string setting(sk.str());
      auto it = spec.settings.find(setting);
      const SkillModuleKind* kind = find_module_kind(spec.kind);
      const bool known = std::any_of(kind->required.begin(), kind->required.end(), [&](const char* x) { return setting == x; }) ||
                         std::any_of(kind->optional.begin(), kind->optional.end(), [&](const char* x) { return setting == x; });
      if (!known) mr.fail(setting, "expected a setting of the \"" + spec.kind + "\" module " + key);
      if (it != spec.settings.end() && it->second.kind == SkillValue::Kind::kParam) {
        mr.fail(setting, "expected a number setting (the skill makes " + key + "." + setting + " the parameter \"" + it->second.param + "\")");
      }
      double v = 0;
      if (!as_number(sn, &v)) mr.fail(setting, "expected a number");
      check_setting(mr, setting, v);
      SkillValue value;
      value.number = v;
      value.line = line_of(sn);
      spec.settings[setting] = value;
    }
  }
}

std::vector<int> select_groups(const std::string& selector, const Character& body) {
  // A group of that name, and every group of that role (a name may be both: "neck").
  std::vector<int> out;
  const int named = body.find_group(selector);
  if (named >= 0) out.push_back(named);
  std::string role = selector;
  auto ends_with = [&](const std::string& tail) {
    return selector.size() > tail.size() && selector.compare(selector.size() - tail.size(), tail.size(), tail) == 0;
  };
  const bool top = ends_with(".top");
  // ROLE.sagittal, ROLE.coronal: the role's groups in that plane.
  const bool sagittal = ends_with(".sagittal"), coronal = ends_with(".coronal");
  if (top) role = selector.substr(0, selector.size() - 4);
  if (sagittal) role = selector.substr(0, selector.size() - 9);
  if (coronal) role = selector.substr(0, selector.size() - 8);
  size_t depth = 0;
  for (size_t g = 0; g < body.groups.size(); ++g) {
    if (role != to_string(body.groups[g].role)) continue;
    if (sagittal && body.groups[g].plane != JointPlane::kSagittal) continue;
    if (coronal && body.groups[g].plane != JointPlane::kCoronal) continue;
    if (!top) {
      if (static_cast<int>(g) != named) out.push_back(static_cast<int>(g));
      continue;
    }
    // The topmost: the group whose joint has the longest chain from the root.
    const size_t d = body.chain(body.groups[g].joints[0]).size();
    if (out.empty() || d > depth) {
      out = {static_cast<int>(g)};
      depth = d;
    }
  }
  return out;
}

namespace {

// The parameter list being built: a name used twice is one parameter.
int add_param(std::vector<ParamSpec>& params, const ParamSpec& spec, const std::string& file, int line,
              const std::string& field) {
  for (size_t i = 0; i < params.size(); ++i) {
    if (params[i].name != spec.name) continue;
    if (params[i].lower != spec.lower || params[i].upper != spec.upper) {
      throw_field_error(file + ": line " + std::to_string(line), field,
                        "expected the range of \"" + spec.name + "\" given before, [" + num(params[i].lower) + ", " +
                            num(params[i].upper) + "], got [" + num(spec.lower) + ", " + num(spec.upper) + "]");
    }
    return static_cast<int>(i);
  }
  params.push_back(spec);
  return static_cast<int>(params.size() - 1);
}

// `sides`: a parameter of a left/right pair is two, NAME_left and NAME_right.
std::string side_name(const SkillValue& v, const JointGroup& group, size_t side) {
  if (!v.sides || group.joints.size() != 2) return "";
  return side == 0 ? "_left" : "_right";
}

std::string replace_group(std::string name, const std::string& group) {
  const std::string key = "{group}";
  for (size_t at = name.find(key); at != std::string::npos; at = name.find(key)) name.replace(at, key.size(), group);
  return name;
}

}  // namespace

SkillBinding bind_skill(const SkillFile& skill, const Character& body, const mjModel* m) {
  const std::string& file = skill.file;
  auto fail = [&](int line, const std::string& field, const std::string& expectation) {
    throw_field_error(file + ": line " + std::to_string(line), field, expectation);
  };
  const std::string who = "the character " + body.spec->file;
  if (body.root != skill.root) {
    fail(skill.root_line, "root", std::string("expected a character with a ") + to_string(skill.root) + " root, but " + who + " has a " +
                        to_string(body.root) + " root");
  }
  for (const std::string& role : skill.pairs) {
    const auto groups = select_groups(role, body);
    if (groups.empty()) fail(skill.pairs_line, "pairs", "expected a joint group with role \"" + role + "\", but " + who + " has none");
    if (body.groups[static_cast<size_t>(groups[0])].joints.size() != 2) {
      fail(skill.pairs_line, "pairs", "expected a left/right pair in the \"" + role + "\" group (two legs), in " + who);
    }
  }

  SkillBinding b;
  b.phases.resize(skill.phases.size());
  // Targets and gains per phase, parameters in the documented order.
  for (size_t p = 0; p < skill.phases.size(); ++p) {
    const SkillPhase& phase = skill.phases[p];
    SkillPhaseBinding& pb = b.phases[p];
    pb.targets.assign(body.joints.size(), {});
    pb.gains.assign(body.joints.size(), {});
    const std::string prefix = (phase.parameters.empty() ? phase.name : phase.parameters) + ".";
    pb.swing = phase.swing;
    // Which entry of the set drives each group: named ones first, then "other".
    const auto& set = skill.target_sets.at(phase.targets);
    std::vector<const SkillTarget*> entry(body.groups.size(), nullptr);
    const SkillTarget* other = nullptr;
    // The root's pitch and roll first (heading frame, free roots).
    for (const SkillTarget& t : set) {
      if (t.selector != "root") continue;
      if (body.root != RootKind::kFree) fail(t.line, "targets." + phase.targets + ".root", "expected no root target: " + who + " has a planar root");
      pb.root = true;
      for (auto [v, jt, what] : {std::tuple{&t.pitch, &pb.root_pitch, "pitch"}, {&t.roll, &pb.root_roll, "roll"}}) {
        jt->world = SkillTarget::World::kHeading;
        jt->value = v;
        jt->sign = v->mirror && phase.swing == 1 ? -1.0 : 1.0;
        if (v->kind != SkillValue::Kind::kParam) continue;
        ParamSpec spec{prefix + v->param, v->has_range ? v->lower : -M_PI, v->has_range ? v->upper : M_PI, v->unit.empty() ? "rad" : v->unit};
        jt->param = add_param(b.params, spec, file, v->line, "targets." + phase.targets + ".root." + what);
      }
    }
    for (const SkillTarget& t : set) {
      if (t.selector == "root") continue;
      if (t.selector == "other") {
        other = &t;
        continue;
      }
      const auto groups = select_groups(t.selector, body);
      if (groups.empty()) {
        fail(t.line, "targets." + phase.targets + "." + t.selector,
             "expected a joint group, role or ROLE.top of " + who + ", got \"" + t.selector + "\" (it has none)");
      }
      for (int g : groups) {
        // A group named by name wins over one picked by role.
        if (entry[static_cast<size_t>(g)] == nullptr || t.selector == body.groups[static_cast<size_t>(g)].name) {
          entry[static_cast<size_t>(g)] = &t;
        }
      }
    }
    for (size_t g = 0; g < body.groups.size(); ++g) {
      const SkillTarget* t = entry[g] != nullptr ? entry[g] : other;
      const JointGroup& group = body.groups[g];
      if (t == nullptr) {
        fail(phase.line, "phases." + phase.name + ".targets",
             "expected a target for the group \"" + group.name + "\" in [targets." + phase.targets + "] (or an \"other\" entry)");
      }
      const std::string field = "targets." + phase.targets + "." + t->selector;
      if (t->by_role && phase.swing < 0) {
        fail(t->line, field, "expected a phase with a swing leg (swing = \"left\" or \"right\") for swing and stance targets, but phase \"" + phase.name + "\" has none");
      }
      if (t->by_role && group.joints.size() != 2) {
        fail(t->line, field, "expected a left/right pair for swing and stance targets, but the group \"" + group.name + "\" of " + who + " has one joint");
      }
      for (size_t side = 0; side < group.joints.size(); ++side) {
        const int j = group.joints[side];
        const SkillValue* v = &t->both;
        // Swing and stance: the swing leg's side holds the swing value.
        const bool second = group.joints.size() == 2 && side == 1;
        if (t->sided) v = (t->by_role ? (static_cast<int>(side) != phase.swing) : second) ? &t->right : &t->left;
        SkillJointTarget& jt = pb.targets[static_cast<size_t>(j)];
        jt.world = v->world >= 0 ? static_cast<SkillTarget::World>(v->world) : t->world;
        jt.value = v;
        jt.from_standing = t->from_standing;
        jt.sign = v->mirror && phase.swing == 1 ? -1.0 : 1.0;
        if (jt.world == SkillTarget::World::kHeading && body.root != RootKind::kFree) {
          fail(v->line, field, "expected world = \"joint\", \"parent\" or \"child\": heading-frame targets need a free root, but " + who + " has a planar root");
        }
        if ((jt.world == SkillTarget::World::kRoot || jt.world == SkillTarget::World::kTorso ||
             jt.world == SkillTarget::World::kSole) && body.root != RootKind::kFree) {
          fail(v->line, field, "expected world = \"joint\", \"parent\" or \"child\": the world pitches a stance3d module holds need a free root, but " + who + " has a planar root");
        }
        if (v->kind == SkillValue::Kind::kParam) {
          const CharacterJoint& joint = body.joints[static_cast<size_t>(group.joints[0])];
          ParamSpec spec{prefix + replace_group(v->param, group.name) + side_name(*v, group, side), v->lower, v->upper, v->unit.empty() ? "rad" : v->unit};
          if (!v->has_range) {
            spec.lower = std::isfinite(joint.lower) ? joint.lower : -M_PI;
            spec.upper = std::isfinite(joint.upper) ? joint.upper : M_PI;
          } else if (jt.world == SkillTarget::World::kHeading) {
            // Angles from standing: the range within what the joint allows from there.
            if (std::isfinite(joint.lower)) spec.lower = std::max(joint.lower - joint.standing, spec.lower);
            if (std::isfinite(joint.upper)) spec.upper = std::min(joint.upper - joint.standing, spec.upper);
          }
          jt.param = add_param(b.params, spec, file, v->line, "targets." + phase.targets + "." + t->selector);
        }
      }
    }
    // Gains: the set's entries, the character's gains for the groups it does not name.
    for (size_t j = 0; j < body.joints.size(); ++j) {
      const JointGroup& group = body.groups[static_cast<size_t>(body.joints[j].group)];
      pb.gains[j].kp = group.kp;
      pb.gains[j].kd = group.kd;
    }
    if (!phase.gains.empty()) {
      const auto& gains = skill.gain_sets.at(phase.gains);
      std::vector<const SkillGain*> gentry(body.groups.size(), nullptr);
      for (const SkillGain& g : gains) {
        const auto groups = select_groups(g.selector, body);
        if (groups.empty()) {
          fail(g.line, "gains." + phase.gains + "." + g.selector,
               "expected a joint group, role or ROLE.top of " + who + ", got \"" + g.selector + "\" (it has none)");
        }
        for (int k : groups) gentry[static_cast<size_t>(k)] = &g;
      }
      for (size_t g = 0; g < body.groups.size(); ++g) {
        const SkillGain* e = gentry[g];
        if (e == nullptr) continue;
        // kp, then kd; a sided parameter the left joint's, then the right's.
        const JointGroup& group = body.groups[g];
        for (const SkillValue* value : {&e->kp, &e->kd}) {
          for (size_t side = 0; side < group.joints.size(); ++side) {
            SkillJointGain& jg = b.phases[p].gains[static_cast<size_t>(group.joints[side])];
            int& index = value == &e->kp ? jg.kp_param : jg.kd_param;
            double& number = value == &e->kp ? jg.kp : jg.kd;
            index = -1;
            if (value->kind != SkillValue::Kind::kParam) {
              number = value->number;
              continue;
            }
            const ParamSpec spec{prefix + replace_group(value->param, group.name) + side_name(*value, group, side), value->lower,
                                 value->upper, value->unit.empty() ? (value == &e->kp ? "Nm/rad" : "Nm s/rad") : value->unit};
            index = add_param(b.params, spec, file, value->line, "gains." + phase.gains + "." + e->selector);
          }
        }
      }
    }
  }
  // Durations, phase by phase.
  for (size_t p = 0; p < skill.phases.size(); ++p) {
    const SkillDuration& d = skill.phases[p].duration;
    if (d.kind != SkillDuration::Kind::kValue || d.value.kind != SkillValue::Kind::kParam) continue;
    const SkillPhase& phase = skill.phases[p];
    const ParamSpec spec{(phase.parameters.empty() ? phase.name : phase.parameters) + "." + d.value.param, d.value.lower, d.value.upper,
                         d.value.unit.empty() ? "s" : d.value.unit};
    b.phases[p].duration_param = add_param(b.params, spec, file, d.value.line, "phases." + skill.phases[p].name + ".duration");
  }
  // Modules' parameters, module by module (full names).
  b.module_params.resize(skill.modules.size());
  for (size_t k = 0; k < skill.modules.size(); ++k) {
    for (const auto& [name, value] : skill.modules[k].settings) {
      int index = -1;
      if (value.kind == SkillValue::Kind::kParam) {
        index = add_param(b.params, {value.param, value.lower, value.upper, value.unit}, file, value.line,
                          "modules." + skill.modules[k].name + "." + name);
      }
      b.module_params[k][name] = index;
    }
  }
  for (size_t p = 0; p < skill.phases.size(); ++p) {
    for (const std::string& mod : skill.phases[p].modules) b.phases[p].modules.push_back(skill.module_index(mod));
  }
  // Joint groups the modules name.
  for (const SkillModuleSpec& mod : skill.modules) {
    for (const char* word : find_module_kind(mod.kind)->selectors) {
      const std::string& selector = mod.words.at(word);
      if (selector == "other" || selector == "root") {
        fail(mod.line, "modules." + mod.name + "." + word, "expected a joint group, role or ROLE.plane, got \"" + selector + "\" (a target set's word, not a selector here)");
      }
      if (select_groups(selector, body).empty()) {
        fail(mod.line, "modules." + mod.name + "." + word,
             "expected a joint group, role or ROLE.plane of " + who + ", got \"" + selector + "\" (it selects no group)");
      }
    }
  }
  // Feet by role need a swing leg.
  for (const SkillPhase& phase : skill.phases) {
    for (const SkillTransition& tr : phase.next) {
      for (const SkillCondition& c : tr.on) {
        if (c.kind == "contact_made" && c.foot == "swing") b.phases[static_cast<size_t>(skill.phase_index(phase.name))].swing_lands = true;
        if (c.type == SkillCondition::Type::kTurned && body.root == RootKind::kFree) {
          fail(tr.line, "phases." + phase.name + ".next.on",
               "expected a planar root for on = \"turned\" (the root's pitch coordinate), but " + who +
                   " has a free root: use on = \"feature\", feature = \"pitch\"");
        }
        if ((c.foot == "swing" || c.foot == "stance") && phase.swing < 0) {
          fail(tr.line, "phases." + phase.name + ".next.foot", "expected a phase with a swing leg (swing = \"left\" or \"right\") for foot = \"" + c.foot + "\"");
        }
      }
    }
  }
  // Bodies the transitions name.
  if (m != nullptr) {
    for (const SkillPhase& phase : skill.phases) {
      for (const SkillTransition& tr : phase.next) {
        for (const SkillCondition& c : tr.on) {
          if (c.body.empty()) continue;
          const int id = mj_name2id(m, mjOBJ_BODY, c.body.c_str());
          if (id < 0 || !body.is_link(m, id)) {
            fail(tr.line, "phases." + phase.name + ".next.body", "expected a body of " + who + ", got \"" + c.body + "\" (no such body)");
          }
        }
      }
    }
  }
  return b;
}

}  // namespace diverse
