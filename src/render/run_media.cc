#include "render/run_media.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/error.h"
#include "io/files.h"
#include "io/motion_record.h"
#include "render/film_strip.h"
#include "render/video.h"
#include "render/film_columns.h"
#include "render/view_plan.h"
#include "task/task.h"

namespace diverse {
namespace fs = std::filesystem;

namespace {

constexpr Rgb kText{34, 34, 34};
constexpr Rgb kMeets{24, 118, 48};    // constraint met
constexpr Rgb kMisses{178, 34, 34};   // constraint violated
constexpr Rgb kBackground{255, 255, 255};

// (Built with append: GCC 12 warns falsely (-Wrestrict) on "literal" + std::string.)
std::string numbered(char prefix, std::size_t i) {
  std::string s(1, prefix);
  s.append(std::to_string(i));
  return s;
}

RunMotion read_motion(const fs::path& dir, std::size_t i, const nlohmann::json& entry) {
  const fs::path file = dir / "motions" / (numbered('m', i) + ".json");
  const std::string summary = (dir / "summary.json").string();
  const std::string field = "motions[" + std::to_string(i) + "]";
  if (!entry.is_object() || !entry.contains("constraint") || !entry["constraint"].is_number())
    throw_field_error(summary, field, "an object with the motion's \"constraint\"");
  const std::string remedy = "the run directory is incomplete (`diverse resume " + dir.string() +
                             "` writes its outputs again)";
  RunMotion m = load_motion_file(file, numbered('M', i), remedy);
  m.index = static_cast<int>(i);
  m.constraint = entry["constraint"].get<double>();
  m.dmin = entry.value("dmin", 0.0);
  m.fell = entry.value("fell", false);
  m.failed = entry.value("failed", false);
  if (entry.contains("label") && entry["label"].is_string()) m.label = entry["label"];
  return m;
}

}  // namespace

RunMotion load_motion_file(const fs::path& file, const std::string& label, const std::string& remedy) {
  RunMotion m;
  m.label = label;
  m.file = file;
  if (!fs::exists(m.file)) throw UserError(m.file.string() + ": missing; " + remedy);
  const nlohmann::json motion = read_json(m.file);
  m.record = read_replay_record(motion, m.file, &m.model_path);
  m.model_path = m.model_path.lexically_normal();
  if (m.record.nq <= 0) throw_field_error(m.file.string(), "replay.nq", "a positive number");
  if (!fs::exists(m.model_path)) throw UserError(m.model_path.string() + ": missing; " + remedy);
  m.model = SharedModel::from_file(m.model_path.string());
  if (m.model->get()->nq != m.record.nq)
    throw UserError(m.file.string() + ": replay.nq: " + std::to_string(m.record.nq) +
                    " does not match the model " + m.model_path.string() + " (nq " +
                    std::to_string(m.model->get()->nq) + ")");
  // Phase names and begin times as the controller reported them, and which phases begin
  // at take-off, the peak and touch-down ("event"; files without it name them rise, fall
  // and land).
  if (motion.contains("phases") && motion["phases"].is_array()) {
    for (const auto& phase : motion["phases"]) {
      if (!phase.is_object()) throw_field_error(m.file.string(), "phases", "an array of objects");
      const std::string name = phase.value("name", "");
      const std::string event = phase.value("event", name == "rise" ? "takeoff" : name == "fall" ? "peak" : name == "land" ? "landing" : "");
      const int index = static_cast<int>(m.phases.names.size());
      if (event == "takeoff") m.phases.rise = index;
      if (event == "peak") m.phases.fall = index;
      if (event == "landing") m.phases.land = index;
      m.phases.names.push_back(name);
      const auto begin = phase.find("begin");
      m.phases.begin.push_back(begin != phase.end() && begin->is_number() ? begin->get<double>() : -1.0);
    }
  }
  return m;
}

namespace {

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

double RunMotion::duration() const { return record.steps() * record.timestep; }

std::vector<double> RunMotion::qpos_at(double t) const {
  // qpos row k is the state after step k, at time (k + 1) dt; t = 0 is qpos0 (as in
  // jump_film_columns).
  const long steps = record.steps();
  const long k = std::lround(t / record.timestep) - 1;
  if (k < 0 || steps == 0) return record.qpos0;
  const long row = std::min(k, steps - 1);
  const auto nq = static_cast<long>(record.nq);
  return std::vector<double>(record.qpos.begin() + row * nq, record.qpos.begin() + (row + 1) * nq);
}

std::vector<std::vector<double>> RunMotion::sample(double fps, double speed) const {
  if (!(fps > 0) || !(speed > 0))
    throw std::invalid_argument("RunMotion::sample: fps and speed must be > 0");
  const double step = speed / fps;  // motion seconds per frame
  const long count = static_cast<long>(std::floor(duration() / step + 1e-9)) + 1;
  std::vector<std::vector<double>> frames;
  frames.reserve(static_cast<std::size_t>(count));
  for (long k = 0; k < count; ++k) frames.push_back(qpos_at(static_cast<double>(k) * step));
  return frames;
}

std::string RunMotion::status() const {
  if (constraint == 0.0) return "C = 0, meets the task";
  char text[64];
  std::snprintf(text, sizeof text, "C = %.3g, %s", constraint,
                failed ? "failed" : fell ? "fell" : "misses the task");
  return text;
}

RunView load_run_view(const fs::path& dir) {
  if (!fs::exists(dir)) throw UserError(dir.string() + ": no such directory");
  if (!fs::is_directory(dir)) throw UserError(dir.string() + ": not a directory");
  const fs::path run_file = dir / "run.json";
  if (!fs::exists(run_file))
    throw UserError(dir.string() +
                    ": not a run directory (no run.json; `diverse run TASK --out DIR` makes one)");
  RunView view;
  view.dir = dir;
  view.run = read_json(run_file);
  if (!view.run.is_object() || view.run.value("format", "") != "diverse.run")
    throw_field_error(run_file.string(), "format", "\"diverse.run\" (a run directory's run.json)");
  const fs::path summary_file = dir / "summary.json";
  if (!fs::exists(summary_file))
    throw UserError(summary_file.string() + ": missing; the run has not finished (`diverse resume " +
                    dir.string() + "` finishes it)");
  view.summary = read_json(summary_file);
  if (!view.summary.is_object() || !view.summary.contains("motions") ||
      !view.summary["motions"].is_array() || view.summary["motions"].empty())
    throw_field_error(summary_file.string(), "motions", "a list of the run's motions, M0 first");
  view.task_name = view.summary.value("task", std::string());
  view.metric = view.summary.value("metric", std::string());

  const nlohmann::json& motions = view.summary["motions"];
  for (std::size_t i = 0; i < motions.size(); ++i)
    view.motions.push_back(read_motion(dir, i, motions[i]));

  // The landing region comes from the task file; pictures are still worth making without.
  const std::string task_file = view.run.value("task_file", std::string());
  try {
    view.ground_strips = task_ground_strips(load_task(task_file));
  } catch (const UserError& e) {
    view.task_note = e.what();
  }
  return view;
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
  film.ground_strips = run.ground_strips;
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
                  : fit_shared_camera(posed, aspect, run.ground_strips, plan.direction, 0.06);
  std::vector<std::unique_ptr<OffscreenRenderer>> renderers;
  for (const RunMotion& m : run.motions) {
    renderers.push_back(std::make_unique<OffscreenRenderer>(m.model->get(), tile_w, tile_h, style));
    renderers.back()->set_ground_strips(run.ground_strips);
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
    paths.push_back(video_dir / (numbered('m', static_cast<std::size_t>(m.index)) + ".mp4"));
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
