// What the gallery shows, collected from a real finished run: a short run of the high jump
// made by the built tool (two variations, two generations, the robustness suite at its end)
// and its blends, then every collected figure checked against the run's own files.
#include "finished/gallery_data.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "io/files.h"
#include "support/cli.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

class GalleryDataTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // One directory per process: CTest runs the tests of this file as separate processes,
    // possibly at the same time.
    dir_ = fs::temp_directory_path() / ("diverse_gallery_data_test_" + std::to_string(getpid())) / "run";
    fs::remove_all(dir_);
    const cli_test::CliResult run = cli_test::run_cli(
        "run jump_high --n 2 --generations 2 --popsize 8 --threads 2 --seed 3 --out " + dir_.string());
    ASSERT_EQ(run.status, 0) << run.output;
    const cli_test::CliResult blend =
        cli_test::run_cli("blend " + dir_.string() + " --samples 3 --path-points 2 --threads 2");
    ASSERT_EQ(blend.status, 0) << blend.output;
    run_ = std::make_unique<RunView>(load_run_view(dir_));
    summary_ = read_json(dir_ / "summary.json");
    GalleryDataOptions options;
    options.threads = 2;
    data_ = std::make_unique<GalleryData>(collect_gallery_data(*run_, options));
  }

  void SetUp() override { ASSERT_NE(data_, nullptr) << "the run or its blends could not be made"; }

  static void TearDownTestSuite() {
    data_.reset();
    run_.reset();
    fs::remove_all(dir_.parent_path());
  }

  static fs::path dir_;
  static std::unique_ptr<RunView> run_;
  static nlohmann::json summary_;
  static std::unique_ptr<GalleryData> data_;  // everything, with the default options
};
fs::path GalleryDataTest::dir_;
std::unique_ptr<RunView> GalleryDataTest::run_;
nlohmann::json GalleryDataTest::summary_;
std::unique_ptr<GalleryData> GalleryDataTest::data_;

// Every motion's figures are the summary's, finite; its poses are its recorded states.
TEST_F(GalleryDataTest, MotionsHaveTheSummarysFiguresAndTheirRecordedPoses) {
  const RunView& run = *run_;
  const nlohmann::json& summary = summary_;
  const GalleryData& data = *data_;

  EXPECT_EQ(data.task, "jump_high");
  EXPECT_EQ(data.metric, summary["metric"]);
  EXPECT_EQ(data.settings["N"], 2);
  EXPECT_EQ(data.settings["generations"], 2);
  EXPECT_EQ(data.settings["D"], summary["D"]);
  EXPECT_EQ(data.distances, summary["distances"]);
  EXPECT_TRUE(data.notes.empty()) << data.notes.front();

  ASSERT_EQ(summary["motions"].size(), 3u);
  ASSERT_EQ(data.motions.size(), 3u);
  for (std::size_t i = 0; i < data.motions.size(); ++i) {
    SCOPED_TRACE(i);
    const GalleryMotion& m = data.motions[i];
    const nlohmann::json& s = summary["motions"][i];
    EXPECT_EQ(m.label, s["label"]);
    EXPECT_EQ(m.index, static_cast<int>(i));
    EXPECT_EQ(m.constraint, s["constraint"].get<double>());
    EXPECT_EQ(m.dmin, s["dmin"].get<double>());
    EXPECT_EQ(m.failed, s["failed"].get<bool>());
    for (const auto& [key, value] : {std::pair{"effort", m.effort}, std::pair{"effort_ratio", m.effort_ratio},
                                     std::pair{"positive_work", m.positive_work},
                                     std::pair{"distance_to_m0", m.distance_to_m0}}) {
      ASSERT_TRUE(value.has_value()) << key;
      EXPECT_TRUE(std::isfinite(*value)) << key;
      EXPECT_EQ(*value, s[key].get<double>()) << key;
    }
    EXPECT_GT(*m.effort, 0.0);
    ASSERT_TRUE(m.within_bounds.has_value());
    EXPECT_EQ(*m.within_bounds, s["within_bounds"].get<bool>());
    ASSERT_TRUE(m.foot_slip.has_value());
    EXPECT_EQ(*m.foot_slip, s["foot_slip"]);

    ASSERT_NE(m.poses.model, nullptr);
    EXPECT_EQ(m.poses.model.get(), run.motions[i].model.get());
    EXPECT_EQ(m.poses.qpos, run.motions[i].sample(30.0));
    EXPECT_EQ(m.poses.qpos.front(), run.motions[i].record.qpos0);
    EXPECT_GT(m.poses.qpos.size(), 30u);  // a jump lasts more than a second
    EXPECT_EQ(m.poses.duration, run.motions[i].duration());
  }
  EXPECT_EQ(*data.motions[0].distance_to_m0, 0.0);
  EXPECT_GT(*data.motions[1].distance_to_m0, 0.0);
  EXPECT_FALSE(data.shapes.has_value()) << "the run varied the controller only";
}

// Progress per generation from log.jsonl, and the robustness shares of robustness.json.
TEST_F(GalleryDataTest, ProgressAndRobustnessAreTheRunsFiles) {
  GalleryDataOptions options;
  options.paths = false;
  options.blends = false;
  const GalleryData data = collect_gallery_data(*run_, options);
  const nlohmann::json& summary = summary_;
  ASSERT_TRUE(data.progress.has_value());
  EXPECT_EQ(data.progress->generations_total, 2u);
  EXPECT_EQ(data.progress->generation, (std::vector<long long>{1, 2}));
  EXPECT_EQ(data.progress->D.back(), summary["D"].get<double>());
  ASSERT_EQ(data.progress->constraint.size(), 2u);
  EXPECT_EQ(data.progress->constraint.back().size(), 3u);
  EXPECT_EQ(data.progress->dmin.back()[1], summary["motions"][1]["dmin"].get<double>());
  EXPECT_TRUE(data.paths.empty());
  EXPECT_FALSE(data.blends.has_value());
  ASSERT_EQ(data.notes.size(), 1u);
  EXPECT_EQ(data.notes[0], "optimization paths left out (--no-paths)");

  const nlohmann::json suite = read_json(dir_ / "robustness.json");
  ASSERT_TRUE(data.robustness.has_value());
  EXPECT_EQ(data.robustness->source, "robustness.json");
  EXPECT_EQ(data.robustness->suite, suite["suite"]);
  ASSERT_EQ(data.robustness->motions.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    ASSERT_TRUE(data.robustness->motions[i].has_value());
    const GalleryRobustness& r = *data.robustness->motions[i];
    const nlohmann::json& m = suite["motions"][i];
    EXPECT_EQ(r.all.held, m["held"].get<long long>());
    EXPECT_EQ(r.all.count, m["count"].get<long long>());
    EXPECT_GT(r.all.count, 0);
    EXPECT_DOUBLE_EQ(r.share, m["share"].get<double>());
    ASSERT_EQ(r.kinds.size(), 4u);
    long long held = 0;
    for (const auto& [key, c] : r.kinds) {
      EXPECT_EQ(c.held, m["kinds"][key]["held"].get<long long>()) << key;
      EXPECT_EQ(c.count, m["kinds"][key]["count"].get<long long>()) << key;
      held += c.held;
    }
    EXPECT_EQ(held, r.all.held);
  }
}

// Each variation's path: its points simulated, the last the recorded result at the
// summary's distance from M0; and the run's blends as blend/summary.json lists them.
TEST_F(GalleryDataTest, PathsEndAtTheResultAndBlendsAreTheBlendFiles) {
  const RunView& run = *run_;
  const nlohmann::json& summary = summary_;
  const GalleryData& data = *data_;
  const GalleryDataOptions options;

  ASSERT_EQ(data.paths.size(), 2u);
  for (std::size_t v = 1; v <= 2; ++v) {
    SCOPED_TRACE(v);
    const GalleryPath& path = data.paths[v - 1];
    EXPECT_EQ(path.variation, v);
    EXPECT_EQ(path.label, run.motions[v].label);
    const nlohmann::json file = read_json(dir_ / "paths" / ("m" + std::to_string(v) + ".json"));
    EXPECT_EQ(path.points_total, file["points"].size() + 1);  // the means, then the result
    EXPECT_EQ(path.points_measured, path.points_total);
    EXPECT_DOUBLE_EQ(path.end_distance, summary["motions"][v]["distance_to_m0"].get<double>());
    ASSERT_EQ(path.points.size(), options.path_fractions.size());
    for (std::size_t f = 0; f < path.points.size(); ++f) {
      const GalleryPathPoint& p = path.points[f];
      EXPECT_EQ(p.fraction, options.path_fractions[f]);
      EXPECT_TRUE(std::isfinite(p.distance));
      EXPECT_EQ(p.feasible, p.constraint == 0.0 && !p.failed);
      ASSERT_NE(p.poses.model, nullptr);
      EXPECT_GT(p.poses.qpos.size(), 30u);
      EXPECT_GT(p.poses.duration, 1.0);
    }
    EXPECT_EQ(path.points.front().distance, 0.0);
    const GalleryPathPoint& end = path.points.back();
    EXPECT_TRUE(end.result);
    EXPECT_EQ(end.point, static_cast<int>(path.points_total) - 1);
    EXPECT_EQ(end.distance, path.end_distance);
    EXPECT_EQ(end.constraint, run.motions[v].constraint);
    EXPECT_EQ(end.poses.qpos, data.motions[v].poses.qpos);  // the recorded motion itself
  }

  const nlohmann::json blends = read_json(dir_ / "blend" / "summary.json");
  ASSERT_TRUE(data.blends.has_value());
  EXPECT_EQ(data.blends->samples, 3);
  EXPECT_EQ(data.blends->feasible, blends["feasible"].get<int>());
  EXPECT_EQ(data.blends->feasible_fraction, blends["feasible_fraction"].get<double>());
  ASSERT_EQ(data.blends->blends.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    SCOPED_TRACE(k);
    const GalleryBlend& b = data.blends->blends[k];
    const nlohmann::json& e = blends["blends"][k];
    EXPECT_EQ(b.label, e["label"]);
    EXPECT_EQ(b.weights, e["weights"].get<std::vector<double>>());
    EXPECT_EQ(b.constraint, e["constraint"].get<double>());
    EXPECT_EQ(b.feasible, e["feasible"].get<bool>());
    ASSERT_EQ(b.distances.size(), 3u);
    EXPECT_EQ(b.distances, e["distances"].get<std::vector<double>>());
    EXPECT_EQ(b.nearest, e["nearest"].get<int>());
    ASSERT_NE(b.poses.model, nullptr);
    EXPECT_GT(b.poses.qpos.size(), 30u);
  }
}

}  // namespace
}  // namespace diverse
