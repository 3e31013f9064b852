// Blends of a finished run's controllers (`diverse blend`, run/blend.h): the weights, the
// blended parameters (and bodies) of real short runs of a 2D and a 3D task, exact replay
// of every blend's motion file, thread-count independence, and the errors users meet.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "io/files.h"
#include "run/blend.h"
#include "support/cli.h"
#include "support/scratch.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

using cli_test::CliResult;
using cli_test::run_cli;

fs::path scratch(const std::string& name) {
  const fs::path dir = test_files::scratch_dir("blend_test_" + name);
  return dir;
}

std::string task(const std::string& name) { return std::string(DIVERSE_SOURCE_DIR) + "/tasks/" + name + ".toml"; }

// A short but real run of the high jump: 2 variations, 3 generations of 8 samples (a
// shaped run: 5 generations from a step of 0.005, as in shape_run_test.cc, else under the
// half-timestep check a variation can still stand at M0's body).
fs::path short_run(const std::string& name, const std::string& extra = "",
                   const std::string& schedule = "--sigma0 0.03 --generations 3") {
  const fs::path dir = scratch(name);
  const CliResult r = run_cli("run " + task("jump_high") + " --n 2 --popsize 8 " + schedule + " --seed 3 " +
                              "--quiet --no-render --threads 2 " + extra + " --out " + dir.string());
  EXPECT_EQ(r.status, 0) << r.output;
  return dir;
}

// The parameters of a motion file (with a shaped body, its scales "shape.NAME" too), in
// the file's order of names.
std::vector<std::pair<std::string, double>> parameters_of(const fs::path& motion) {
  const nlohmann::json m = read_json(motion);  // kept alive through the loop
  std::vector<std::pair<std::string, double>> out;
  for (const auto& [name, value] : m["parameters"].items()) out.emplace_back(name, value.get<double>());
  return out;
}

TEST(BlendWeights, OnTheSimplexDeterministicAndUniform) {
  std::vector<double> mean(5, 0.0);
  const int samples = 4000;
  for (int k = 1; k <= samples; ++k) {
    const Eigen::VectorXd w = blend_weights(5, 7, k);
    ASSERT_EQ(w.size(), 5);
    EXPECT_NEAR(w.sum(), 1.0, 1e-12);
    EXPECT_GE(w.minCoeff(), 0.0);
    EXPECT_EQ(w, blend_weights(5, 7, k));  // sample k depends on the seed and k only
    for (int i = 0; i < 5; ++i) mean[static_cast<std::size_t>(i)] += w[i] / samples;
  }
  EXPECT_NE(blend_weights(5, 7, 1), blend_weights(5, 8, 1));
  // Uniform on the simplex (flat Dirichlet): every weight has mean 1/5 and the chance
  // that the first weight exceeds 1/2 is (1 - 1/2)^4 = 1/16.
  for (double m : mean) EXPECT_NEAR(m, 0.2, 0.01);
  int over_half = 0;
  for (int k = 1; k <= samples; ++k) over_half += blend_weights(5, 7, k)[0] > 0.5 ? 1 : 0;
  EXPECT_NEAR(static_cast<double>(over_half) / samples, 1.0 / 16.0, 0.015);
}

TEST(BlendPoint, ConvexCombinationInsideTheBoxAndExactAtACorner) {
  const std::vector<Eigen::VectorXd> points{Eigen::Vector3d(0.0, 1.0, 0.25), Eigen::Vector3d(1.0, 1.0, 0.75)};
  EXPECT_EQ(blend_point(points, Eigen::Vector2d(0.0, 1.0)), points[1]);
  const Eigen::VectorXd mid = blend_point(points, Eigen::Vector2d(0.25, 0.75));
  EXPECT_DOUBLE_EQ(mid[0], 0.75);
  EXPECT_DOUBLE_EQ(mid[1], 1.0);
  EXPECT_DOUBLE_EQ(mid[2], 0.625);
  EXPECT_THROW(blend_point(points, Eigen::Vector3d(0.2, 0.3, 0.5)), std::invalid_argument);
}

TEST(Blend, ControlRunBlendsReplayExactlyAndDoNotDependOnThreads) {
  const fs::path dir = short_run("control");
  const CliResult a = run_cli("blend " + dir.string() + " --samples 6 --path-points 3 --threads 1");
  ASSERT_EQ(a.status, 0) << a.output;
  EXPECT_NE(a.output.find("blends meet the task"), std::string::npos) << a.output;
  const std::string one = read_file(dir / "blend" / "summary.json");
  const CliResult b = run_cli("blend " + dir.string() + " --samples 6 --path-points 3 --threads 2");
  ASSERT_EQ(b.status, 0) << b.output;
  EXPECT_EQ(read_file(dir / "blend" / "summary.json"), one) << "the blends depend on the thread count";

  const nlohmann::json s = nlohmann::json::parse(one);
  const nlohmann::json run = read_json(dir / "summary.json");
  EXPECT_EQ(s["format"], "diverse.blend");
  EXPECT_EQ(s["samples"], 6);
  EXPECT_EQ(s["vertices"], 3);
  EXPECT_EQ(s["labels"], nlohmann::json({"M0", "M1", "M2"}));
  // The run's motions simulated again are the motions the run returned.
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(s["motions"][i]["constraint"], run["motions"][i]["constraint"]) << i;

  int feasible = 0;
  std::set<std::string> weights_seen;
  ASSERT_EQ(s["blends"].size(), 6u);
  for (std::size_t k = 0; k < 6; ++k) {
    SCOPED_TRACE("blend " + std::to_string(k + 1));
    const nlohmann::json& e = s["blends"][k];
    EXPECT_EQ(e["label"], "B" + std::to_string(k + 1));
    const Eigen::VectorXd w = blend_weights(3, 1, static_cast<int>(k) + 1);  // --seed 1
    for (int i = 0; i < 3; ++i) EXPECT_EQ(e["weights"][static_cast<std::size_t>(i)].get<double>(), w[i]);
    weights_seen.insert(e["weights"].dump());
    const bool ok = e["constraint"].is_number() && e["constraint"].get<double>() == 0.0 && !e["failed"].get<bool>();
    EXPECT_EQ(e["feasible"].get<bool>(), ok);
    feasible += ok ? 1 : 0;
    ASSERT_EQ(e["distances"].size(), 3u);
    for (const auto& d : e["distances"]) {
      if (d.is_null()) continue;
      EXPECT_GE(d.get<double>(), 0.0);
    }

    // The motion file: parameters the weighted sum of the motions' (the controller's
    // ranges map linearly onto [0, 1]), the constraint of the summary, exact replay.
    const fs::path file = dir / "blend" / e["file"].get<std::string>();
    const nlohmann::json motion = read_json(file);
    EXPECT_EQ(motion["label"], e["label"]);
    EXPECT_EQ(motion["constraint"]["total"], e["constraint"]);
    const auto p = parameters_of(file);
    std::vector<std::vector<std::pair<std::string, double>>> vertices;
    for (int i = 0; i < 3; ++i) vertices.push_back(parameters_of(dir / "motions" / ("m" + std::to_string(i) + ".json")));
    for (std::size_t j = 0; j < p.size(); ++j) {
      double expected = 0;
      for (int i = 0; i < 3; ++i) expected += w[i] * vertices[static_cast<std::size_t>(i)][j].second;
      EXPECT_NEAR(p[j].second, expected, 1e-9 * (1 + std::abs(expected))) << p[j].first;
    }
    const CliResult replay = run_cli("replay " + file.string());
    EXPECT_EQ(replay.status, 0) << replay.output;
  }
  EXPECT_EQ(weights_seen.size(), 6u);
  EXPECT_EQ(s["feasible"], feasible);
  EXPECT_DOUBLE_EQ(s["feasible_fraction"].get<double>(), feasible / 6.0);
  // Path points: up to 3 per variation, between M0 and the result.
  const nlohmann::json& paths = s["paths"];
  ASSERT_EQ(paths["variations"].size(), 2u);
  int points = 0;
  for (const auto& v : paths["variations"]) {
    EXPECT_LE(v["points"].get<int>(), 3);
    EXPECT_LE(v["points"].get<int>(), v["points_total"].get<int>());
    EXPECT_LE(v["feasible"].get<int>(), v["points"].get<int>());
    points += v["points"].get<int>();
  }
  EXPECT_EQ(paths["points"], points);

  // Fewer samples: the same first blends, and no file of the larger set left behind.
  const CliResult fewer = run_cli("blend " + dir.string() + " --samples 2 --path-points 0 --threads 2");
  ASSERT_EQ(fewer.status, 0) << fewer.output;
  const nlohmann::json f = read_json(dir / "blend" / "summary.json");
  ASSERT_EQ(f["blends"].size(), 2u);
  EXPECT_EQ(f["blends"][1], s["blends"][1]);
  EXPECT_EQ(f["paths"]["points"], 0);
  EXPECT_FALSE(fs::exists(dir / "blend" / "motions" / "b3.json"));

  // The gallery plays them; after the run is replaced, it leaves the old blends out.
  const CliResult gallery = run_cli("gallery " + dir.string() + " --no-paths");
  if (gallery.status == 0) {
    const std::string html = read_file(dir / "gallery.html");
    EXPECT_NE(html.find("\"label\":\"B2\""), std::string::npos);
    const CliResult rerun = run_cli("run " + task("jump_high") + " --n 2 --popsize 8 --sigma0 0.03 --generations 2 " +
                                    "--seed 4 --quiet --no-render --force --out " + dir.string());
    ASSERT_EQ(rerun.status, 0) << rerun.output;
    ASSERT_EQ(run_cli("gallery " + dir.string() + " --no-paths").status, 0);
    const std::string stale = read_file(dir / "gallery.html");
    EXPECT_EQ(stale.find("\"label\":\"B2\""), std::string::npos);
    EXPECT_NE(stale.find("blends left out"), std::string::npos);
  } else {
    EXPECT_NE(gallery.output.find("page template"), std::string::npos) << gallery.output;  // built without node
  }
}

TEST(Blend, ShapedRunBlendsTheBodiesToo) {
  const fs::path dir = short_run("shape", "--vary shape --metric md+shape", "--sigma0 0.005 --generations 5");
  const CliResult r = run_cli("blend " + dir.string() + " --samples 3 --path-points 1 --threads 2");
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json s = read_json(dir / "blend" / "summary.json");
  EXPECT_EQ(s["vary"], nlohmann::json({"control", "shape"}));
  std::vector<std::vector<std::pair<std::string, double>>> vertices;
  for (int i = 0; i < 3; ++i) vertices.push_back(parameters_of(dir / "motions" / ("m" + std::to_string(i) + ".json")));
  for (std::size_t k = 0; k < 3; ++k) {
    const nlohmann::json& e = s["blends"][k];
    const fs::path file = dir / "blend" / e["file"].get<std::string>();
    const auto p = parameters_of(file);
    int shape_scales = 0;
    ASSERT_EQ(p.size(), vertices[0].size());
    for (std::size_t j = 0; j < p.size(); ++j) {
      ASSERT_EQ(p[j].first, vertices[0][j].first);
      double expected = 0;
      for (int i = 0; i < 3; ++i) expected += e["weights"][static_cast<std::size_t>(i)].get<double>() * vertices[static_cast<std::size_t>(i)][j].second;
      EXPECT_NEAR(p[j].second, expected, 1e-9 * (1 + std::abs(expected))) << p[j].first;
      if (p[j].first.rfind("shape.", 0) != 0) continue;
      ++shape_scales;  // the body the blend ran on has the blended scale
      EXPECT_EQ(read_json(file)["shape"]["scales"][p[j].first].get<double>(), p[j].second) << p[j].first;
    }
    EXPECT_EQ(shape_scales, 10);
    // Its own body: the blended scales in its saved model, which it replays on exactly.
    EXPECT_NE(read_json(file)["shape"]["link_lengths"], read_json(dir / "motions" / "m0.json")["shape"]["link_lengths"]);
    const CliResult replay = run_cli("replay " + file.string());
    EXPECT_EQ(replay.status, 0) << replay.output;
  }
}

TEST(Blend, ThreeDimensionalRun) {
  // The bird robot's long jump: 1 variation, 1 generation of 2 samples.
  const fs::path dir = scratch("robot");
  const CliResult run = run_cli("run " + task("robot_jump") + " --n 1 --popsize 2 --generations 1 --seed 2 " +
                                "--quiet --no-render --threads 2 --out " + dir.string());
  ASSERT_EQ(run.status, 0) << run.output;
  const CliResult r = run_cli("blend " + dir.string() + " --samples 2 --path-points 1 --threads 2");
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json s = read_json(dir / "blend" / "summary.json");
  EXPECT_EQ(s["vertices"], 2);
  ASSERT_EQ(s["blends"].size(), 2u);
  for (const auto& e : s["blends"]) {
    EXPECT_EQ(run_cli("replay " + (dir / "blend" / e["file"].get<std::string>()).string()).status, 0);
  }
}

TEST(BlendErrors, OneLineMessagesAndExitCode2) {
  const fs::path missing = scratch("missing");
  const fs::path unfinished = scratch("unfinished");
  fs::create_directories(unfinished);
  write_file_atomic(unfinished / "run.json", R"({"format": "diverse.run"})");
  const fs::path changed = short_run("changed");
  nlohmann::json run = read_json(changed / "run.json");
  run["task_text"] = run["task_text"].get<std::string>() + "\n# edited";
  write_json_atomic(changed / "run.json", run);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"blend " + missing.string(), missing.string() + ": no such directory"},
      {"blend " + unfinished.string(), "summary.json: missing; the run has not finished"},
      {"blend " + changed.string(), "changed since the run; the blends cannot be simulated"},
      {"blend " + changed.string() + " --samples 0", "--samples: expected an integer in [1, 100000], got '0'"},
      {"blend " + changed.string() + " --samples many", "--samples: expected an integer in [1, 100000], got 'many'"},
      {"blend " + changed.string() + " --path-points -1", "--path-points: expected an integer in [0, 10000], got '-1'"},
      {"blend " + changed.string() + " --seed -3", "--seed"},
      {"blend", "run is required"},
  };
  for (const auto& [args, message] : cases) {
    SCOPED_TRACE(args);
    const CliResult r = run_cli(args);
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  }
}

}  // namespace
}  // namespace diverse
