#include "params/parameters.h"

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

// An unknown name is refused; when the set has NAME_left and NAME_right instead (a pair the
// controller splits, jump3d's `asymmetric`), the one line says so.
TEST(ParameterSet, UnknownNameNamesTheParametersThatSplitIt) {
  ParameterSet p({{"rise.knee_left", -2.6, 0.0, "rad"}, {"rise.knee_right", -2.6, 0.0, "rad"}, {"rise.waist", -1, 1, "rad"}},
                 {0.0, 0.0, 0.0});
  auto error = [&](const nlohmann::json& j) {
    try {
      p.set_from_json(j, "m0.json");
    } catch (const UserError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(error({{"rise.knee", -1.0}, {"rise.waist", 0.0}}),
            "m0.json: parameters.rise.knee: expected a known parameter name (unknown parameter; this controller has "
            "rise.knee_left, rise.knee_right instead)");
  EXPECT_EQ(error({{"rise.kne", -1.0}}), "m0.json: parameters.rise.kne: expected a known parameter name (unknown parameter)");
  EXPECT_EQ(error({{"rise.knee_left", -1.0}, {"rise.waist", 0.0}}),
            "m0.json: parameters.rise.knee_right: expected a number in [-2.6, 0] rad");
}

}  // namespace
}  // namespace diverse
