#include "character/shape.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <system_error>

#include "core/error.h"

namespace diverse {
namespace {

// Shortest text that reads back as the same double.
std::string format_number(double v) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), v);
  return std::string(buffer, result.ptr);
}

// ---------------------------------------------------------------------------------------
// A small XML reader: elements, their attributes with the span of each value in the text,
// and the tree. Comments, processing instructions, declarations and CDATA are skipped;
// text content is ignored. Enough for MJCF, which uses nothing else.

struct XmlAttr {
  std::string name, value;
  size_t begin = 0, end = 0;  // value span in the text (between the quotes)
};

struct XmlElement {
  std::string name;
  size_t offset = 0;  // position of '<'
  int parent = -1;
  std::vector<XmlAttr> attrs;
  std::vector<int> children;
  const XmlAttr* attr(const char* key) const {
    for (const XmlAttr& a : attrs) {
      if (a.name == key) return &a;
    }
    return nullptr;
  }
};

class XmlReader {
 public:
  XmlReader(const std::string& text, const std::string& origin) : s_(text), origin_(origin) {}

  std::vector<XmlElement> read() {
    std::vector<XmlElement> out;
    std::vector<int> open;
    size_t i = 0;
    const size_t n = s_.size();
    while (i < n) {
      if (s_[i] != '<') {
        i = s_.find('<', i);
        if (i == std::string::npos) break;
        continue;
      }
      if (starts(i, "<!--")) {
        i = skip_past(i, "-->", "an unterminated comment");
      } else if (starts(i, "<![CDATA[")) {
        i = skip_past(i, "]]>", "an unterminated CDATA section");
      } else if (starts(i, "<?")) {
        i = skip_past(i, "?>", "an unterminated processing instruction");
      } else if (starts(i, "<!")) {
        i = skip_past(i, ">", "an unterminated declaration");
      } else if (starts(i, "</")) {
        size_t p = i + 2;
        const std::string name = read_name(p);
        skip_space(p);
        if (p >= n || s_[p] != '>') fail(i, "expected '>' to close </" + name);
        if (open.empty() || out[open.back()].name != name) {
          fail(i, "</" + name + "> does not close the open element");
        }
        open.pop_back();
        i = p + 1;
      } else {
        i = read_start_tag(i, out, open);
      }
    }
    if (!open.empty()) fail(out[open.back()].offset, "<" + out[open.back()].name + "> is never closed");
    return out;
  }

 private:
  bool starts(size_t at, const char* prefix) const {
    return s_.compare(at, std::strlen(prefix), prefix) == 0;
  }

  size_t skip_past(size_t at, const char* end, const char* what) const {
    const size_t e = s_.find(end, at + 1);
    if (e == std::string::npos) fail(at, std::string("expected the end of ") + what);
    return e + std::strlen(end);
  }

  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
  void skip_space(size_t& p) const {
    while (p < s_.size() && is_space(s_[p])) ++p;
  }
  std::string read_name(size_t& p) const {
    const size_t begin = p;
    while (p < s_.size() && !is_space(s_[p]) && s_[p] != '/' && s_[p] != '>' && s_[p] != '=' &&
           s_[p] != '<' && s_[p] != '"' && s_[p] != '\'') {
      ++p;
    }
    return s_.substr(begin, p - begin);
  }

  size_t read_start_tag(size_t at, std::vector<XmlElement>& out, std::vector<int>& open) const {
    XmlElement element;
    element.offset = at;
    element.parent = open.empty() ? -1 : open.back();
    size_t p = at + 1;
    element.name = read_name(p);
    if (element.name.empty()) fail(at, "expected an element name after '<'");
    bool closed = false;
    for (;;) {
      skip_space(p);
      if (p >= s_.size()) fail(at, "<" + element.name + " is not terminated");
      if (s_[p] == '>') {
        ++p;
        break;
      }
      if (s_[p] == '/') {
        if (p + 1 >= s_.size() || s_[p + 1] != '>') fail(p, "expected '/>'");
        p += 2;
        closed = true;
        break;
      }
      XmlAttr attr;
      attr.name = read_name(p);
      if (attr.name.empty()) fail(p, "expected an attribute name in <" + element.name + ">");
      skip_space(p);
      if (p >= s_.size() || s_[p] != '=') fail(p, "expected '=' after attribute " + attr.name);
      ++p;
      skip_space(p);
      if (p >= s_.size() || (s_[p] != '"' && s_[p] != '\'')) {
        fail(p, "expected a quoted value for attribute " + attr.name);
      }
      const char quote = s_[p];
      attr.begin = p + 1;
      attr.end = s_.find(quote, attr.begin);
      if (attr.end == std::string::npos) fail(p, "unterminated value of attribute " + attr.name);
      attr.value = s_.substr(attr.begin, attr.end - attr.begin);
      p = attr.end + 1;
      if (element.attr(attr.name.c_str()) != nullptr) fail(at, "attribute " + attr.name + " given twice");
      element.attrs.push_back(std::move(attr));
    }
    const int index = static_cast<int>(out.size());
    if (element.parent >= 0) out[element.parent].children.push_back(index);
    out.push_back(std::move(element));
    if (!closed) open.push_back(index);
    return p;
  }

  [[noreturn]] void fail(size_t at, const std::string& what) const {
    const long line =
        1 + std::count(s_.begin(), s_.begin() + static_cast<long>(std::min(at, s_.size())), '\n');
    throw UserError(origin_ + ": line " + std::to_string(line) + ": malformed XML: " + what);
  }

  const std::string& s_;
  const std::string& origin_;
};

// Whitespace-separated numbers of an attribute value.
std::vector<double> parse_numbers(const XmlAttr& a, const std::string& where) {
  std::vector<double> values;
  const char* p = a.value.data();
  const char* end = p + a.value.size();
  for (;;) {
    while (p < end && std::strchr(" \t\n\r", *p) != nullptr) ++p;
    if (p == end) break;
    double v = 0;
    const auto result = std::from_chars(p, end, v);
    if (result.ec != std::errc() || !std::isfinite(v)) {
      throw UserError(where + ": " + a.name + ": expected numbers, got \"" + a.value + "\"");
    }
    values.push_back(v);
    p = result.ptr;
  }
  return values;
}

}  // namespace

void require_shape(const CharacterSpec& spec) {
  if (!spec.has_shape()) {
    throw UserError(spec.file +
                    ": shape: expected [shape] parameters in the character file for --vary shape "
                    "(this character has none)");
  }
  if (spec.root != RootKind::kPlanar) {
    throw UserError(spec.file + ": shape: expected a planar character (the shape rules scale the sagittal plane)");
  }
}

ShapeSpace::ShapeSpace(std::string base_xml, const CharacterSpec& spec, std::string origin)
    : xml_(std::move(base_xml)), origin_(std::move(origin)) {
  require_shape(spec);
  const std::vector<XmlElement> doc = XmlReader(xml_, origin_).read();
  auto child_named = [&](int parent, const char* name) {
    const std::vector<int>* list = nullptr;
    std::vector<int> roots;
    if (parent < 0) {
      for (int i = 0; i < static_cast<int>(doc.size()); ++i) {
        if (doc[i].parent < 0) roots.push_back(i);
      }
      list = &roots;
    } else {
      list = &doc[parent].children;
    }
    for (int c : *list) {
      if (doc[c].name == name) return c;
    }
    return -1;
  };
  const int mujoco = child_named(-1, "mujoco");
  if (mujoco < 0) throw UserError(origin_ + ": expected a <mujoco> element");
  const int world = child_named(mujoco, "worldbody");
  if (world < 0) throw UserError(origin_ + ": expected a <worldbody> element");

  // Geom type of the main default class (MJCF's own default is a sphere).
  std::string default_type = "sphere";
  const int defaults = child_named(mujoco, "default");
  if (defaults >= 0) {
    const XmlAttr* cls = doc[defaults].attr("class");
    if (cls != nullptr && cls->value != "main") {
      throw UserError(origin_ + ": <default class=\"" + cls->value + "\">: expected the main class");
    }
    const int g = child_named(defaults, "geom");
    if (g >= 0 && doc[g].attr("type") != nullptr) default_type = doc[g].attr("type")->value;
  }

  // The root link: the character file's root body, directly in the world.
  int root = -1;
  for (int c : doc[world].children) {
    const XmlAttr* name = doc[c].attr("name");
    if (doc[c].name == "body" && name != nullptr && name->value == spec.root_body) root = c;
  }
  if (root < 0) throw UserError(origin_ + ": body '" + spec.root_body + "': expected it in <worldbody>");

  constexpr const char* kRotations[] = {"quat", "axisangle", "euler", "xyaxes", "zaxis"};
  auto where = [&](int e) {
    const XmlAttr* name = doc[e].attr("name");
    return origin_ + ": " + doc[e].name + " '" + (name != nullptr ? name->value : "?") + "'";
  };
  auto check_plain = [&](int e) {
    for (const char* key : kRotations) {
      if (doc[e].attr(key) != nullptr) {
        throw UserError(where(e) + ": " + key +
                        ": expected no rotation (the shape rules scale axis-aligned frames)");
      }
    }
    if (doc[e].attr("class") != nullptr || doc[e].attr("childclass") != nullptr) {
      throw UserError(where(e) + ": expected no default class (the shape rules read the main class only)");
    }
  };
  auto add_edit = [&](const XmlAttr& a, int link, EditKind kind, const std::string& at, size_t count) {
    Edit edit;
    edit.begin = a.begin;
    edit.end = a.end;
    edit.values = parse_numbers(a, at);
    if (edit.values.size() != count) {
      throw UserError(at + ": " + a.name + ": expected " + std::to_string(count) + " numbers, got \"" +
                      a.value + "\"");
    }
    edit.link = link;
    edit.kind = kind;
    edits_.push_back(edit);
    return edits_.back().values;
  };

  // Walk the character's bodies in document order (MuJoCo's body order).
  struct Visit {
    int element, parent_link;
  };
  std::vector<Visit> stack = {{root, -1}};
  while (!stack.empty()) {
    const Visit v = stack.back();
    stack.pop_back();
    const XmlElement& body = doc[v.element];
    check_plain(v.element);
    const XmlAttr* name = body.attr("name");
    const std::string body_name = name != nullptr ? name->value : "";
    for (const Link& l : links_) {
      if (!body_name.empty() && l.name == body_name)
        throw UserError(origin_ + ": body '" + body_name + "': expected it once");
    }
    Link link;
    link.name = body_name;
    link.parent = v.parent_link;
    link.foot = (v.parent_link >= 0 && links_[static_cast<size_t>(v.parent_link)].foot) ||
                (!body_name.empty() && (body_name == spec.feet[0] || body_name == spec.feet[1]));
    const int self = static_cast<int>(links_.size());
    const std::string at = where(v.element);
    if (const XmlAttr* pos = body.attr("pos")) {
      const EditKind k = v.parent_link < 0 ? EditKind::kRootHeight : EditKind::kSagittal;
      const std::vector<double> p = add_edit(*pos, v.parent_link < 0 ? self : v.parent_link, k, at, 3);
      link.offset = Eigen::Vector2d(p[0], p[2]);
      if (v.parent_link < 0) root_z_ = p[2];
    } else if (v.parent_link < 0) {
      throw UserError(at + ": pos: expected the root's start position");
    }

    std::vector<int> child_bodies;
    for (int c : body.children) {
      const XmlElement& e = doc[c];
      const std::string eat = where(c);
      if (e.name == "body") {
        child_bodies.push_back(c);
      } else if (e.name == "inertial") {
        throw UserError(at + ": <inertial>: expected none (inertia follows the geometry, inertiafromgeom)");
      } else if (e.name == "geom") {
        check_plain(c);
        if (e.attr("mass") == nullptr) {
          throw UserError(eat + ": expected a mass attribute (link masses stay fixed when shapes change)");
        }
        const std::string type = e.attr("type") != nullptr ? e.attr("type")->value : default_type;
        const XmlAttr* size = e.attr("size");
        if (size == nullptr) throw UserError(eat + ": expected a size attribute");
        const std::vector<double> sz = parse_numbers(*size, eat);
        if (sz.empty()) throw UserError(eat + ": size: expected a radius");
        Primitive prim;
        prim.radius = sz[0];
        if (type == "capsule" || type == "cylinder") {
          const XmlAttr* fromto = e.attr("fromto");
          if (fromto == nullptr || e.attr("pos") != nullptr) {
            throw UserError(eat + ": expected a capsule given by fromto (and no pos)");
          }
          const std::vector<double> f = add_edit(*fromto, self, EditKind::kSagittal, eat, 6);
          prim.a = Eigen::Vector2d(f[0], f[2]);
          prim.b = Eigen::Vector2d(f[3], f[5]);
        } else if (type == "sphere") {
          prim.sphere = true;
          if (const XmlAttr* pos = e.attr("pos")) {
            const std::vector<double> p = add_edit(*pos, self, EditKind::kSagittal, eat, 3);
            prim.a = Eigen::Vector2d(p[0], p[2]);
          }
          add_edit(*size, self, EditKind::kUniform, eat, 1);
        } else {
          throw UserError(eat + ": type " + type +
                          ": expected a capsule, cylinder or sphere (the shape rules cover those)");
        }
        link.primitives.push_back(prim);
      } else if (const XmlAttr* pos = e.attr("pos")) {
        // Joints, sites, cameras: their anchor moves with the link.
        add_edit(*pos, self, EditKind::kSagittal, eat, 3);
      }
    }
    links_.push_back(std::move(link));
    for (auto it = child_bodies.rbegin(); it != child_bodies.rend(); ++it) stack.push_back({*it, self});
  }
  // The parameters' links, and the feet, must be links of the character.
  auto find_link = [&](const std::string& name) {
    for (size_t i = 0; i < links_.size(); ++i) {
      if (links_[i].name == name) return static_cast<int>(i);
    }
    return -1;
  };
  auto not_a_link = [&](const std::string& field, const std::string& name) {
    const bool in_model = std::any_of(doc.begin(), doc.end(), [&](const XmlElement& e) {
      return e.name == "body" && e.attr("name") != nullptr && e.attr("name")->value == name;
    });
    if (!in_model) {
      throw UserError(spec.file + ": " + field + ": expected a body of the model " + origin_ +
                      ", but it has no body '" + name + "'");
    }
    throw UserError(spec.file + ": " + field + ": expected a link of the character (a body inside '" +
                    spec.root_body + "'), got '" + name + "'");
  };
  const int num_params = static_cast<int>(spec.shape.size());
  for (int p = 0; p < num_params; ++p) {
    for (const std::string& name : spec.shape[static_cast<size_t>(p)].links) {
      const int i = find_link(name);
      if (i < 0) not_a_link("shape.parameters[" + std::to_string(p) + "].links", name);
      links_[static_cast<size_t>(i)].param = p;
    }
  }
  for (const std::string& name : spec.feet) {
    if (find_link(name) < 0) not_a_link("feet.bodies", name);
  }
  std::sort(edits_.begin(), edits_.end(), [](const Edit& a, const Edit& b) { return a.begin < b.begin; });

  // Base link lengths: to the farthest child origin, or the end link's own geometry.
  const int num_links = static_cast<int>(links_.size());
  base_lengths_.resize(num_links);
  for (int i = 0; i < num_links; ++i) {
    double length = 0;
    bool has_child = false;
    for (const Link& l : links_) {
      if (l.parent == i) {
        has_child = true;
        length = std::max(length, l.offset.norm());
      }
    }
    if (!has_child) {
      for (const Primitive& p : links_[i].primitives) {
        length = std::max(length, p.sphere ? p.a.norm() + p.radius : (p.b - p.a).norm());
      }
    }
    if (!(length > 0) && links_[i].param >= 0)
      throw UserError(origin_ + ": body '" + links_[i].name + "': expected a length > 0 to scale");
    base_lengths_[i] = length;
    link_names_.push_back(links_[i].name);
    link_params_.push_back(links_[i].param);
  }

  // Ranges: the character file's [min, max] (the paper's [0.4, 2.5]), the lower bound
  // raised where min would make a link shorter than the minimum link length; rounded up
  // to 0.001 so that the bound prints exactly.
  const double min_length = spec.shape_min_link_length;
  for (int p = 0; p < num_params; ++p) {
    const ShapeGroupSpec& group = spec.shape[static_cast<size_t>(p)];
    double shortest = std::numeric_limits<double>::infinity();
    for (int i = 0; i < num_links; ++i) {
      if (links_[i].param == p) shortest = std::min(shortest, base_lengths_[i]);
    }
    const double needed = std::ceil(min_length / shortest * 1000.0 - 1e-9) / 1000.0;
    const double lower = std::max(group.min, needed);
    if (lower > group.max) {
      throw UserError(origin_ + ": shape." + group.name + ": links too short to scale (below " +
                      format_number(min_length / group.max) + " m)");
    }
    specs_.push_back(ParamSpec{"shape." + group.name, lower, group.max, "scale"});
  }
  base_feet_low_ = extent(identity()).feet_low;
  if (!std::isfinite(base_feet_low_)) {
    throw UserError(spec.file + ": feet.bodies: expected a geom on the feet (the shaped character stands on them)");
  }
}

Eigen::VectorXd ShapeSpace::scales_from(const ParameterSet& params) const {
  Eigen::VectorXd scales(size());
  for (int p = 0; p < size(); ++p) scales[p] = params.get(specs_[static_cast<size_t>(p)].name);
  return scales;
}

Eigen::VectorXd ShapeSpace::link_lengths(const Eigen::VectorXd& scales) const {
  Eigen::VectorXd lengths(base_lengths_.size());
  for (int i = 0; i < base_lengths_.size(); ++i) lengths[i] = scale(scales, i) * base_lengths_[i];
  return lengths;
}

void ShapeSpace::validate(const Eigen::VectorXd& scales, const std::string& origin) const {
  if (scales.size() != size()) {
    throw std::invalid_argument("ShapeSpace: expected " + std::to_string(size()) + " scales, got " +
                                std::to_string(scales.size()));
  }
  for (int p = 0; p < size(); ++p) {
    const ParamSpec& s = specs_[static_cast<size_t>(p)];
    const double v = scales[p];
    if (!(v >= s.lower && v <= s.upper)) {
      throw UserError(origin + ": " + s.name + ": expected a scale in [" + format_number(s.lower) + ", " +
                      format_number(s.upper) + "], got " + format_number(v));
    }
  }
}

// Extents of the standing pose (all joints 0) relative to the root's origin: every frame
// is axis-aligned, so a link's origin is the sum of the scaled offsets above it.
ShapeSpace::Extent ShapeSpace::extent(const Eigen::VectorXd& scales) const {
  const double inf = std::numeric_limits<double>::infinity();
  Extent e{inf, inf, -inf};
  std::vector<double> origin_z(links_.size(), 0.0);
  for (size_t i = 0; i < links_.size(); ++i) {
    const Link& l = links_[i];
    if (l.parent >= 0) origin_z[i] = origin_z[l.parent] + scale(scales, l.parent) * l.offset[1];
    const double r = scale(scales, static_cast<int>(i));
    for (const Primitive& p : l.primitives) {
      double low = 0, high = 0;
      if (p.sphere) {
        low = r * p.a[1] - r * p.radius;
        high = r * p.a[1] + r * p.radius;
      } else {
        low = std::min(r * p.a[1], r * p.b[1]) - p.radius;
        high = std::max(r * p.a[1], r * p.b[1]) + p.radius;
      }
      low += origin_z[i];
      high += origin_z[i];
      if (l.foot) {
        e.feet_low = std::min(e.feet_low, low);
      } else {
        e.other_low = std::min(e.other_low, low);
      }
      e.top = std::max(e.top, high);
    }
  }
  return e;
}

StandingShape ShapeSpace::standing(const Eigen::VectorXd& scales) const {
  const Extent e = extent(scales);
  StandingShape s;
  // The feet's lowest point stays where the base model has it; at scale 1 the difference
  // is exactly 0, so the base start height is reproduced bit for bit.
  s.pelvis_z = root_z_ + (base_feet_low_ - e.feet_low);
  s.feet_z = s.pelvis_z + e.feet_low;
  s.lowest_other_z = s.pelvis_z + e.other_low;
  s.height = e.top - e.feet_low;
  return s;
}

std::string ShapeSpace::xml(const Eigen::VectorXd& scales, const std::string& origin) const {
  validate(scales, origin);
  const double pelvis_z = standing(scales).pelvis_z;
  std::string out;
  out.reserve(xml_.size() + 256);
  size_t copied = 0;
  std::vector<double> values;
  for (const Edit& edit : edits_) {
    out.append(xml_, copied, edit.begin - copied);
    copied = edit.end;
    values = edit.values;
    const double r = scale(scales, edit.link);
    for (size_t k = 0; k < values.size(); ++k) {
      switch (edit.kind) {
        case EditKind::kSagittal:
          if (k % 3 != 1) values[k] *= r;  // x and z; y (lateral) stays
          break;
        case EditKind::kUniform:
          values[k] *= r;
          break;
        case EditKind::kRootHeight:
          if (k == 2) values[k] = pelvis_z;
          break;
      }
    }
    if (values == edit.values) {
      out.append(xml_, edit.begin, edit.end - edit.begin);  // unchanged: keep the text
      continue;
    }
    for (size_t k = 0; k < values.size(); ++k) {
      if (k > 0) out += ' ';
      out += format_number(values[k]);
    }
  }
  out.append(xml_, copied, std::string::npos);
  return out;
}

std::shared_ptr<const SharedModel> ShapeSpace::compile(const Eigen::VectorXd& scales,
                                                       const std::string& origin) const {
  return SharedModel::from_xml(xml(scales, origin), origin_);
}

std::string shaped_model_xml(const std::string& base_xml, const CharacterSpec& spec,
                             const Eigen::VectorXd& scales) {
  return ShapeSpace(base_xml, spec).xml(scales);
}

}  // namespace diverse
