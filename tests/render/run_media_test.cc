// Pictures, videos and the gallery data of a run, on a small real run directory made with
// the run's own writers (two simulated jumps, M0 and a variation, and a path between them),
// and the errors `diverse render`, `gallery` and `export` give on directories that are not
// finished runs.
#include "render/run_media.h"

#include <gtest/gtest.h>

#include "support/cli.h"
#include "support/jump_run.h"
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <set>
#include <string>

#include "core/error.h"
#include "io/files.h"
#include "io/bvh.h"
#include "io/motion_record.h"
#include "render/gallery.h"
#include "render/image.h"
#include "robust/robustness.h"
#include "core/thread_pool.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

const std::string kTaskFile = test_support::jump_high_task_file();

using Result = cli_test::CliResult;
using cli_test::run_cli;

std::string ffprobe_frames(const fs::path& video) {
  const std::string command = "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
                              "stream=nb_read_frames -of csv=p=0 " + video.string() + " 2>&1";
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  char buffer[256];
  while (pipe && fgets(buffer, sizeof buffer, pipe)) out += buffer;
  pclose(pipe);
  while (!out.empty() && (out.back() == '\n' || out.back() == ',')) out.pop_back();
  return out;
}

// A run directory as `diverse run` leaves it (support/jump_run.h): M0 is the task's input
// motion, M1 the same controller with every parameter moved by 0.06 of its range, and M1's
// path goes M0 -> half-way -> M1.
class RunMediaTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // One directory per process: CTest runs the tests of this file as separate processes,
    // possibly at the same time.
    dir_ = fs::temp_directory_path() / ("diverse_run_media_test_" + std::to_string(getpid())) / "run";
    test_support::write_jump_run(dir_);
  }

  static void TearDownTestSuite() { fs::remove_all(dir_.parent_path()); }

  // A copy of the run to break.
  static fs::path copy(const std::string& name) {
    const fs::path to = dir_.parent_path() / name;
    fs::remove_all(to);
    fs::copy(dir_, to, fs::copy_options::recursive);
    return to;
  }

  static fs::path dir_;
};
fs::path RunMediaTest::dir_;

// The task's landing region, x = 0.055 +- 0.15 m, is drawn on the floor; a run whose task
// file cannot be read has none.
TEST_F(RunMediaTest, GroundStripsAreTheTasksLandingRegion) {
  RunView run = load_run_view(dir_);
  const std::vector<GroundStrip> strips = run_ground_strips(run);
  ASSERT_EQ(strips.size(), 1u);
  EXPECT_NEAR(strips[0].x_min, -0.095, 1e-12);
  EXPECT_NEAR(strips[0].x_max, 0.205, 1e-12);
  run.task = nullptr;
  EXPECT_TRUE(run_ground_strips(run).empty());
}

TEST_F(RunMediaTest, FilmStripHasOneRowPerMotionAndRowsDiffer) {
  const RunView run = load_run_view(dir_);
  const fs::path png = dir_.parent_path() / "filmstrip.png";
  write_run_film_strip(run, png);
  const Image image = read_png(png.string());

  // The layout of render_film_strip with its defaults: 8 columns (crouch .. end) of
  // 240 px tiles, 6 px gaps, 12 px margins, a title line and a line of column labels.
  const int label_w = text_width("M0", FontSize::kLarge) + 8;
  const int grid_x = 12 + label_w;
  const int grid_y = 12 + text_height(FontSize::kMedium) + 8 + text_height(FontSize::kLarge) + 4;
  EXPECT_EQ(image.width(), grid_x + 8 * 240 + 7 * 6 + 12);
  EXPECT_EQ(image.height(), grid_y + 2 * 240 + 6 + 12);

  // Not blank: a rendered scene has many colours.
  std::set<int> colours;
  for (int y = 0; y < image.height(); y += 2)
    for (int x = 0; x < image.width(); x += 2) {
      const Rgb p = image.pixel(x, y);
      colours.insert(p.r << 16 | p.g << 8 | p.b);
    }
  EXPECT_GT(colours.size(), 500u);

  // The two rows show different motions: their tiles differ pixel by pixel.
  long differing = 0;
  for (int y = 0; y < 240; ++y)
    for (int x = 0; x < 8 * 246 - 6; ++x)
      if (!(image.pixel(grid_x + x, grid_y + y) == image.pixel(grid_x + x, grid_y + 246 + y))) ++differing;
  EXPECT_GT(differing, 5000);
}

TEST_F(RunMediaTest, VideosHaveOneFramePerSample) {
  const fs::path dir = copy("videos");
  const RunView run = load_run_view(dir);
  RunVideoOptions options;
  options.tile_width = options.tile_height = 96;
  const auto paths = write_run_videos(run, options);
  ASSERT_EQ(paths.size(), 3u);
  EXPECT_EQ(paths[0], dir / "videos" / "m0.mp4");
  EXPECT_EQ(paths[2], dir / "videos" / "all.mp4");
  const std::size_t f0 = run.motions[0].sample(30).size(), f1 = run.motions[1].sample(30).size();
  EXPECT_EQ(ffprobe_frames(paths[0]), std::to_string(f0));
  EXPECT_EQ(ffprobe_frames(paths[1]), std::to_string(f1));
  EXPECT_EQ(ffprobe_frames(paths[2]), std::to_string(std::max(f0, f1)));

  options.speed = 0.5;  // half speed: twice the frames
  const auto slow = write_run_videos(run, options);
  const std::size_t s0 = run.motions[0].sample(30, 0.5).size(), s1 = run.motions[1].sample(30, 0.5).size();
  EXPECT_EQ(ffprobe_frames(slow[2]), std::to_string(std::max(s0, s1)));
}

TEST(PickPathPoints, NearestToEachFractionOfTheEndDistance) {
  const std::vector<double> fractions{0, 0.25, 0.5, 0.75, 1};
  EXPECT_EQ(pick_path_points(std::vector<double>{0, 1, 2, 3, 4}, fractions), (std::vector<int>{0, 1, 2, 3, 4}));
  // Not monotone: 50 % of 8 is nearest to point 1 (d = 4.5); 25 % (2) to point 3 (d = 1.8).
  EXPECT_EQ(pick_path_points(std::vector<double>{0, 4.5, 9, 1.8, 7, 8}, fractions),
            (std::vector<int>{0, 3, 1, 4, 5}));
  // Unknown distances (failed simulations) are skipped.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(pick_path_points(std::vector<double>{0, nan, 5, 10}, std::vector<double>{0.5}), (std::vector<int>{2}));
  // Ties go to the point nearest in index to the fraction of the path.
  EXPECT_EQ(pick_path_points(std::vector<double>{0, 2, 2, 2, 4}, std::vector<double>{0.5, 0.25, 0.75}),
            (std::vector<int>{2, 1, 3}));
  // An end no farther than the start: by index.
  EXPECT_EQ(pick_path_points(std::vector<double>{0, 2, 1, 0}, fractions), (std::vector<int>{0, 1, 2, 2, 3}));
  EXPECT_THROW(pick_path_points(std::vector<double>{}, fractions), std::invalid_argument);
}

TEST_F(RunMediaTest, GalleryDataHasPosesConstraintsAndThePath) {
  const RunView run = load_run_view(dir_);
  GalleryOptions options;
  options.threads = 2;
  const nlohmann::json data = gallery_data(run, options);
  EXPECT_EQ(data["format"], "diverse.gallery");
  ASSERT_EQ(data["motions"].size(), 2u);
  const mjModel* m = run.motions[0].model->get();
  for (std::size_t i = 0; i < 2; ++i) {
    const nlohmann::json& motion = data["motions"][i];
    EXPECT_EQ(motion["constraint"], run.motions[i].constraint);
    const std::size_t count = run.motions[i].sample(30).size();
    EXPECT_EQ(motion["frames"]["count"], count);
    EXPECT_EQ(motion["frames"]["bodies"], m->nbody - 1);
    ASSERT_EQ(motion["frames"]["data"].size(), count * static_cast<std::size_t>(m->nbody - 1) * 7);
  }
  // Frame 0 of M0 is the pelvis at its initial position, rounded to 0.1 mm.
  const nlohmann::json& first = data["motions"][0]["frames"]["data"];
  EXPECT_NEAR(first[2].get<double>(), run.motions[0].record.qpos0[1] + m->body_pos[3 * 1 + 2], 5e-5);
  for (const auto& v : first) EXPECT_NEAR(v.get<double>() * 1e4, std::round(v.get<double>() * 1e4), 1e-6);
  // Models: the planar human's 17 bodies and its geoms but the floor plane, which the page
  // draws itself.
  ASSERT_GE(data["models"].size(), 1u);
  EXPECT_EQ(data["models"][0]["bodies"].size(), 17u);
  EXPECT_EQ(data["models"][0]["geoms"].size(), static_cast<std::size_t>(m->ngeom - 1));
  EXPECT_EQ(data["models"][0]["floor"], 0.0);
  EXPECT_EQ(data["models"][0]["bodies"][0]["name"], "pelvis");
  EXPECT_NEAR(data["scene"]["strips"][0][0].get<double>(), -0.095, 1e-12);
  EXPECT_EQ(data["distances"]["md"][0][1], 1.5);

  // M1's path: 0 % is M0 itself, 100 % the result; every point simulated and marked.
  ASSERT_EQ(data["paths"].size(), 2u);
  EXPECT_TRUE(data["paths"][0].is_null());
  const nlohmann::json& path = data["paths"][1];
  EXPECT_EQ(path["points_total"], 4);  // three means and the result
  ASSERT_EQ(path["points"].size(), 5u);
  const nlohmann::json& start = path["points"][0];
  EXPECT_EQ(start["fraction"], 0.0);
  EXPECT_EQ(start["point"], 0);
  EXPECT_EQ(start["distance"], 0.0);
  const nlohmann::json& end = path["points"][4];
  EXPECT_EQ(end["point"], 3);
  EXPECT_TRUE(end["result"].get<bool>());
  EXPECT_EQ(end["constraint"], run.motions[1].constraint);
  EXPECT_GT(end["distance"].get<double>(), 0.0);
  EXPECT_EQ(end["distance"], path["end_distance"]);
  EXPECT_EQ(end["frames"], data["motions"][1]["frames"]);  // the recorded motion itself
  for (const auto& p : path["points"]) {
    EXPECT_EQ(p["feasible"].get<bool>(), p["constraint"] == 0.0 && !p["failed"].get<bool>());
    EXPECT_GT(p["frames"]["count"].get<int>(), 10);
  }
}

// The plots panel's data: the run's progress per generation from log.jsonl (a generation's
// last record), thinned evenly to at most max_progress_points generations, and the bodies'
// link-length scales of a run whose shape varied; a malformed log line is a one-line error.
TEST_F(RunMediaTest, GalleryDataHasProgressAndShapes) {
  const fs::path dir = copy("progress");
  std::string log;
  for (int g = 1; g <= 10; ++g)
    for (int v = 1; v <= 2; ++v)
      log += nlohmann::json({{"generation", g}, {"step", 2 * g + v - 2}, {"variation", v},
                             {"D", 10.0 * g + v}, {"best_D", 10.0 * g + v + 0.5},
                             {"constraint", {0.0, 1.0 / g}}, {"dmin", {1.5, 1.0 * g}},
                             {"evaluations", 16 * g}}).dump() + "\n";
  write_file_atomic(dir / "log.jsonl", log);
  nlohmann::json summary = read_json(dir / "summary.json");
  summary["vary"] = {"control", "shape"};
  summary["motions"][0]["shape_scales"] = {{"thigh", 1.0}, {"shin", 1.0}};
  summary["motions"][1]["shape_scales"] = {{"thigh", 1.4}, {"shin", 0.7}};
  write_json_atomic(dir / "summary.json", summary);

  GalleryOptions options;
  options.paths = false;
  options.max_progress_points = 4;
  const nlohmann::json data = gallery_data(load_run_view(dir), options);
  const nlohmann::json& p = data["progress"];
  EXPECT_EQ(p["generations_total"], 10);
  EXPECT_EQ(p["generation"], nlohmann::json({1, 4, 7, 10}));
  EXPECT_EQ(p["D"], nlohmann::json({12.0, 42.0, 72.0, 102.0}));  // each generation's last step
  EXPECT_EQ(p["best_D"][3], 102.5);
  EXPECT_EQ(p["constraint"][3], nlohmann::json({0.0, 0.1}));
  EXPECT_EQ(p["dmin"][1], nlohmann::json({1.5, 4.0}));
  EXPECT_EQ(data["shape"]["names"], nlohmann::json({"shin", "thigh"}));
  EXPECT_EQ(data["shape"]["scales"][1], nlohmann::json({0.7, 1.4}));
  EXPECT_TRUE(data["view"].is_object());
  EXPECT_FALSE(data["view"]["three_quarter"].get<bool>()) << "the planar human is seen from the side";

  write_file_atomic(dir / "log.jsonl", log + "{\"generation\": 11}\n");
  try {
    gallery_data(load_run_view(dir), options);
    FAIL() << "expected a UserError";
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()), (dir / "log.jsonl").string() +
                                         ": line 21: expected a JSON record with generation, D, best_D, constraint and dmin");
  }
  // Without log.jsonl and an unshaped run: no progress, no shapes.
  fs::remove(dir / "log.jsonl");
  summary.erase("vary");
  write_json_atomic(dir / "summary.json", summary);
  const nlohmann::json bare = gallery_data(load_run_view(dir), options);
  EXPECT_TRUE(bare["progress"].empty());
  EXPECT_TRUE(bare["shape"].is_null());
}

// Every motion's shares of the robustness suite: from RUN/robustness.json (as `diverse
// robustness RUN` writes it), else from summary.json "robustness" (as a run's end writes it);
// a run with neither (made before the suite) gives null and a note saying the suite was not
// run; a malformed file is a one-line error naming it.
TEST_F(RunMediaTest, GalleryDataHasEveryMotionsRobustness) {
  const fs::path dir = copy("robustness");
  GalleryOptions options;
  options.paths = false;
  const nlohmann::json none = gallery_data(load_run_view(dir), options);
  EXPECT_TRUE(none["robustness"].is_null());
  auto says_not_run = [](const nlohmann::json& notes) {
    return std::any_of(notes.begin(), notes.end(), [](const nlohmann::json& n) {
      return n.get<std::string>().find("robustness suite not run") != std::string::npos;
    });
  };
  EXPECT_TRUE(says_not_run(none["notes"])) << none["notes"];

  // The suite's file as the command writes it, with one rollout of each kind per motion.
  RobustnessSuite suite;
  suite.parameter_samples = 1;
  suite.push_samples = 1;
  suite.friction_factors = {0.6};
  const TaskEvaluator evaluator(load_task(kTaskFile));
  const RunView run = load_run_view(dir);
  std::vector<MotionUnderTest> motions;
  for (const RunMotion& m : run.motions)
    motions.push_back({m.label, m.index, evaluator.load_parameters((dir / "motions" / ("m" + std::to_string(m.index) + ".json")).string())});
  ThreadPool pool(2);
  const nlohmann::json file = robustness_json(evaluator, motions, suite, pool);
  write_json_atomic(dir / "robustness.json", file);
  const nlohmann::json data = gallery_data(load_run_view(dir), options);
  EXPECT_FALSE(says_not_run(data["notes"])) << data["notes"];
  ASSERT_TRUE(data["robustness"].is_object());
  EXPECT_EQ(data["robustness"]["source"], "robustness.json");
  EXPECT_EQ(data["robustness"]["suite"], file["suite"]);
  ASSERT_EQ(data["robustness"]["motions"].size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const nlohmann::json& shown = data["robustness"]["motions"][i];
    const nlohmann::json& measured = file["motions"][i];
    EXPECT_EQ(shown["held"], measured["held"]);
    EXPECT_EQ(shown["count"], 4);
    EXPECT_EQ(shown["share"], measured["share"]);
    for (const char* kind : {"parameters", "pushes", "friction", "half_timestep"}) {
      EXPECT_EQ(shown["kinds"][kind]["held"], measured["kinds"][kind]["held"]) << kind;
      EXPECT_EQ(shown["kinds"][kind]["count"], 1) << kind;
    }
  }

  // Without the file, summary.json's shares (a run's end writes both).
  nlohmann::json summary = read_json(dir / "summary.json");
  summary["robustness"] = {{"suite", file["suite"]}, {"motions", nlohmann::json::array()}};
  for (const nlohmann::json& m : file["motions"]) {
    nlohmann::json kinds = nlohmann::json::object();
    for (const auto& [key, kind] : m["kinds"].items()) kinds[key] = {{"held", kind["held"]}, {"count", kind["count"]}};
    summary["robustness"]["motions"].push_back(
        {{"label", m["label"]}, {"held", m["held"]}, {"count", m["count"]}, {"share", m["share"]}, {"kinds", kinds}});
  }
  write_json_atomic(dir / "summary.json", summary);
  fs::remove(dir / "robustness.json");
  const nlohmann::json from_summary = gallery_data(load_run_view(dir), options);
  EXPECT_EQ(from_summary["robustness"]["source"], "summary.json");
  EXPECT_EQ(from_summary["robustness"]["motions"], data["robustness"]["motions"]);

  // A broken file is refused in one line naming it and the field.
  nlohmann::json broken = file;
  broken["motions"][1]["kinds"]["pushes"]["held"] = -1;
  write_json_atomic(dir / "robustness.json", broken);
  try {
    gallery_data(load_run_view(dir), options);
    FAIL() << "expected a UserError";
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()), (dir / "robustness.json").string() +
                                         ": motions[].kinds.pushes.held: expected a count (an integer >= 0)");
  }
}

TEST(GalleryHtml, DataReplacesTheDataMarkerAndCannotEndTheScript) {
  const std::string page = "<script id=d type=application/json>__DIVERSE_GALLERY_DATA__</script>";
  const std::string html = gallery_html(page, {{"name", "</script><b>"}});
  EXPECT_EQ(html, "<script id=d type=application/json>{\"name\":\"<\\/script><b>\"}</script>");
  try {
    gallery_html("<html></html>", {});
    FAIL();
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(), "gallery: the page template has no single __DIVERSE_GALLERY_DATA__ "
                           "data marker; rebuild it from web/");
  }
}

TEST_F(RunMediaTest, CommandsWriteTheirFiles) {
  const fs::path dir = copy("commands");
  const fs::path page = dir.parent_path() / "template.html";
  write_file_atomic(page, "<html><script type=application/json>__DIVERSE_GALLERY_DATA__</script></html>");
  const Result gallery = run_cli("gallery " + dir.string() + " --no-paths", "DIVERSE_GALLERY_TEMPLATE=" + page.string());
  ASSERT_EQ(gallery.status, 0) << gallery.output;
  EXPECT_NE(read_file(dir / "gallery.html").find("\"format\":\"diverse.gallery\""), std::string::npos);

  const Result render = run_cli("render " + dir.string() + " --no-video");
  ASSERT_EQ(render.status, 0) << render.output;
  EXPECT_EQ(render.output, (dir / "filmstrip.png").string() + "\n");

  const Result bvh = run_cli("export " + dir.string() + " --bvh --fps 60");
  ASSERT_EQ(bvh.status, 0) << bvh.output;
  const RunView run = load_run_view(dir);
  for (int i = 0; i < 2; ++i) {
    const Bvh file = read_bvh(dir / "export" / ("m" + std::to_string(i) + ".bvh"));
    EXPECT_EQ(file.joints.size(), 17u);
    EXPECT_EQ(file.frame_count(), static_cast<int>(run.motions[static_cast<std::size_t>(i)].sample(60).size()));
  }

  const Result gltf = run_cli("export " + dir.string() + " --gltf");
  ASSERT_EQ(gltf.status, 0) << gltf.output;
  for (const char* name : {"m0.glb", "m1.glb", "all.glb"}) {
    const std::string bytes = read_file(dir / "export" / name);
    ASSERT_GT(bytes.size(), 12u) << name;
    EXPECT_EQ(bytes.substr(0, 4), "glTF") << name;  // the binary container's magic
  }
  EXPECT_NE(gltf.output.find("all.glb  (2 motions side by side"), std::string::npos) << gltf.output;
}

TEST_F(RunMediaTest, CommandsOnWhatIsNotAFinishedRunAreOneLineErrors) {
  const fs::path empty = dir_.parent_path() / "empty";
  fs::remove_all(empty);
  fs::create_directories(empty);
  const fs::path no_motion = copy("no_motion");
  fs::remove(no_motion / "motions" / "m1.json");
  const fs::path no_model = copy("no_model");
  fs::remove(no_model / "model" / "m1.xml");
  const fs::path unfinished = copy("unfinished");
  fs::remove(unfinished / "summary.json");

  for (const std::string command : {"render", "gallery", "export --bvh", "export --gltf"}) {
    SCOPED_TRACE(command);
    Result r = run_cli(command + " " + empty.string());
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.output, "diverse: error: " + empty.string() +
                            ": not a run directory (no run.json; `diverse run TASK --out DIR` makes one)\n");
    r = run_cli(command + " " + no_motion.string());
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.output, "diverse: error: " + (no_motion / "motions" / "m1.json").string() +
                            ": missing; the run directory is incomplete (`diverse resume " +
                            no_motion.string() + "` writes its outputs again)\n");
    r = run_cli(command + " " + no_model.string());
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.output, "diverse: error: " + (no_model / "model" / "m1.xml").string() +
                            ": missing; the run directory is incomplete (`diverse resume " +
                            no_model.string() + "` writes its outputs again)\n");
    r = run_cli(command + " " + unfinished.string());
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.output, "diverse: error: " + (unfinished / "summary.json").string() +
                            ": missing; the run has not finished (`diverse resume " +
                            unfinished.string() + "` finishes it)\n");
    r = run_cli(command + " " + (empty / "nothing").string());
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.output, "diverse: error: " + (empty / "nothing").string() + ": no such directory\n");
  }

  Result r = run_cli("render " + dir_.string() + " --fps 45");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output, "diverse: error: --fps: expected 30 or 60, got 45\n");
  r = run_cli("export " + dir_.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output, "diverse: error: export: choose a format: --bvh, --gltf or both\n");

  // The page template missing, with no node to build it.
  r = run_cli("gallery " + dir_.string(), "PATH=/nonexistent DIVERSE_GALLERY_TEMPLATE=/nonexistent/t.html");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output, "diverse: error: gallery: the page template /nonexistent/t.html is not built: it "
                      "needs node and npm; install them (Debian: apt-get install nodejs npm) and run "
                      "scripts/build.sh\n");

  // Paths cannot be simulated once the task file differs from the run's.
  const fs::path changed = copy("changed");
  nlohmann::json run = read_json(changed / "run.json");
  run["task_text"] = "# another task\n";
  write_json_atomic(changed / "run.json", run);
  const fs::path page = dir_.parent_path() / "template.html";
  write_file_atomic(page, "<html>__DIVERSE_GALLERY_DATA__</html>");
  r = run_cli("gallery " + changed.string(), "DIVERSE_GALLERY_TEMPLATE=" + page.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output, "diverse: error: " + (changed / "run.json").string() + ": task_file: " + kTaskFile +
                          " changed since the run; the optimization paths cannot be simulated (restore "
                          "it, or make the gallery with --no-paths)\n");
}

}  // namespace
}  // namespace diverse

namespace diverse {
namespace {

// A single motion's video header: its title and the time stamp never overlap. The bird
// robot's walk ("robot_silly_walk M1, real time" beside "t = 11.70 s") did not fit in
// one 384-pixel tile and was drawn over the stamp; the shorter "M1, real time" does.
TEST(RunMedia, VideoTitlesLeaveRoomForTheTimeStamp) {
  const int gap = 6, width = 384 + 2 * gap;
  const std::string stamp = "t = 11.70 s";
  const std::vector<std::string> titles = {"robot_silly_walk M1, real time", "M1, real time", "M1"};
  EXPECT_GT(text_width(titles[0], FontSize::kMedium) + text_width(stamp, FontSize::kMedium) + 3 * gap, width);
  const std::string title = fitting_title(titles, stamp, width, gap);
  EXPECT_EQ(title, "M1, real time");
  EXPECT_LE(text_width(title, FontSize::kMedium) + text_width(stamp, FontSize::kMedium) + 3 * gap, width);
  EXPECT_EQ(fitting_title(titles, stamp, 2000, gap), titles[0]);  // room for the whole title
  EXPECT_EQ(fitting_title(titles, stamp, 100, gap), "M1");         // nothing fits: the shortest
  EXPECT_EQ(fitting_title({}, stamp, width, gap), "");
}

}  // namespace
}  // namespace diverse
