// Offscreen rendering, images, film strips and videos, on a tiny planar character.
#include <gtest/gtest.h>

#include "support/cli.h"
#include <mujoco/mujoco.h>
#include <stdlib.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"
#include "render/film_strip.h"
#include "render/image.h"
#include "render/offscreen.h"
#include "render/video.h"

namespace diverse {
namespace {

// A planar walker (root: slide z, slide x, hinge y; hips and knees hinge about y), a floor
// and a box obstacle. qpos = (rootz, rootx, rooty, hip_r, knee_r, hip_l, knee_l).
constexpr char kTinyModel[] = R"(
<mujoco model="tiny_planar">
  <worldbody>
    <geom name="floor" type="plane" size="0 0 0.1" rgba="0.8 0.8 0.8 1"/>
    <geom name="box" type="box" pos="1.4 0 0.15" size="0.15 0.3 0.15" rgba="0.6 0.42 0.25 1"/>
    <body name="torso" pos="0 0 1.0">
      <joint name="rootz" type="slide" axis="0 0 1"/>
      <joint name="rootx" type="slide" axis="1 0 0"/>
      <joint name="rooty" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 0.5" size="0.08" rgba="0.25 0.45 0.8 1"/>
      <geom type="sphere" pos="0 0 0.66" size="0.11" rgba="0.95 0.78 0.62 1"/>
      <body name="thigh_r" pos="0 -0.06 0">
        <joint name="hip_r" type="hinge" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.45" size="0.06" rgba="0.85 0.35 0.3 1"/>
        <body name="shin_r" pos="0 0 -0.45">
          <joint name="knee_r" type="hinge" axis="0 1 0"/>
          <geom type="capsule" fromto="0 0 0 0 0 -0.42" size="0.05" rgba="0.85 0.35 0.3 1"/>
          <geom type="capsule" fromto="-0.04 0 -0.45 0.14 0 -0.45" size="0.04"
                rgba="0.3 0.3 0.3 1"/>
        </body>
      </body>
      <body name="thigh_l" pos="0 0.06 0">
        <joint name="hip_l" type="hinge" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.45" size="0.06" rgba="0.55 0.25 0.25 1"/>
        <body name="shin_l" pos="0 0 -0.45">
          <joint name="knee_l" type="hinge" axis="0 1 0"/>
          <geom type="capsule" fromto="0 0 0 0 0 -0.42" size="0.05" rgba="0.55 0.25 0.25 1"/>
          <geom type="capsule" fromto="-0.04 0 -0.45 0.14 0 -0.45" size="0.04"
                rgba="0.2 0.2 0.2 1"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
)";

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;

ModelPtr load_model(const std::string& xml) {
  mjVFS vfs;
  mj_defaultVFS(&vfs);
  mj_makeEmptyFileVFS(&vfs, "model.xml", static_cast<int>(xml.size()));
  std::memcpy(vfs.filedata[mj_findFileVFS(&vfs, "model.xml")], xml.data(), xml.size());
  char error[1000] = "";
  ModelPtr model(mj_loadXML("model.xml", &vfs, error, sizeof error));
  mj_deleteVFS(&vfs);
  EXPECT_TRUE(model) << error;
  return model;
}

// The same character with 30% longer shins: a different body shape for multi-model rows.
std::string long_legged_model() {
  std::string xml = kTinyModel;
  for (std::size_t at; (at = xml.find("0 0 -0.42")) != std::string::npos;) {
    xml.replace(at, 9, "0 0 -0.55");
  }
  return xml;
}

// A short crouch-and-jump: standing, crouched, airborne, landed further on.
std::vector<std::vector<double>> jump_frames() {
  return {{0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
          {-0.25, 0.2, 0.3, -1.0, 1.6, -1.0, 1.6},
          {0.4, 0.9, 0.0, -0.9, 1.2, -0.9, 1.2},
          {0.0, 1.7, 0.1, -0.3, 0.5, -0.2, 0.4}};
}

double variance(const Image& image) {
  double sum = 0.0;
  double sum2 = 0.0;
  const std::size_t n = static_cast<std::size_t>(image.width()) * image.height() * 3;
  for (std::size_t i = 0; i < n; ++i) {
    sum += image.data()[i];
    sum2 += image.data()[i] * static_cast<double>(image.data()[i]);
  }
  return sum2 / n - (sum / n) * (sum / n);
}

::testing::AssertionResult near(Rgb a, Rgb b, int tolerance = 2) {
  if (std::abs(a.r - b.r) <= tolerance && std::abs(a.g - b.g) <= tolerance &&
      std::abs(a.b - b.b) <= tolerance) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "(" << int{a.r} << "," << int{a.g} << "," << int{a.b}
                                       << ") vs (" << int{b.r} << "," << int{b.g} << ","
                                       << int{b.b} << ")";
}

Image crop(const Image& image, int x, int y, int width, int height) {
  Image out(width, height);
  out.paste(image, -x, -y);
  return out;
}

class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "render_test-XXXXXX").string();
    path_ = mkdtemp(pattern.data());
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

std::string run_and_read(const std::string& command) { return cli_test::shell_output(command); }

// ---------------------------------------------------------------------------- images

TEST(ImageTest, FillAndPasteClipToTheImage) {
  Image image(4, 3, Rgb{0, 0, 0});
  image.fill_rect(-2, 1, 4, 10, Rgb{9, 8, 7});  // covers x 0..1, y 1..2
  EXPECT_EQ(image.pixel(0, 0), (Rgb{0, 0, 0}));
  EXPECT_EQ(image.pixel(1, 2), (Rgb{9, 8, 7}));
  EXPECT_EQ(image.pixel(2, 2), (Rgb{0, 0, 0}));

  Image patch(2, 2, Rgb{1, 2, 3});
  image.paste(patch, 3, -1);  // only (3, 0) lands inside
  EXPECT_EQ(image.pixel(3, 0), (Rgb{1, 2, 3}));
  EXPECT_EQ(image.pixel(3, 1), (Rgb{0, 0, 0}));
  image.paste(patch, 10, 10);  // entirely outside: no effect, no crash
  EXPECT_THROW(Image(-1, 2), std::invalid_argument);
}

TEST(ImageTest, PngRoundTripIsExact) {
  TempDir dir;
  Image image(5, 3);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 5; ++x) {
      image.set_pixel(x, y,
                      Rgb{static_cast<std::uint8_t>(50 * x), static_cast<std::uint8_t>(80 * y),
                          static_cast<std::uint8_t>(x * y)});
    }
  }
  write_png(dir.file("a.png"), image);
  EXPECT_EQ(read_png(dir.file("a.png")), image);
}

TEST(ImageTest, PngErrorsNameThePath) {
  TempDir dir;
  try {
    read_png(dir.file("missing.png"));
    FAIL() << "expected UserError";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find(dir.file("missing.png") + ": cannot read PNG"),
              std::string::npos)
        << e.what();
  }
  try {
    write_png(dir.file("no/such/dir/a.png"), Image(2, 2));
    FAIL() << "expected UserError";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("no/such/dir/a.png: cannot write PNG"), std::string::npos)
        << e.what();
  }
}

TEST(ImageTest, TextIsDrawnInsideItsBox) {
  for (FontSize size : {FontSize::kSmall, FontSize::kMedium, FontSize::kLarge}) {
    const int w = text_width("M0", size);
    const int h = text_height(size);
    EXPECT_GT(w, text_width("I", size));
    Image image(w + 20, h + 20, Rgb{255, 255, 255});
    draw_text(image, "M0", 10, 10, Rgb{0, 0, 0}, size);
    int ink = 0;
    for (int y = 0; y < image.height(); ++y) {
      for (int x = 0; x < image.width(); ++x) {
        if (image.pixel(x, y) == Rgb{0, 0, 0}) {
          ++ink;
          EXPECT_TRUE(x >= 10 && x < 10 + w && y >= 10 && y < 10 + h) << x << "," << y;
        }
      }
    }
    EXPECT_GT(ink, 2 * h);  // two glyphs' strokes at least as tall as the line
  }
  EXPECT_EQ(text_height(FontSize::kSmall), 15);
  EXPECT_EQ(text_height(FontSize::kLarge), 28);
  // Outside printable ASCII shows as '?'.
  EXPECT_EQ(text_width("\x01\xff", FontSize::kMedium), 2 * text_width("?", FontSize::kMedium));
  // Centred and right-aligned text ends up where asked.
  Image a(100, 40, Rgb{255, 255, 255});
  Image b(100, 40, Rgb{255, 255, 255});
  draw_text(a, "AB", 50, 5, Rgb{0, 0, 0}, FontSize::kMedium, Align::kCenter);
  draw_text(b, "AB", 50 - text_width("AB", FontSize::kMedium) / 2, 5, Rgb{0, 0, 0});
  EXPECT_EQ(a, b);
}

TEST(FilmStripTest, ColumnLabelsCountLikeSpreadsheets) {
  EXPECT_EQ(column_label(0), "A");
  EXPECT_EQ(column_label(25), "Z");
  EXPECT_EQ(column_label(26), "AA");
  EXPECT_EQ(column_label(27), "AB");
  EXPECT_EQ(column_label(701), "ZZ");
  EXPECT_EQ(column_label(702), "AAA");
}

// ---------------------------------------------------------------------------- camera

TEST(CameraTest, PoseBoundsAreExactForCapsulesAndSpheres) {
  const ModelPtr model = load_model(kTinyModel);
  const std::vector<std::vector<double>> standing = {std::vector<double>(model->nq, 0.0)};
  const Bounds b = pose_bounds(model.get(), standing);
  // Head sphere top 1 + 0.66 + 0.11; foot capsules at z 0.1 with radius 0.04 reaching
  // x 0.14 + 0.04; the head is the widest part behind (x -0.11). The world box is excluded.
  EXPECT_NEAR(b.hi[2], 1.77, 1e-9);
  EXPECT_NEAR(b.lo[2], 0.06, 1e-9);
  EXPECT_NEAR(b.hi[0], 0.18, 1e-9);
  EXPECT_NEAR(b.lo[0], -0.11, 1e-9);
  EXPECT_NEAR(b.lo[1], -0.06 - 0.06, 1e-9);  // right thigh at y -0.06, radius 0.06
  EXPECT_NEAR(b.hi[1], 0.06 + 0.06, 1e-9);

  // Moving the root along x moves the box by as much.
  std::vector<std::vector<double>> moved = standing;
  moved[0][1] = 2.0;
  EXPECT_NEAR(pose_bounds(model.get(), moved).hi[0], 2.18, 1e-9);
  const std::vector<std::vector<double>> wrong = {std::vector<double>(3, 0.0)};
  EXPECT_THROW(pose_bounds(model.get(), wrong), std::invalid_argument);
}

TEST(CameraTest, PoseBoundsAreExactForATiltedCapsule) {
  const ModelPtr model = load_model(
      R"(<mujoco><worldbody><body pos="0 0 1"><joint type="hinge" axis="0 1 0"/>
         <geom type="capsule" fromto="0 0 0 0 0 0.5" size="0.1"/></body></worldbody></mujoco>)");
  const double angle = 0.7;  // rad about +y: the capsule's far end tips towards +x
  const std::vector<std::vector<double>> frames = {{angle}};
  const Bounds b = pose_bounds(model.get(), frames);
  // The capsule's box is its end points' box grown by its radius.
  EXPECT_NEAR(b.lo[0], -0.1, 1e-9);
  EXPECT_NEAR(b.hi[0], 0.5 * std::sin(angle) + 0.1, 1e-9);
  EXPECT_NEAR(b.lo[2], 1.0 - 0.1, 1e-9);
  EXPECT_NEAR(b.hi[2], 1.0 + 0.5 * std::cos(angle) + 0.1, 1e-9);
  EXPECT_NEAR(b.hi[1], 0.1, 1e-9);
}

TEST(CameraTest, FloorHeightComesFromTheWorldPlane) {
  const ModelPtr model = load_model(kTinyModel);
  ASSERT_TRUE(floor_height(model.get()).has_value());
  EXPECT_EQ(*floor_height(model.get()), 0.0);
  const ModelPtr no_floor = load_model(
      R"(<mujoco><worldbody><body><joint type="slide" axis="1 0 0"/><geom size="0.1"/></body>
         </worldbody></mujoco>)");
  EXPECT_FALSE(floor_height(no_floor.get()).has_value());
}

// The fitted camera sees every corner of the box, and the box fills the view: some corner
// lies on the edge of the view shrunk by the margin.
TEST(CameraTest, FittedCameraFramesTheBoxTightly) {
  Bounds box;
  box.add({-0.5, -0.2, 0.0});
  box.add({2.5, 0.2, 1.8});
  for (const double aspect : {1.0, 2.0, 0.5}) {
    SideCamera direction;
    const double margin = 0.1;
    const SideCamera cam = fit_side_camera(box, aspect, direction, margin);
    const double az = cam.azimuth * std::numbers::pi / 180;
    const double el = cam.elevation * std::numbers::pi / 180;
    const std::array<double, 3> f{std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                                  std::sin(el)};
    const std::array<double, 3> u{-std::sin(el) * std::cos(az), -std::sin(el) * std::sin(az),
                                  std::cos(el)};
    const std::array<double, 3> r{f[1] * u[2] - f[2] * u[1], f[2] * u[0] - f[0] * u[2],
                                  f[0] * u[1] - f[1] * u[0]};
    EXPECT_NEAR(r[0], 1.0, 1e-12);  // azimuth 90: world +x points right on screen
    const double tan_v = std::tan(0.5 * cam.fovy * std::numbers::pi / 180);
    double fill = 0.0;
    for (int corner = 0; corner < 8; ++corner) {
      std::array<double, 3> q{};
      for (int i = 0; i < 3; ++i) {
        q[i] = ((corner >> i & 1) ? box.hi[i] : box.lo[i]) - cam.lookat[i];
      }
      const double depth = cam.distance + q[0] * f[0] + q[1] * f[1] + q[2] * f[2];
      const double x = (q[0] * r[0] + q[1] * r[1] + q[2] * r[2]) / (depth * tan_v * aspect);
      const double y = (q[0] * u[0] + q[1] * u[1] + q[2] * u[2]) / (depth * tan_v);
      EXPECT_LE(std::abs(x), 1.0 - margin + 1e-9);
      EXPECT_LE(std::abs(y), 1.0 - margin + 1e-9);
      fill = std::max({fill, std::abs(x), std::abs(y)});
    }
    EXPECT_NEAR(fill, 1.0 - margin, 1e-9) << "aspect " << aspect;
  }
}

// ---------------------------------------------------------------------------- renderer

TEST(OffscreenTest, RendersPosesDeterministicallyOnASky) {
  const ModelPtr model = load_model(kTinyModel);
  const auto frames = jump_frames();
  const SideCamera camera =
      fit_shared_camera(std::vector<PosedModel>{{model.get(), frames}}, 4.0 / 3.0, {});
  RenderStyle style;
  OffscreenRenderer renderer(model.get(), 160, 120, style);
  const Image a = renderer.render(frames[0], camera);
  ASSERT_EQ(a.width(), 160);
  ASSERT_EQ(a.height(), 120);
  EXPECT_GT(variance(a), 100.0);
  // Top-left: sky, the top colour of the gradient.
  EXPECT_TRUE(near(a.pixel(0, 0), style.sky_top));
  // Same pose, same picture; another pose, another picture.
  EXPECT_EQ(renderer.render(frames[0], camera), a);
  EXPECT_NE(renderer.render(frames[2], camera), a);
  EXPECT_THROW(renderer.render(std::vector<double>(3, 0.0), camera), std::invalid_argument);
}

TEST(OffscreenTest, GroundStripsShowInTheirColour) {
  const ModelPtr model = load_model(kTinyModel);
  const std::vector<double> pose(model->nq, 0.0);
  SideCamera camera;
  camera.lookat = {1.0, 0.0, 0.8};
  camera.distance = 6.0;
  OffscreenRenderer renderer(model.get(), 120, 120);
  const Image plain = renderer.render(pose, camera);
  const Rgb green{40, 200, 40};
  renderer.set_ground_strips({GroundStrip{1.8, 2.4, green}});
  const Image marked = renderer.render(pose, camera);
  int strip_pixels = 0;
  for (int y = 0; y < marked.height(); ++y) {
    for (int x = 0; x < marked.width(); ++x) {
      const Rgb p = marked.pixel(x, y);
      if (p.g > 150 && p.r < 100 && p.b < 100) ++strip_pixels;
      if (plain.pixel(x, y).g > 150 && plain.pixel(x, y).r < 100) ADD_FAILURE() << "green before";
    }
  }
  EXPECT_GT(strip_pixels, 100);
}

TEST(OffscreenTest, ModelsWithoutOffscreenSizeOrFloorRender) {
  // No <visual> offscreen size (MuJoCo's default is 640x480) and a picture larger than
  // it; no floor plane and no light either.
  const ModelPtr model = load_model(
      R"(<mujoco><worldbody><body pos="0 0 1"><joint type="hinge" axis="0 1 0"/>
         <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.1" rgba="1 0 0 1"/></body>
         </worldbody></mujoco>)");
  ASSERT_EQ(model->vis.global.offwidth, 640);
  OffscreenRenderer renderer(model.get(), 700, 500);
  SideCamera camera;
  camera.lookat = {0.25, 0.0, 1.0};
  camera.distance = 3.0;
  const Image image = renderer.render(std::vector<double>{0.0}, camera);
  ASSERT_EQ(image.width(), 700);
  // The red capsule is at the centre of the picture; the sky is everywhere else.
  const Rgb centre = image.pixel(350, 250);
  EXPECT_GT(centre.r, 120);
  EXPECT_LT(centre.g, 80);
  EXPECT_TRUE(near(image.pixel(699, 499), RenderStyle{}.sky_bottom));
  // The caller's model is untouched.
  EXPECT_EQ(model->vis.global.offwidth, 640);
}

TEST(OffscreenTest, RenderersWorkOnSeveralThreadsAtOnce) {
  const ModelPtr model = load_model(kTinyModel);
  const auto frames = jump_frames();
  const SideCamera camera =
      fit_shared_camera(std::vector<PosedModel>{{model.get(), frames}}, 1.0, {});
  std::vector<Image> expected;
  {
    OffscreenRenderer renderer(model.get(), 64, 64);
    for (const auto& q : frames) expected.push_back(renderer.render(q, camera));
  }
  std::vector<std::vector<Image>> got(2);
  std::vector<std::thread> threads;
  for (int t = 0; t < 2; ++t) {
    threads.emplace_back([&, t] {
      OffscreenRenderer renderer(model.get(), 64, 64);
      for (const auto& q : frames) got[t].push_back(renderer.render(q, camera));
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(got[0], expected);
  EXPECT_EQ(got[1], expected);
}

// ---------------------------------------------------------------------------- film strip

TEST(FilmStripTest, WritesTwoDifferentRowsOfTheExpectedSize) {
  const ModelPtr model = load_model(kTinyModel);
  const ModelPtr long_legs = load_model(long_legged_model());
  auto other = jump_frames();
  for (auto& q : other) {
    q[3] += 0.6;  // right hip forward, left hip back: a split-legged variation
    q[5] -= 0.6;
  }
  const std::vector<FilmRow> rows = {{model.get(), "M0", jump_frames()},
                                     {long_legs.get(), "M1", other}};
  FilmStripOptions options;
  options.tile_width = 120;
  options.tile_height = 100;
  options.ground_strips = {GroundStrip{1.5, 2.0}};
  TempDir dir;
  const std::string path = dir.file("strip.png");
  write_film_strip(path, rows, options);

  const Image strip = read_png(path);
  const int label_w = text_width("M0", FontSize::kLarge) + 8;
  const int header_h = text_height(FontSize::kLarge) + 4;
  const int grid_x = options.margin + label_w;
  const int grid_y = options.margin + header_h;
  EXPECT_EQ(strip.width(), grid_x + 4 * 120 + 3 * options.gap + options.margin);
  EXPECT_EQ(strip.height(), grid_y + 2 * 100 + options.gap + options.margin);
  EXPECT_EQ(strip, render_film_strip(rows, options));
  EXPECT_GT(variance(strip), 100.0);

  for (int c = 0; c < 4; ++c) {
    const int x = grid_x + c * (120 + options.gap);
    const Image top = crop(strip, x, grid_y, 120, 100);
    const Image bottom = crop(strip, x, grid_y + 100 + options.gap, 120, 100);
    EXPECT_GT(variance(top), 100.0) << "column " << c;
    EXPECT_NE(top, bottom) << "column " << c;
  }
  // The column label "A" is drawn above the first tile.
  const Image header = crop(strip, grid_x, options.margin, 120, header_h);
  EXPECT_GT(variance(header), 10.0);
}

TEST(FilmStripTest, AnEmptyFrameLeavesItsTileEmpty) {
  // A motion that never reached a column's phase event (e.g. it fell before take-off)
  // passes an empty qpos there: the tile stays background, the others are drawn.
  const ModelPtr model = load_model(kTinyModel);
  auto frames = jump_frames();
  frames[1].clear();
  const std::vector<FilmRow> rows = {{model.get(), "M0", frames}};
  FilmStripOptions options;
  options.tile_width = 120;
  options.tile_height = 100;
  const Image strip = render_film_strip(rows, options);
  const int label_w = text_width("M0", FontSize::kLarge) + 8;
  const int grid_x = options.margin + label_w;
  const int grid_y = options.margin + text_height(FontSize::kLarge) + 4;
  const Image drawn = crop(strip, grid_x, grid_y, 120, 100);
  const Image empty = crop(strip, grid_x + 120 + options.gap, grid_y, 120, 100);
  EXPECT_GT(variance(drawn), 100.0);
  EXPECT_LT(variance(empty), 1.0);
}

TEST(FilmStripTest, RowsNeedAModel) {
  const std::vector<FilmRow> rows = {{nullptr, "M0", jump_frames()}};
  EXPECT_THROW(render_film_strip(rows), std::invalid_argument);
}

// ---------------------------------------------------------------------------- video

int probe_frames(const std::string& path) {
  const std::string out = run_and_read(
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames "
      "-of csv=p=0 '" + path + "' 2>/dev/null");
  return out.empty() ? -1 : std::atoi(out.c_str());
}

bool have_ffprobe() { return !run_and_read("command -v ffprobe").empty(); }

TEST(VideoTest, WritesEveryFrame) {
  ASSERT_FALSE(find_ffmpeg().empty()) << "ffmpeg is needed (scripts/setup.sh installs it)";
  TempDir dir;
  const std::string path = dir.file("ten.mp4");
  VideoWriter writer(path, 65, 47, VideoOptions{10.0, 23});  // odd sizes are padded
  for (int i = 0; i < 10; ++i) {
    Image frame(65, 47, Rgb{20, 20, 20});
    frame.fill_rect(5 * i, 10, 8, 8, Rgb{250, 200, 0});
    writer.add_frame(frame);
  }
  EXPECT_THROW(writer.add_frame(Image(10, 10)), std::invalid_argument);
  writer.close();
  EXPECT_EQ(writer.frames(), 10);
  ASSERT_TRUE(std::filesystem::exists(path));
  EXPECT_GT(std::filesystem::file_size(path), 0u);
  if (have_ffprobe()) {
    EXPECT_EQ(probe_frames(path), 10);
  }
}

TEST(VideoTest, SideBySideHoldsTheLastFrameOfShorterMotions) {
  const ModelPtr model = load_model(kTinyModel);
  std::vector<VideoTrack> tracks(2);
  for (int k = 0; k < 2; ++k) {
    tracks[k].model = model.get();
    tracks[k].label = "M" + std::to_string(k);
    for (int t = 0; t < 6 + 4 * k; ++t) {
      tracks[k].frames.push_back(
          {0.05 * t, 0.1 * t * (k + 1), 0.0, -0.1 * t, 0.2 * t, 0.1 * t, 0.0});
    }
  }
  SideBySideOptions options;
  options.tile_width = 96;
  options.tile_height = 96;
  options.title = "two motions";
  TempDir dir;
  const std::string path = dir.file("side.mp4");
  write_side_by_side_video(path, tracks, options);
  ASSERT_TRUE(std::filesystem::exists(path));
  EXPECT_GT(std::filesystem::file_size(path), 0u);
  if (have_ffprobe()) {
    EXPECT_EQ(probe_frames(path), 10);  // the longer track's length
  }

  EXPECT_THROW(write_side_by_side_video(path, {}, options), std::invalid_argument);
}

TEST(VideoTest, FfmpegFailureIsAUserError) {
  TempDir dir;
  const std::string path = dir.file("no/such/dir/out.mp4");
  try {
    VideoWriter writer(path, 16, 16);
    writer.add_frame(Image(16, 16));
    writer.close();
    FAIL() << "expected UserError";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": ffmpeg failed (exit status"),
              std::string::npos)
        << e.what();
  }
}

TEST(VideoTest, MissingFfmpegIsAUserError) {
  const std::string saved = std::getenv("PATH") ? std::getenv("PATH") : "";
  TempDir dir;  // an empty directory: no ffmpeg in it
  setenv("PATH", dir.file("").c_str(), 1);
  EXPECT_TRUE(find_ffmpeg().empty());
  try {
    VideoWriter writer(dir.file("a.mp4"), 16, 16);
    ADD_FAILURE() << "expected UserError";
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(),
                 "ffmpeg: not found on PATH; install it (Debian: apt-get install ffmpeg) to "
                 "write videos");
  }
  setenv("PATH", saved.c_str(), 1);
}

}  // namespace
}  // namespace diverse
