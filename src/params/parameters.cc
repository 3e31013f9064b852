#include "params/parameters.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/error.h"

namespace diverse {
namespace {

std::string range_text(const ParamSpec& s) {
  std::ostringstream out;
  out << "expected a number in [" << s.lower << ", " << s.upper << "]";
  if (!s.unit.empty()) out << " " << s.unit;
  return out.str();
}

}  // namespace

ParameterSet::ParameterSet(std::vector<ParamSpec> specs, std::vector<double> values)
    : specs_(std::move(specs)), values_(std::move(values)) {
  if (values_.size() != specs_.size()) throw std::logic_error("ParameterSet: size mismatch");
}

int ParameterSet::find(const std::string& name) const {
  for (size_t i = 0; i < specs_.size(); ++i) {
    if (specs_[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

double ParameterSet::get(const std::string& name) const {
  const int i = find(name);
  if (i < 0) throw std::out_of_range("no parameter " + name);
  return values_[i];
}

void ParameterSet::set(const std::string& name, double value) {
  const int i = find(name);
  if (i < 0) throw std::out_of_range("no parameter " + name);
  values_[i] = value;
}

Eigen::VectorXd ParameterSet::normalized() const {
  Eigen::VectorXd x(size());
  for (int i = 0; i < size(); ++i) {
    x[i] = (values_[i] - specs_[i].lower) / (specs_[i].upper - specs_[i].lower);
  }
  return x;
}

void ParameterSet::set_normalized(const Eigen::VectorXd& x) {
  if (x.size() != size()) throw std::logic_error("ParameterSet: normalized vector size mismatch");
  for (int i = 0; i < size(); ++i) {
    // x = 1 maps to the upper bound exactly: lower + 1 * (upper - lower) can round past
    // it, and a value past its bound is refused when the parameters are read back.
    values_[i] = x[i] == 1.0 ? specs_[i].upper
                             : specs_[i].lower + x[i] * (specs_[i].upper - specs_[i].lower);
  }
}

nlohmann::json ParameterSet::to_json() const {
  nlohmann::json object = nlohmann::json::object();
  for (int i = 0; i < size(); ++i) object[specs_[i].name] = values_[i];
  return object;
}

void ParameterSet::set_from_json(const nlohmann::json& object, const std::string& origin) {
  if (!object.is_object()) {
    throw_field_error(origin, "parameters", "expected an object mapping parameter names to numbers");
  }
  for (const auto& [name, value] : object.items()) {
    (void)value;
    if (find(name) >= 0) continue;
    // A parameter that this controller splits in two (a skill's `sides = true`: NAME_left and
    // NAME_right) is named so that a file written for the shared one says what to do.
    std::string split;
    for (const ParamSpec& s : specs_) {
      if (s.name.size() > name.size() && s.name.compare(0, name.size() + 1, name + "_") == 0) {
        split += (split.empty() ? "" : ", ") + s.name;
      }
    }
    throw_field_error(origin, "parameters." + name,
                      split.empty() ? "expected a known parameter name (unknown parameter)"
                                    : "expected a known parameter name (unknown parameter; this controller has " +
                                          split + " instead)");
  }
  for (int i = 0; i < size(); ++i) {
    const ParamSpec& s = specs_[i];
    auto it = object.find(s.name);
    if (it == object.end()) throw_field_error(origin, "parameters." + s.name, range_text(s));
    if (!it->is_number()) throw_field_error(origin, "parameters." + s.name, range_text(s));
    const double v = it->get<double>();
    if (!std::isfinite(v) || v < s.lower || v > s.upper) {
      throw_field_error(origin, "parameters." + s.name, range_text(s));
    }
    values_[i] = v;
  }
}

}  // namespace diverse
