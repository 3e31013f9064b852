#include "control/parameters.h"

#include <gtest/gtest.h>

#include "task/evaluate.h"
#include "task/task.h"
#include "core/error.h"

namespace diverse {
namespace {

TEST(ParameterSet, NormalizedEndpointsMapExactlyOntoTheBounds) {
  // Every controller parameter: x = 0 and x = 1 give exactly the bounds, so a vector at
  // the edge of the optimizer's box always reads back as valid parameters.
  const TaskEvaluator ev(load_task(std::string(DIVERSE_SOURCE_DIR) + "/tasks/backflip.toml"));
  const auto specs = ev.parameters().specs();
  ParameterSet p(specs, std::vector<double>(specs.size(), 0.0));
  p.set_normalized(Eigen::VectorXd::Ones(p.size()));
  for (int i = 0; i < p.size(); ++i) EXPECT_EQ(p.values()[i], specs[i].upper) << specs[i].name;
  ParameterSet back(specs, std::vector<double>(specs.size(), 0.0));
  EXPECT_NO_THROW(back.set_from_json(p.to_json(), "test"));
  p.set_normalized(Eigen::VectorXd::Zero(p.size()));
  for (int i = 0; i < p.size(); ++i) EXPECT_EQ(p.values()[i], specs[i].lower) << specs[i].name;
}

TEST(ParameterSet, NormalizeRoundTrip) {
  ParameterSet p({{"a", -1.0, 3.0, "rad"}, {"b", 0.1, 0.3, "s"}}, {0.0, 0.2});
  const Eigen::VectorXd x = p.normalized();
  EXPECT_DOUBLE_EQ(x[0], 0.25);
  EXPECT_DOUBLE_EQ(x[1], 0.5);
  p.set_normalized(Eigen::Vector2d(0.5, 1.0));
  EXPECT_DOUBLE_EQ(p.get("a"), 1.0);
  EXPECT_EQ(p.get("b"), 0.3);
}

TEST(ParameterSet, OutOfRangeValueIsAOneLineError) {
  ParameterSet p({{"a", -1.0, 3.0, "rad"}}, {0.0});
  try {
    p.set_from_json({{"a", 7.0}}, "m0.json");
    FAIL();
  } catch (const UserError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("m0.json: parameters.a: expected", 0), 0u) << what;
  }
}

}  // namespace
}  // namespace diverse
