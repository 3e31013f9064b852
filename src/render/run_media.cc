#include "render/run_media.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "render/film_columns.h"
#include "render/film_strip.h"
#include "render/video.h"
#include "render/view_plan.h"

namespace diverse {
namespace fs = std::filesystem;

namespace {

constexpr Rgb kText{34, 34, 34};
constexpr Rgb kMeets{24, 118, 48};    // constraint met
constexpr Rgb kMisses{178, 34, 34};   // constraint violated
constexpr Rgb kBackground{255, 255, 255};

// Draws a motion's label and status into the top-left corner of its tile.
void label_tile(Image& tile, const RunMotion& m, const std::string& note) {
  draw_text(tile, m.label, 10, 8, kText, FontSize::kLarge);
  const int x = 10 + text_width(m.label, FontSize::kLarge) + 10;
  draw_text(tile, m.status(), x, 12, m.constraint == 0.0 ? kMeets : kMisses, FontSize::kMedium);
  if (!note.empty())
    draw_text(tile, note, tile.width() - 10, tile.height() - 8 - text_height(FontSize::kSmall), kText,
              FontSize::kSmall, Align::kRight);
}

std::string time_stamp(double t) {
  char text[32];
  std::snprintf(text, sizeof text, "t = %.2f s", t);
  return text;
}

}  // namespace

std::string fitting_title(const std::vector<std::string>& titles, const std::string& stamp, int width, int gap) {
  if (titles.empty()) return "";
  const int room = width - 3 * gap - text_width(stamp, FontSize::kMedium);
  for (const std::string& title : titles)
    if (text_width(title, FontSize::kMedium) <= room) return title;
  return titles.back();
}

std::vector<GroundStrip> run_ground_strips(const RunView& run) {
  return run.task ? task_ground_strips(*run.task) : std::vector<GroundStrip>{};
}

void write_run_film_strip(const RunView& run, const fs::path& png) {
  std::vector<FilmRow> rows;
  std::vector<std::string> names;
  for (const RunMotion& m : run.motions) {
    FilmColumns columns = motion_film_columns(m.phases, m.record);
    if (columns.names.size() > names.size()) names = columns.names;
    rows.push_back(FilmRow{m.model->get(), m.label, std::move(columns.frames)});
  }
  // The direction and whether to follow come from the whole motions, not only the tiles.
  std::vector<std::vector<std::vector<double>>> all(run.motions.size());
  std::vector<PosedModel> posed;
  for (std::size_t i = 0; i < run.motions.size(); ++i) {
    all[i] = run.motions[i].sample(10.0);
    posed.push_back({run.motions[i].model->get(), all[i]});
  }
  const ViewPlan plan = plan_view(posed);
  FilmStripOptions film;
  film.title = film_title(run.task_name + ", metric " + run.metric, names);
  film.ground_strips = run_ground_strips(run);
  film.camera_direction = plan.direction;
  film.follow = plan.follow;
  fs::create_directories(png.has_parent_path() ? png.parent_path() : fs::path("."));
  write_film_strip(png.string(), rows, film);
}

std::vector<fs::path> write_run_videos(const RunView& run, const RunVideoOptions& options) {
  if (run.motions.empty()) throw std::invalid_argument("write_run_videos: no motions");
  const int tile_w = options.tile_width, tile_h = options.tile_height;
  const double speed = options.speed;

  // Frames of every motion at the video rate, and one camera fitted to all of them.
  std::vector<std::vector<std::vector<double>>> frames;
  std::vector<PosedModel> posed;
  std::size_t length = 0;
  for (const RunMotion& m : run.motions) frames.push_back(m.sample(options.fps, speed));
  for (std::size_t i = 0; i < run.motions.size(); ++i) {
    posed.push_back({run.motions[i].model->get(), frames[i]});
    length = std::max(length, frames[i].size());
  }
  RenderStyle style;
  const std::vector<GroundStrip> strips = run_ground_strips(run);
  const ViewPlan plan = plan_view(posed);
  const double aspect = static_cast<double>(tile_w) / tile_h;
  // Following: each tile's camera moves with its own character's root, averaged over a
  // second of motion time so the stride's sway does not shake the picture.
  std::vector<std::vector<std::array<double, 3>>> anchors(run.motions.size());
  if (plan.follow) {
    const int half_window = std::max(1, static_cast<int>(std::lround(0.5 * options.fps / speed)));
    for (std::size_t i = 0; i < run.motions.size(); ++i)
      anchors[i] = follow_anchors(run.motions[i].model->get(), frames[i], half_window);
  }
  const SideCamera camera =
      plan.follow ? fit_following_camera(posed, anchors, aspect, plan.direction, 0.06)
                  : fit_shared_camera(posed, aspect, strips, plan.direction, 0.06);
  std::vector<std::unique_ptr<OffscreenRenderer>> renderers;
  for (const RunMotion& m : run.motions) {
    renderers.push_back(std::make_unique<OffscreenRenderer>(m.model->get(), tile_w, tile_h, style));
    renderers.back()->set_ground_strips(strips);
  }

  // Layout: a header line (what, speed, time), then the tiles.
  const std::string speed_note = speed == 1.0 ? "real time" : speed == 0.5 ? "half speed" : "";
  const int gap = 6;
  const int header_h = text_height(FontSize::kMedium) + 2 * gap;
  const int n = static_cast<int>(run.motions.size());
  const int columns = std::clamp(options.columns, 1, n);
  const int rows = (n + columns - 1) / columns;
  const int all_w = columns * tile_w + (columns + 1) * gap;
  const int all_h = header_h + rows * tile_h + (rows + 1) * gap;
  const int one_w = tile_w + 2 * gap;
  const int one_h = header_h + tile_h + 2 * gap;

  const fs::path video_dir = run.dir / "videos";
  fs::create_directories(video_dir);
  VideoOptions video;
  video.fps = options.fps;
  std::vector<fs::path> paths;
  std::vector<std::unique_ptr<VideoWriter>> writers;
  for (const RunMotion& m : run.motions) {
    paths.push_back(video_dir / std::string("m").append(std::to_string(m.index)).append(".mp4"));
    writers.push_back(std::make_unique<VideoWriter>(paths.back().string(), one_w, one_h, video));
  }
  paths.push_back(video_dir / "all.mp4");
  VideoWriter all(paths.back().string(), all_w, all_h, video);

  std::string all_title = run.task_name;
  all_title.append(", metric ").append(run.metric).append(", ").append(std::to_string(n));
  all_title.append(" motions");
  if (!speed_note.empty()) all_title.append(", ").append(speed_note);
  // Each header chosen once, to fit beside the motion's last (widest) time stamp.
  const std::string note = speed_note.empty() ? "" : ", " + speed_note;
  const std::string last_stamp = time_stamp(static_cast<double>(length) * speed / options.fps);
  all_title = fitting_title({all_title, run.task_name + note, run.task_name}, last_stamp, all_w, gap);
  std::vector<std::string> single_titles;
  for (std::size_t k = 0; k < run.motions.size(); ++k) {
    const std::string& label = run.motions[k].label;
    const std::string stamp = time_stamp(static_cast<double>(frames[k].size()) * speed / options.fps);
    single_titles.push_back(fitting_title({run.task_name + " " + label + note, label + note, label}, stamp, one_w, gap));
  }
  Image canvas(all_w, all_h, kBackground);
  Image single(one_w, one_h, kBackground);
  std::vector<Image> last(run.motions.size());  // a finished motion holds its last tile
  for (std::size_t t = 0; t < length; ++t) {
    const std::string stamp = time_stamp(static_cast<double>(t) * speed / options.fps);
    canvas.fill_rect(0, 0, all_w, header_h, kBackground);
    draw_text(canvas, all_title, gap, gap, kText, FontSize::kMedium);
    draw_text(canvas, stamp, all_w - gap, gap, kText, FontSize::kMedium, Align::kRight);
    for (int i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const RunMotion& m = run.motions[k];
      if (t < frames[k].size()) {
        last[k] = renderers[k]->render(frames[k][t], plan.follow ? at_anchor(camera, anchors[k][t]) : camera);
        label_tile(last[k], m, t + 1 == frames[k].size() ? "end" : "");
        single.fill(kBackground);
        draw_text(single, single_titles[k], gap, gap, kText, FontSize::kMedium);
        draw_text(single, stamp, one_w - gap, gap, kText, FontSize::kMedium, Align::kRight);
        single.paste(last[k], gap, header_h + gap);
        writers[k]->add_frame(single);
        if (t + 1 == frames[k].size()) writers[k]->close();
      }
      canvas.paste(last[k], gap + (i % columns) * (tile_w + gap),
                   header_h + gap + (i / columns) * (tile_h + gap));
    }
    all.add_frame(canvas);
  }
  all.close();
  return paths;
}

}  // namespace diverse
