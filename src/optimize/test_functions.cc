#include "optimize/test_functions.h"

#include <array>
#include <cmath>
#include <numbers>

namespace diverse {
namespace {

constexpr std::array<TestProblem, 4> kProblems{{
    {"sphere", sphere, 0.5},
    {"ellipsoid", ellipsoid, 0.5},
    {"rosenbrock", rosenbrock, 0.0},
    {"rastrigin", rastrigin, 0.5},
}};

}  // namespace

double sphere(const Eigen::VectorXd& x) { return x.squaredNorm(); }

double ellipsoid(const Eigen::VectorXd& x) {
  const Eigen::Index n = x.size();
  double f = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double exponent = n > 1 ? static_cast<double>(i) / static_cast<double>(n - 1) : 0.0;
    f += std::pow(1e6, exponent) * x[i] * x[i];
  }
  return f;
}

double rosenbrock(const Eigen::VectorXd& x) {
  double f = 0;
  for (Eigen::Index i = 0; i + 1 < x.size(); ++i) {
    const double a = x[i + 1] - x[i] * x[i];
    const double b = 1 - x[i];
    f += 100 * a * a + b * b;
  }
  return f;
}

double rastrigin(const Eigen::VectorXd& x) {
  double f = 10.0 * static_cast<double>(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    f += x[i] * x[i] - 10 * std::cos(2 * std::numbers::pi * x[i]);
  }
  return f;
}

const TestProblem* find_test_problem(std::string_view name) {
  for (const auto& p : kProblems) {
    if (name == p.name) return &p;
  }
  return nullptr;
}

std::vector<std::string> test_problem_names() {
  std::vector<std::string> names;
  for (const auto& p : kProblems) names.emplace_back(p.name);
  return names;
}

}  // namespace diverse
