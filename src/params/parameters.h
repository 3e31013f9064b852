// Named, ranged controller parameters and their normalized form.
//
// Every free parameter of a controller has a name, a unit and a range [lower, upper].
// The optimizer sees the normalized vector x = (value - lower) / (upper - lower) (paper
// section 6; SPEC 2.2): coordinates in [0, 1] when the value is in range. The map is
// linear and never clips; what happens outside [0, 1] is the optimizer's business (our
// CMA-ES reflects at the bounds), and the task evaluator rejects out-of-range vectors.
//
// Files store parameters by name (JSON object name -> value), so a parameter file stays
// readable and survives a change of order.
#pragma once

#include <Eigen/Dense>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace diverse {

struct ParamSpec {
  std::string name;   // e.g. "crouch.knee"
  double lower = 0;   // range, in `unit`
  double upper = 1;
  std::string unit;   // "rad", "s", "Nm/rad", ...
};

class ParameterSet {
 public:
  ParameterSet() = default;
  ParameterSet(std::vector<ParamSpec> specs, std::vector<double> values);

  int size() const { return static_cast<int>(specs_.size()); }
  const std::vector<ParamSpec>& specs() const { return specs_; }
  const std::vector<double>& values() const { return values_; }
  std::vector<double>& values() { return values_; }

  // Index of a parameter, or -1.
  int find(const std::string& name) const;
  double get(const std::string& name) const;      // throws std::out_of_range
  void set(const std::string& name, double value);  // throws std::out_of_range

  Eigen::VectorXd normalized() const;
  void set_normalized(const Eigen::VectorXd& x);  // linear map, no clipping

  // {"name": value, ...} with every parameter.
  nlohmann::json to_json() const;
  // Strict: every parameter present, no unknown names, finite numbers inside their
  // ranges. Errors are UserError "ORIGIN: parameters.NAME: expected ..."; an unknown NAME
  // whose NAME_* parameters exist (a left/right pair split in two) names them..
  void set_from_json(const nlohmann::json& object, const std::string& origin);

 private:
  std::vector<ParamSpec> specs_;
  std::vector<double> values_;
};

}  // namespace diverse
