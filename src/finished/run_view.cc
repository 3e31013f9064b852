#include "finished/run_view.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/error.h"
#include "io/files.h"
#include "io/motion_record.h"
#include "task/task.h"

namespace diverse {
namespace fs = std::filesystem;

namespace {

RunMotion read_motion(const fs::path& dir, std::size_t i, const nlohmann::json& entry) {
  // (Built with append: GCC 12 warns falsely (-Wrestrict) on "literal" + std::string.)
  const std::string number = std::to_string(i);
  const fs::path file = dir / "motions" / std::string("m").append(number).append(".json");
  const std::string summary = (dir / "summary.json").string();
  const std::string field = "motions[" + std::to_string(i) + "]";
  if (!entry.is_object() || !entry.contains("constraint") || !entry["constraint"].is_number())
    throw_field_error(summary, field, "an object with the motion's \"constraint\"");
  const std::string remedy = "the run directory is incomplete (`diverse resume " + dir.string() +
                             "` writes its outputs again)";
  RunMotion m = load_motion_file(file, std::string("M").append(number), remedy);
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

  // The task file, for the landing region; pictures are still worth making without.
  const std::string task_file = view.run.value("task_file", std::string());
  try {
    view.task = std::make_shared<const Task>(load_task(task_file));
  } catch (const UserError& e) {
    view.task_note = e.what();
  }
  return view;
}

}  // namespace diverse
