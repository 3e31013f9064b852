// Looking at 3D and travelling motions: the view plan (side view for planar characters,
// three-quarters for free roots, facing where they travel; cameras that follow a character
// that travels far), film-strip columns chosen from any motion's phases (a jump's events,
// one stride of a cyclic motion, other phases, or even times), film strips that keep a
// 15 m walker in every tile, and film strips and videos of a run of 3D motions.
#include "render/view_plan.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "finished/run_view.h"
#include "physics/model.h"
#include "render/film_columns.h"
#include "render/film_strip.h"
#include "render/image.h"
#include "render/offscreen.h"
#include "render/run_media.h"
#include "support/stance_run.h"
#include "task/task.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

std::shared_ptr<const SharedModel> character(const std::string& name) {
  return SharedModel::from_file(std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/" + name + ".xml");
}

fs::path out_dir() {
  const fs::path dir = fs::temp_directory_path() / ("diverse_view3d_test_" + std::to_string(getpid()));
  fs::create_directories(dir);
  return dir;
}

// qpos0 with the root moved by (dx, dy) per frame, `count` frames: a character that
// glides (a stand-in for a walk's root path; pictures only).
std::vector<std::vector<double>> glide(const mjModel* m, double dx, double dy, int count) {
  std::vector<std::vector<double>> frames;
  for (int k = 0; k < count; ++k) {
    std::vector<double> q(m->qpos0, m->qpos0 + m->nq);
    q[0] += dx * k;
    q[1] += dy * k;
    frames.push_back(q);
  }
  return frames;
}

TEST(ViewPlan, PlanarCharactersAreSeenFromTheSide) {
  const auto model = character("human2d");
  const auto frames = glide(model->get(), 0.01, 0.0, 20);
  const ViewPlan plan = plan_view(std::vector<PosedModel>{{model->get(), frames}});
  EXPECT_FALSE(has_free_root(model->get()));
  EXPECT_FALSE(plan.three_quarter);
  EXPECT_FALSE(plan.follow);
  EXPECT_EQ(plan.direction.azimuth, SideCamera{}.azimuth);
  EXPECT_EQ(plan.direction.elevation, SideCamera{}.elevation);
}

TEST(ViewPlan, FreeRootsAreSeenThreeQuartersFromTheirFront) {
  const auto model = character("human3d");
  EXPECT_TRUE(has_free_root(model->get()));
  EXPECT_EQ(root_body(model->get()), mj_name2id(model->get(), mjOBJ_BODY, "pelvis"));
  // Standing in place: the root's x axis (+x) is the front.
  const auto still = glide(model->get(), 0.0, 0.0, 5);
  const ViewPlan stand = plan_view(std::vector<PosedModel>{{model->get(), still}});
  EXPECT_TRUE(stand.three_quarter);
  EXPECT_NEAR(stand.heading, 0.0, 1e-9);
  EXPECT_NEAR(stand.direction.azimuth, 90.0 + kThreeQuarterTurn, 1e-9);
  EXPECT_NEAR(stand.direction.elevation, kThreeQuarterElevation, 1e-9);
  EXPECT_FALSE(stand.follow);
  // Travelling 1.9 m along -x (a jump backwards) or along +y: the front is still where the
  // root faces.
  const auto back = glide(model->get(), -0.1, 0.0, 20);
  EXPECT_NEAR(plan_view(std::vector<PosedModel>{{model->get(), back}}).heading, 0.0, 1e-9);
  const auto sideways = glide(model->get(), 0.0, 0.1, 20);
  EXPECT_NEAR(plan_view(std::vector<PosedModel>{{model->get(), sideways}}).heading, 0.0, 1e-9);
  // A root turned 90 degrees to the left (about z) faces +y.
  auto turned = still;
  for (auto& q : turned) {
    q[3] = std::cos(M_PI / 4);
    q[6] = std::sin(M_PI / 4);
  }
  const ViewPlan plan = plan_view(std::vector<PosedModel>{{model->get(), turned}});
  EXPECT_NEAR(plan.heading, 90.0, 1e-9);
  EXPECT_NEAR(plan.direction.azimuth, 180.0 + kThreeQuarterTurn, 1e-9);
  EXPECT_FALSE(plan.follow);
  // Lying on its back (root x axis straight up) and travelling along +y: the travel decides.
  auto lying = sideways;
  for (auto& q : lying) {
    q[3] = std::cos(-M_PI / 4);
    q[5] = std::sin(-M_PI / 4);  // -90 degrees about y: x axis to +z
  }
  EXPECT_NEAR(plan_view(std::vector<PosedModel>{{model->get(), lying}}).heading, 90.0, 1e-9);
}

TEST(ViewPlan, CamerasFollowACharacterThatTravelsFar) {
  const auto model = character("human3d");
  const auto walk = glide(model->get(), 0.1, 0.01, 151);  // 15 m forward, 1.5 m to the left
  const ViewPlan plan = plan_view(std::vector<PosedModel>{{model->get(), walk}});
  EXPECT_TRUE(plan.follow);
  // Anchors: the root's x and y at the floor; smoothed anchors of a straight glide are the
  // glide itself away from the ends.
  const auto a = follow_anchor(model->get(), walk[100]);
  EXPECT_NEAR(a[0], 10.0, 1e-9);
  EXPECT_NEAR(a[1], 1.0, 1e-9);
  EXPECT_EQ(a[2], 0.0);
  const auto smooth = follow_anchors(model->get(), walk, 15);
  EXPECT_NEAR(smooth[100][0], 10.0, 1e-9);
  EXPECT_NEAR(smooth[0][0], 0.75, 1e-9);  // frames 0..15 averaged
  // The following camera frames one standing body, not 15 m of floor.
  std::vector<std::vector<std::array<double, 3>>> anchors{smooth};
  const SideCamera follow = fit_following_camera(std::vector<PosedModel>{{model->get(), walk}}, anchors, 1.0, plan.direction);
  const SideCamera fixed = fit_shared_camera(std::vector<PosedModel>{{model->get(), walk}}, 1.0, {}, plan.direction);
  EXPECT_LT(follow.distance, 8.0);
  EXPECT_GT(fixed.distance, 3 * follow.distance);
}

// Fraction of a tile's rows that hold something other than sky and floor (the character):
// rows whose pixels differ from the row's median by a lot.
double character_height_fraction(const Image& strip, int x0, int y0, int w, int h) {
  int rows = 0;
  for (int y = y0; y < y0 + h; ++y) {
    int dark = 0;
    for (int x = x0; x < x0 + w; ++x) {
      const Rgb c = strip.pixel(x, y);
      // The character (rgba 0.8 0.6 0.4: orange-brown) against grey floor and blue-grey sky.
      if (c.r > c.b + 40) ++dark;
    }
    if (dark >= 2) ++rows;
  }
  return static_cast<double>(rows) / h;
}

TEST(FollowingFilmStrip, KeepsAFifteenMetreWalkerLargeInEveryTile) {
  const auto model = character("human3d");
  const auto walk = glide(model->get(), 0.1, 0.01, 151);
  std::vector<std::vector<double>> columns;
  for (int k = 0; k <= 150; k += 30) columns.push_back(walk[static_cast<std::size_t>(k)]);
  std::vector<FilmRow> rows{FilmRow{model->get(), "M0", columns}};
  const ViewPlan plan = plan_view(std::vector<PosedModel>{{model->get(), walk}});
  FilmStripOptions options;
  options.tile_width = options.tile_height = 160;
  options.camera_direction = plan.direction;
  options.follow = true;
  const Image strip = render_film_strip(rows, options);
  write_png((out_dir() / "follow.png").string(), strip);
  // Tiles: grid starts after the label column and the header; find them from the layout.
  const int label_w = text_width("M0", FontSize::kLarge) + 8;
  const int x0 = options.margin + label_w;
  const int y0 = options.margin + text_height(FontSize::kLarge) + 4;
  for (int c = 0; c < 6; ++c) {
    const double f = character_height_fraction(strip, x0 + c * (160 + options.gap), y0, 160, 160);
    EXPECT_GT(f, 0.5) << "tile " << c << " shows the character at least half the tile tall";
  }
  // Without following, the same strip shows a character a fraction of that size.
  options.follow = false;
  const Image fixed = render_film_strip(rows, options);
  write_png((out_dir() / "fixed.png").string(), fixed);
  EXPECT_LT(character_height_fraction(fixed, x0, y0, 160, 160), 0.25);
}

// Green pixels of a picture (the ground strips' colour): count and bounding box.
struct GreenArea {
  int count = 0, x0 = 1 << 20, x1 = -1, y0 = 1 << 20, y1 = -1;
};
GreenArea green_area(const Image& image) {
  GreenArea a;
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      const Rgb p = image.pixel(x, y);
      if (p.g < p.r + 40 || p.g < p.b + 40) continue;
      ++a.count;
      a.x0 = std::min(a.x0, x);
      a.x1 = std::max(a.x1, x);
      a.y0 = std::min(a.y0, y);
      a.y1 = std::max(a.y1, y);
    }
  }
  return a;
}

// A 3D task's landing point with a radius is drawn as a disc there, not as a strip across
// the track.
TEST(GroundStrips, A3dLandingPointIsADiscOnTheFloor) {
  const Task task = load_task(std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_backwards.toml");
  const std::vector<GroundStrip> strips = task_ground_strips(task);
  ASSERT_EQ(strips.size(), 1u);
  EXPECT_DOUBLE_EQ(strips[0].radius, 0.25);
  EXPECT_DOUBLE_EQ(strips[0].y, 0.0);
  EXPECT_DOUBLE_EQ(strips[0].x_min, -1.05);
  EXPECT_DOUBLE_EQ(strips[0].x_max, -0.55);

  const auto model = character("human3d");
  std::vector<std::vector<double>> frames{std::vector<double>(model->get()->qpos0, model->get()->qpos0 + model->get()->nq)};
  std::vector<FilmRow> rows{FilmRow{model->get(), "M0", frames}};
  FilmStripOptions options;
  options.tile_width = options.tile_height = 200;
  options.camera_direction = plan_view(std::vector<PosedModel>{{model->get(), frames}}).direction;
  options.ground_strips = strips;
  const Image disc = render_film_strip(rows, options);
  write_png((out_dir() / "disc.png").string(), disc);
  GroundStrip across = strips[0];
  across.radius = 0;
  options.ground_strips = {across};
  const Image strip = render_film_strip(rows, options);
  write_png((out_dir() / "strip.png").string(), strip);

  const GreenArea d = green_area(disc), s = green_area(strip);
  ASSERT_GT(d.count, 100) << "the disc is in the picture";
  // Seen from above at an angle, the disc is an ellipse wider than tall, and it covers a
  // fraction of what the 2.2 m wide strip with the same extent along x covers.
  EXPECT_GT(d.x1 - d.x0, d.y1 - d.y0);
  EXPECT_LT(d.count, s.count / 2);
}

// Isolated specks: pixels brighter or darker by more than 24 grey levels than both their
// left and right neighbours, which differ little from each other. Shadow-map "acne" on a
// floor shows as such specks; edges of shadows and bodies do not.
int specks(const Image& image) {
  const auto lum = [&](int x, int y) {
    const Rgb p = image.pixel(x, y);
    return (299 * p.r + 587 * p.g + 114 * p.b) / 1000;
  };
  int n = 0;
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 1; x + 1 < image.width(); ++x) {
      const int l = lum(x - 1, y), c = lum(x, y), r = lum(x + 1, y);
      if (std::abs(l - r) < 8 && std::abs(c - l) > 24 && std::abs(c - r) > 24 && (c - l > 0) == (c - r > 0)) ++n;
    }
  }
  return n;
}

// The 2.9 m bird robot standing: its shadow on the floor is clean, without the speckled
// self-shadowing a coarse shadow map leaves on a large character's floor.
TEST(Shadows, ATallCharacterLeavesNoAcneOnTheFloor) {
  const auto model = character("robot3d");
  const mjModel* m = model->get();
  std::vector<std::vector<double>> frames{std::vector<double>(m->qpos0, m->qpos0 + m->nq)};
  const ViewPlan plan = plan_view(std::vector<PosedModel>{{m, frames}});
  const SideCamera camera = fit_shared_camera(std::vector<PosedModel>{{m, frames}}, 1.0, {}, plan.direction);
  OffscreenRenderer renderer(m, 400, 400);
  const Image picture = renderer.render(frames[0], camera);
  write_png((out_dir() / "robot_shadow.png").string(), picture);
  EXPECT_LT(specks(picture), 40);
}

TEST(FilmColumns, OneStrideOfACyclicMotion) {
  PhaseTimes p;
  p.names = {"start", "s0", "s1", "s2", "s3", "s0", "s1", "s2", "s3", "s0", "s1"};
  p.begin = {0.0, 0.1, 0.4, 0.7, 1.0, 1.3, 1.6, 1.9, 2.2, 2.5, 2.8};
  int first = -1, length = -1;
  ASSERT_TRUE(last_stride(p, &first, &length));
  EXPECT_EQ(first, 5);
  EXPECT_EQ(length, 4);
  StepRecorder r;
  r.nq = 1;
  r.nu = 1;
  r.timestep = 0.01;
  r.qpos0 = {0.0};
  for (int k = 0; k < 300; ++k) {
    r.qpos.push_back((k + 1) * 0.01);  // qpos = time
    r.ctrl.push_back(0.0);
  }
  const FilmColumns c = motion_film_columns(p, r);
  ASSERT_EQ(c.names.size(), 9u);
  EXPECT_EQ(c.names[0], "s0");
  EXPECT_EQ(c.names[1], "mid s0");
  EXPECT_EQ(c.names[8], "s0");
  EXPECT_NEAR(c.frames[0][0], 1.3, 1e-9);
  EXPECT_NEAR(c.frames[1][0], 1.45, 1e-9);
  EXPECT_NEAR(c.frames[8][0], 2.5, 1e-9);

  // A state that ends almost at once (a strike state whose foot is already down) gets no
  // middle column: it would repeat the moments around it.
  PhaseTimes quick = p;
  quick.begin = {0.0, 0.1, 0.4, 0.7, 1.0, 1.3, 1.58, 1.6, 2.2, 2.5, 2.8};
  const FilmColumns q = motion_film_columns(quick, r);
  EXPECT_EQ(q.names, (std::vector<std::string>{"s0", "mid s0", "s1", "s2", "mid s2", "s3", "mid s3", "s0"}));

  // Phases that do not repeat: each phase's begin, then the end.
  PhaseTimes once;
  once.names = {"start", "lean", "never", "settle"};
  once.begin = {0.0, 0.5, -1.0, 2.0};
  EXPECT_FALSE(last_stride(once, &first, &length));
  const FilmColumns o = motion_film_columns(once, r);
  EXPECT_EQ(o.names, (std::vector<std::string>{"start", "lean", "settle", "end"}));
  EXPECT_NEAR(o.frames[3][0], 3.0, 1e-9);

  // A walk's controller keeps each state's latest begin: the last time through each state,
  // in time order.
  PhaseTimes latest;
  latest.names = {"left_lift", "left_strike", "right_lift", "right_strike"};
  latest.begin = {2.0, 2.3, 1.4, 1.7};
  const FilmColumns l = motion_film_columns(latest, r);
  EXPECT_EQ(l.names, (std::vector<std::string>{"right_lift", "right_strike", "left_lift", "left_strike", "end"}));
  EXPECT_NEAR(l.frames[0][0], 1.4, 1e-9);

  // No phases: evenly spaced moments.
  const FilmColumns e = motion_film_columns(PhaseTimes{}, r);
  ASSERT_EQ(e.names.size(), static_cast<std::size_t>(kEvenColumns));
  EXPECT_EQ(e.names[0], "0.00 s");
  EXPECT_NEAR(e.frames.back()[0], 3.0, 1e-9);

  // A jump's events still give the jump's columns.
  PhaseTimes jump;
  jump.names = {"start", "crouch", "extend", "rise", "fall", "land"};
  jump.begin = {0.0, 0.2, 0.5, 0.8, 1.1, 1.4};
  jump.rise = 3;
  jump.fall = 4;
  jump.land = 5;
  const FilmColumns j = motion_film_columns(jump, r);
  EXPECT_EQ(j.names, (std::vector<std::string>{"crouch", "extend", "take-off", "rising", "peak", "falling",
                                                "touch-down", "end"}));
}

// A real walk (the 3D human under SIMBICON control, 12 steps, about 6 m): the film strip
// follows it, one stride from its left lift, the character large in every tile.
TEST(Walk3d, FilmStripFollowsOneStride) {
  const fs::path dir = out_dir() / "walk";
  test_support::write_walk_run(dir, "human3d", {"silly_walk_start.json"}, 12);
  const RunView run = load_run_view(dir);
  ASSERT_EQ(run.motions.size(), 1u);
  const RunMotion& walk = run.motions[0];
  const auto frames = walk.sample(10);
  const ViewPlan plan = plan_view(std::vector<PosedModel>{{walk.model->get(), frames}});
  EXPECT_TRUE(plan.three_quarter);
  EXPECT_TRUE(plan.follow) << "the walk travels "
                           << follow_anchor(walk.model->get(), frames.back())[0] - follow_anchor(walk.model->get(), frames.front())[0] << " m";
  EXPECT_NEAR(plan.heading, 0.0, 20.0) << "it walks along +x";
  const FilmColumns columns = motion_film_columns(walk.phases, walk.record);
  // The strike states end within a few steps (the swing foot is down early in them), so
  // they get no middle column.
  EXPECT_EQ(columns.names, (std::vector<std::string>{"left_lift", "mid left_lift", "left_strike", "right_lift",
                                                     "mid right_lift", "right_strike", "left_lift"}));
  write_run_film_strip(run, dir / "filmstrip.png");
  const Image strip = read_png((dir / "filmstrip.png").string());
  const int label_w = text_width("M0", FontSize::kLarge) + 8;
  const int title_h = text_height(FontSize::kMedium) + 8;
  const int x0 = 12 + label_w, y0 = 12 + title_h + text_height(FontSize::kLarge) + 4;
  for (int c = 0; c < static_cast<int>(columns.names.size()); ++c)
    EXPECT_GT(character_height_fraction(strip, x0 + c * (240 + 6), y0, 240, 240), 0.5) << "tile " << c;
}

// A run of 3D motions (the 3D human pushed three ways): its film strip is drawn
// three-quarters at evenly spaced moments (stance control reports no phases), and its
// videos have one frame per sample.
TEST(Run3d, FilmStripAndVideos) {
  const fs::path dir = out_dir() / "run3d";
  test_support::write_stance_run(dir, "human3d", {{0.3, 0, 0}, {0, 0.3, 0}, {-0.2, -0.2, 0}}, 1.0);
  const RunView run = load_run_view(dir);
  ASSERT_EQ(run.motions.size(), 3u);
  write_run_film_strip(run, dir / "filmstrip.png");
  const Image strip = read_png((dir / "filmstrip.png").string());
  EXPECT_GT(strip.width(), kEvenColumns * 240);
  EXPECT_GT(strip.height(), 3 * 240);
  RunVideoOptions video;
  video.fps = 10;
  video.tile_width = video.tile_height = 128;
  const auto paths = write_run_videos(run, video);
  ASSERT_EQ(paths.size(), 4u);
  for (const auto& p : paths) EXPECT_GT(fs::file_size(p), 1000u) << p;
}

}  // namespace
}  // namespace diverse
