// `diverse cmaes`: runs the CMA-ES on a classic test function and prints one JSON
// object (evaluations, generations, best_f, reached_target, stop_reason, ...).
// This is how the optimizer is checked against the reference implementations;
// docs/reference/cmaes.md has the loop that produces its table.
#include <CLI/CLI.hpp>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <memory>
#include <string>
#include <system_error>

#include "command.h"
#include "core/error.h"
#include "optimize/cmaes.h"
#include "optimize/test_functions.h"

namespace diverse::cli {
namespace {

// Limits that keep the n x n matrices and the n x lambda samples within memory.
constexpr long long kMaxDim = 1000;
constexpr long long kMaxPopsize = 10000;

struct CmaesArgs {
  std::string function;
  std::string dim;
  std::string seed = "1";
  std::string popsize;
  std::string sigma0 = "0.5";
  std::string target = "1e-10";
  std::string max_evals;
  bool no_active = false;
};

[[noreturn]] void bad_value(const std::string& flag, const std::string& expectation,
                            const std::string& text) {
  throw UserError(flag + ": expected " + expectation + ", got '" + text + "'");
}

long long parse_integer(const std::string& flag, const std::string& text, long long min,
                        long long max, const std::string& expectation) {
  long long v = 0;
  const char* end = text.data() + text.size();
  const auto result = std::from_chars(text.data(), end, v);
  if (text.empty() || result.ec != std::errc() || result.ptr != end || v < min || v > max) {
    bad_value(flag, expectation, text);
  }
  return v;
}

std::uint64_t parse_seed(const std::string& text) {
  std::uint64_t v = 0;
  const char* end = text.data() + text.size();
  const auto result = std::from_chars(text.data(), end, v);
  if (text.empty() || result.ec != std::errc() || result.ptr != end) {
    bad_value("--seed", "an integer from 0 to 18446744073709551615", text);
  }
  return v;
}

double parse_number(const std::string& flag, const std::string& text, bool positive) {
  double v = 0;
  const char* end = text.data() + text.size();
  const auto result = std::from_chars(text.data(), end, v);
  if (text.empty() || result.ec != std::errc() || result.ptr != end || !std::isfinite(v) ||
      (positive && !(v > 0))) {
    bad_value(flag, positive ? "a positive number" : "a finite number", text);
  }
  return v;
}

void run(const CmaesArgs& args) {
  const TestProblem* problem = find_test_problem(args.function);
  if (problem == nullptr) {
    std::string names;
    for (const auto& name : test_problem_names()) names += (names.empty() ? "" : ", ") + name;
    throw UserError("--function: unknown function '" + args.function + "'; expected one of " +
                    names);
  }
  CmaesOptions options;
  options.dim = static_cast<int>(parse_integer("--dim", args.dim, 1, kMaxDim,
                                               "an integer from 1 to " + std::to_string(kMaxDim)));
  options.seed = parse_seed(args.seed);
  if (!args.popsize.empty()) {
    options.popsize =
        static_cast<int>(parse_integer("--popsize", args.popsize, 2, kMaxPopsize,
                                       "an integer from 2 to " + std::to_string(kMaxPopsize)));
  }
  options.sigma0 = parse_number("--sigma0", args.sigma0, true);
  options.target_f = parse_number("--target", args.target, false);
  const long long n = options.dim;
  options.max_evaluations = args.max_evals.empty() ? std::max(10000LL, 1000 * n * n)
                                                   : parse_integer("--max-evals", args.max_evals, 1,
                                                                   1LL << 53, "a positive integer");
  options.active = !args.no_active;

  Cmaes es(options, Eigen::VectorXd::Constant(options.dim, problem->start));
  std::vector<double> fitness(es.popsize());
  while (es.stop_reason() == StopReason::kNone) {
    const auto& xs = es.ask();
    for (size_t k = 0; k < xs.size(); ++k) fitness[k] = problem->f(xs[k]);
    es.tell(fitness);
  }

  nlohmann::json best_x = nlohmann::json::array();
  for (Eigen::Index i = 0; i < es.best_x().size(); ++i) best_x.push_back(es.best_x()[i]);
  const nlohmann::json out = {
      {"function", problem->name},
      {"dim", options.dim},
      {"seed", options.seed},
      {"popsize", es.popsize()},
      {"sigma0", options.sigma0},
      {"active", options.active},
      {"target", options.target_f},
      {"max_evaluations", options.max_evaluations},
      {"evaluations", es.evaluations()},
      {"generations", es.generation()},
      {"best_f", es.best_f()},
      {"reached_target", es.best_f() <= options.target_f},
      {"stop_reason", to_string(es.stop_reason())},
      {"sigma", es.sigma()},
      {"condition", es.condition_number()},
      {"best_x", best_x},
  };
  std::cout << out.dump() << "\n";
}

void add_cmaes(CLI::App& app) {
  auto args = std::make_shared<CmaesArgs>();
  CLI::App* sub = app.add_subcommand(
      "cmaes", "Run CMA-ES on a test function and print the result as one JSON object");
  sub->footer("Example:\n"
              "  diverse cmaes --function rosenbrock --dim 10 --seed 3");
  sub->add_option("--function", args->function,
                  "Test function: sphere, ellipsoid, rosenbrock or rastrigin")
      ->required();
  sub->add_option("--dim", args->dim, "Number of parameters n")->required();
  sub->add_option("--seed", args->seed, "Random seed (default 1)");
  sub->add_option("--popsize", args->popsize, "Population size lambda (default 4 + 3 ln n)");
  sub->add_option("--sigma0", args->sigma0, "Initial step size (default 0.5)");
  sub->add_option("--target", args->target, "Stop when f <= target (default 1e-10)");
  sub->add_option("--max-evals", args->max_evals,
                  "Evaluation budget (default max(10000, 1000 n^2))");
  sub->add_flag("--no-active", args->no_active, "Turn off the active covariance update");
  sub->callback([args] { run(*args); });
}

const bool registered = register_command(90, add_cmaes);

}  // namespace
}  // namespace diverse::cli
