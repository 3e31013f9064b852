// End-to-end tests of `diverse run --vary shape` on a short run of a real task: every
// variation meets the task on its own body and replays exactly from its own saved model,
// with link lengths in bounds and masses unchanged; resume after kill -9; body shapes
// given by hand to `diverse simulate`; and the errors users meet.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

#include "io/files.h"
#include "io/motion_record.h"
#include "physics/model.h"
#include "run/run.h"
#include "support/cli.h"
#include "task/evaluate.h"
#include "task/task.h"
#include "support/scratch.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

using cli_test::CliResult;
using cli_test::run_cli;

fs::path scratch(const std::string& name) {
  const fs::path dir = test_files::scratch_dir("shape_run_test_" + name);
  return dir;
}

const std::string kTask = std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_high.toml";
// Short but real: 2 variations, 8 samples per generation, 5 generations from a small
// step (the high jump's feasible neighbourhood is thin, at both timesteps and at rest
// balanced: from 0.01, or in 3 generations, a variation can still stand at M0).
const std::string kShort = kTask +
                           " --vary shape --n 2 --popsize 8 --sigma0 0.005 --generations 5 --seed 3 "
                           "--quiet --no-render";

const TaskEvaluator& evaluator() {
  static const TaskEvaluator ev(load_task(kTask));
  return ev;
}

Eigen::VectorXd vector_of(const nlohmann::json& array) {
  const auto v = array.get<std::vector<double>>();
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

TEST(ShapeRun, EveryVariationMeetsTheTaskOnItsOwnBodyAndReplaysFromItsOwnModel) {
  const fs::path dir = scratch("short");
  const CliResult r = run_cli("run " + kShort + " --metric shape --threads 2 --out " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json summary = read_json(dir / "summary.json");
  EXPECT_EQ(summary["metric"], "shape");
  EXPECT_EQ(summary["vary"], nlohmann::json({"control", "shape"}));
  EXPECT_EQ(read_json(dir / "run.json")["vary"], nlohmann::json({"control", "shape"}));
  EXPECT_TRUE(summary["all_satisfied"].get<bool>());

  const ShapeSpace& shapes = evaluator().shapes();
  EXPECT_EQ(summary["link_names"].get<std::vector<std::string>>(), shapes.link_names());
  const mjModel* base = evaluator().model().get();
  const nlohmann::json& d = summary["distances"];
  for (const char* metric : {"hf", "md", "wja", "shape"}) ASSERT_EQ(d[metric].size(), 3u) << metric;
  EXPECT_EQ(d["objective"], "shape");

  std::vector<Eigen::VectorXd> lengths;
  for (int i = 0; i <= 2; ++i) {
    SCOPED_TRACE("M" + std::to_string(i));
    const nlohmann::json& m = summary["motions"][static_cast<std::size_t>(i)];
    EXPECT_EQ(m["constraint"], 0.0);

    // Scales within their ranges, link lengths the scaled links and never below 3 cm.
    Eigen::VectorXd scales(shapes.size());
    for (int p = 0; p < shapes.size(); ++p) {
      const ParamSpec& spec = shapes.specs()[static_cast<std::size_t>(p)];
      scales[p] = m["shape_scales"][spec.name].get<double>();
      EXPECT_GE(scales[p], spec.lower) << spec.name;
      EXPECT_LE(scales[p], spec.upper) << spec.name;
      EXPECT_GE(scales[p], 0.4);
      EXPECT_LE(scales[p], 2.5);
    }
    const Eigen::VectorXd L = vector_of(m["link_lengths"]);
    EXPECT_EQ(L, shapes.link_lengths(scales));
    EXPECT_GE(L.minCoeff(), 0.03);
    lengths.push_back(L);
    if (i == 0) {
      EXPECT_EQ(scales, evaluator().shapes().identity());
    }

    // Its own model: the exact shaped text, masses as the task's body, replays exactly.
    const fs::path motion_file = dir / "motions" / ("m" + std::to_string(i) + ".json");
    const fs::path model_file = dir / "model" / ("m" + std::to_string(i) + ".xml");
    EXPECT_EQ(read_file(model_file), shapes.xml(scales));
    const auto model = SharedModel::from_file(model_file.string());
    ASSERT_EQ(model->get()->nbody, base->nbody);
    for (int b = 0; b < base->nbody; ++b) EXPECT_EQ(model->get()->body_mass[b], base->body_mass[b]) << b;
    int steps = 0;
    EXPECT_LT(replay_motion_file(motion_file, &steps), 1e-6);
    EXPECT_GT(steps, 100);

    // The motion file names the shape beside the controller's parameters.
    const nlohmann::json motion = read_json(motion_file);
    for (int p = 0; p < shapes.size(); ++p) {
      const std::string& name = shapes.specs()[static_cast<std::size_t>(p)].name;
      EXPECT_EQ(motion["parameters"][name].get<double>(), scales[p]) << name;
    }
    EXPECT_EQ(vector_of(motion["shape"]["link_lengths"]), L);
  }

  // The shape matrix holds sum |dL| over the links; the variations changed shape.
  for (int i = 0; i <= 2; ++i)
    for (int j = 0; j <= 2; ++j)
      EXPECT_NEAR(d["shape"][i][j].get<double>(), (lengths[static_cast<std::size_t>(i)] - lengths[static_cast<std::size_t>(j)]).cwiseAbs().sum(), 1e-12);
  EXPECT_GT(d["shape"][0][1].get<double>(), 0.0);
  EXPECT_GT(d["shape"][0][2].get<double>(), 0.0);

  // A variation's motion file is a parameter file: simulating it gives the same motion.
  const fs::path again = scratch("again");
  const CliResult s = run_cli("simulate " + kTask + " --params " + (dir / "motions" / "m1.json").string() +
                              " --no-film --out " + again.string());
  ASSERT_EQ(s.status, 0) << s.output;
  EXPECT_NE(s.output.find("C = 0"), std::string::npos) << s.output;
  EXPECT_EQ(read_file(again / "model.xml"), read_file(dir / "model" / "m1.xml"));
  EXPECT_EQ(read_json(again / "motion.json")["replay"]["qpos"], read_json(dir / "motions" / "m1.json")["replay"]["qpos"]);
}

TEST(ShapeRun, ResumeAfterKillGivesTheSameSummary) {
  const fs::path whole = scratch("whole"), killed = scratch("killed");
  const std::string args =
      kShort + " --metric md+shape --shape-weight 5 --generations 5 --threads 1 --checkpoint-seconds 0";
  CliResult a = run_cli("run " + args + " --out " + whole.string());
  ASSERT_EQ(a.status, 0) << a.output;

  ASSERT_GE(cli_test::run_then_kill(args, killed, 2), 2);
  ASSERT_FALSE(fs::exists(killed / "summary.json")) << "the run finished before it was killed";
  EXPECT_EQ(read_json(killed / "checkpoint.json")["vary"], nlohmann::json({"control", "shape"}));

  CliResult r = run_cli("resume " + killed.string() + " --threads 2 --quiet --no-render");
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json summary = read_json(whole / "summary.json");
  EXPECT_EQ(without_timing(summary), without_timing(read_json(killed / "summary.json")));
  EXPECT_EQ(read_file(whole / "log.jsonl"), read_file(killed / "log.jsonl"));
  // The objective's own matrix: MD plus 5 times the shape distance.
  EXPECT_EQ(summary["metric"], "md+shape");
  EXPECT_EQ(summary["shape_weight"], 5.0);
  const nlohmann::json& d = summary["distances"];
  EXPECT_EQ(d["objective"], "md+shape");
  for (int i = 0; i <= 2; ++i)
    for (int j = 0; j <= 2; ++j)
      EXPECT_DOUBLE_EQ(d["md+shape"][i][j].get<double>(),
                       d["md"][i][j].get<double>() + 5 * d["shape"][i][j].get<double>());
  EXPECT_GT(d["shape"][0][1].get<double>(), 0.0);
  EXPECT_GT(d["md"][0][1].get<double>(), 0.0);
}

TEST(ShapeRun, WithoutVaryShapeTheShapeMatrixIsZeroAndModelsAreTheSceneText) {
  const fs::path dir = scratch("control");
  const CliResult r = run_cli("run " + kTask + " --n 1 --popsize 4 --generations 1 --seed 2 --quiet --no-render "
                              "--threads 2 --out " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json summary = read_json(dir / "summary.json");
  EXPECT_EQ(summary["vary"], nlohmann::json({"control"}));
  EXPECT_EQ(summary["distances"]["shape"], nlohmann::json({{0.0, 0.0}, {0.0, 0.0}}));
  const Eigen::VectorXd base = evaluator().shapes().base_link_lengths();
  for (const auto& m : summary["motions"]) {
    EXPECT_EQ(vector_of(m["link_lengths"]), base);
    for (const auto& [name, scale] : m["shape_scales"].items()) EXPECT_EQ(scale.get<double>(), 1.0) << name;
  }
  // The task's scene text exactly, and motion files without a shape section; the replay on
  // the saved model is exact.
  EXPECT_EQ(read_file(dir / "model" / "m1.xml"), evaluator().model().xml());
  EXPECT_FALSE(read_json(dir / "motions" / "m1.json").contains("shape"));
  EXPECT_EQ(replay_motion_file(dir / "motions" / "m1.json"), 0.0);
}

// A parameter file: M0's parameters plus the given extra entries.
fs::path params_file(const std::string& name, const nlohmann::json& extra) {
  nlohmann::json params = read_json(evaluator().task().m0);
  nlohmann::json& values = params.contains("parameters") ? params["parameters"] : params;
  for (const auto& [key, value] : extra.items()) values[key] = value;
  const fs::path path = scratch(name) / "params.json";
  write_json_atomic(path, params);
  return path;
}

TEST(ShapeParams, AShapeGivenByHandIsSimulatedOnItsBodyAndReplaysExactly) {
  const fs::path params = params_file("byhand", {{"shape.thigh", 1.1}, {"shape.hand", 0.7}});
  const fs::path out = scratch("byhand_out");
  const CliResult r = run_cli("simulate " + kTask + " --params " + params.string() + " --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("shape: pelvis 1 abdomen 1 chest 1 head 1 thigh 1.1"), std::string::npos) << r.output;
  Eigen::VectorXd scales = evaluator().shapes().identity();
  const auto& specs = evaluator().shapes().specs();
  for (std::size_t p = 0; p < specs.size(); ++p) {
    if (specs[p].name == "shape.thigh") scales[static_cast<Eigen::Index>(p)] = 1.1;
    if (specs[p].name == "shape.hand") scales[static_cast<Eigen::Index>(p)] = 0.7;
  }
  EXPECT_EQ(read_file(out / "model.xml"), evaluator().shapes().xml(scales));
  const CliResult replay = run_cli("replay " + (out / "motion.json").string());
  EXPECT_EQ(replay.status, 0) << replay.output;
  EXPECT_TRUE(fs::exists(out / "filmstrip.png"));
}

TEST(ShapeParams, AShapeOutsideItsBoundsIsRefusedWithOneLine) {
  struct Case {
    nlohmann::json extra;
    std::string message;
  };
  const Case cases[] = {
      {{{"shape.thigh", 2.7}}, ": shape.thigh: expected a scale in [0.4, 2.5], got 2.7\n"},
      {{{"shape.head", 0.41}}, ": shape.head: expected a scale in [0.429, 2.5], got 0.41\n"},
      {{{"shape.tail", 1.0}}, ": shape.tail: expected a known shape parameter (shape.pelvis, ..., shape.hand)\n"},
      {{{"shape.foot", "long"}}, ": shape.foot: expected a scale in [0.4, 2.5], got \"long\"\n"},
  };
  int k = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.extra.dump());
    const fs::path params = params_file("bad" + std::to_string(k++), c.extra);
    const fs::path out = scratch("bad_out");
    const CliResult r = run_cli("simulate " + kTask + " --params " + params.string() + " --out " + out.string());
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.output, "diverse: error: " + params.string() + c.message);
    EXPECT_FALSE(fs::exists(out / "motion.json"));
  }
}

TEST(ShapeRunErrors, OneLineMessagesAndNonZeroExit) {
  const fs::path out = scratch("errors");
  struct Case {
    std::string args, message;
  };
  const Case cases[] = {
      {"run " + kTask + " --metric shape --out " + out.string(),
       "--metric: the shape metric needs the shape parameters (--vary shape)"},
      {"run " + kTask + " --metric md+shape --out " + out.string(),
       "--metric: the md+shape metric needs the shape parameters (--vary shape)"},
      {"run " + kTask + " --vary legs --out " + out.string(), "--vary: expected control or shape, got 'legs'"},
      {"run " + kTask + " --vary shape --metric md+shape --shape-weight -1 --out " + out.string(),
       "--shape-weight: expected a number in (0, 1000000000], got '-1'"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const CliResult r = run_cli(c.args);
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << "expected one line: " << r.output;
    EXPECT_EQ(r.output.rfind("diverse: error: ", 0), 0u) << r.output;
  }
}

}  // namespace
}  // namespace diverse
