// Classic test functions for optimizers, shared by tests, benchmarks and
// `diverse cmaes`.
//
// Definitions as in N. Hansen's pycma (cma.ff) and the CMA-ES reference figures in
// docs/reference/cmaes.md; all minima are 0:
//   sphere      f = sum x_i^2                                      min at 0
//   ellipsoid   f = sum 1e6^((i-1)/(n-1)) x_i^2  (i = 1..n)         min at 0
//   rosenbrock  f = sum_{i<n} 100 (x_{i+1} - x_i^2)^2 + (1 - x_i)^2  min at (1, .., 1)
//   rastrigin   f = 10 n + sum x_i^2 - 10 cos(2 pi x_i)            min at 0
#pragma once

#include <Eigen/Dense>
#include <string>
#include <string_view>
#include <vector>

namespace diverse {

double sphere(const Eigen::VectorXd& x);
double ellipsoid(const Eigen::VectorXd& x);  // n = 1: x^2
double rosenbrock(const Eigen::VectorXd& x);
double rastrigin(const Eigen::VectorXd& x);

using TestFunction = double (*)(const Eigen::VectorXd&);

// A named function and the conventional start: x0 = start in every coordinate
// (0.5, Rosenbrock 0).
struct TestProblem {
  const char* name;
  TestFunction f;
  double start;
};

// The problem called `name`, or nullptr.
const TestProblem* find_test_problem(std::string_view name);
// All names, in a fixed order (for messages).
std::vector<std::string> test_problem_names();

}  // namespace diverse
