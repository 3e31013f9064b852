// A finished run read back: the run reader that `diverse render`, `gallery`, `export`,
// `simulate`, `robustness` and `blend` share.
//
// A run directory (run/run.h) holds, per motion M0..MN, the motion file motions/m<i>.json
// with its exact-replay record (io/motion_record.h) and the model it was simulated with,
// model/m<i>.xml. A RunView holds those recorded states with each motion's own model (rows
// and tiles may differ in body shape): nothing is simulated again. Its pictures and videos
// are drawn by render/run_media.h; more of its points are simulated through
// finished/run_problem.h.
#pragma once

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "control/controller.h"
#include "physics/model.h"
#include "physics/rollout.h"

namespace diverse {

struct Task;

// One motion of a run, as recorded.
struct RunMotion {
  int index = 0;
  std::string label;                           // "M0", "M1", ...
  std::filesystem::path file;                  // motions/m<i>.json
  std::filesystem::path model_path;            // model/m<i>.xml
  std::shared_ptr<const SharedModel> model;    // loaded with SharedModel::from_file
  StepRecorder record;                         // qpos0 and qpos after every step
  PhaseTimes phases;                           // phase begin times (s), -1 if never reached
  double constraint = 0;                       // C (summary.json); 0 = meets the task
  double dmin = 0;                             // distance to the nearest other motion
  bool fell = false;
  bool failed = false;

  double duration() const;                     // s: recorded steps * timestep
  // The recorded qpos nearest in time to t (s); t <= 0 gives qpos0, t past the end the
  // last state.
  std::vector<double> qpos_at(double t) const;
  // qpos every speed / fps seconds of motion time from 0 to the end (a frame rate of
  // `fps` played at `speed` times real time). Throws std::invalid_argument unless
  // fps > 0 and speed > 0.
  std::vector<std::vector<double>> sample(double fps, double speed = 1.0) const;
  // "C = 0, meets the task", "C = 1.2e+05, fell", ...
  std::string status() const;
};

// Reads one motion file (io/motion_record.h) with its model and phases, labelled `label`;
// the caller fills in index, constraint, dmin, fell and failed. Throws UserError on a
// missing or malformed file: "FILE: missing; <remedy>" for a missing motion or model file.
RunMotion load_motion_file(const std::filesystem::path& file, const std::string& label,
                           const std::string& remedy);

// A finished run directory, read for viewing.
struct RunView {
  std::filesystem::path dir;
  nlohmann::json run;                      // run.json
  nlohmann::json summary;                  // summary.json
  std::string task_name;
  std::string metric;                      // the run's metric, "md", ...
  std::vector<RunMotion> motions;          // M0 .. MN
  std::shared_ptr<const Task> task;        // the task file (run.json task_file) as read now, or null
  std::string task_note;                   // why the task file could not be read, or ""
};

// Reads run.json, summary.json, every motion file and its model. Throws UserError with
// one line naming what is wrong: not a directory, not a run directory (no run.json), a
// run that has not finished (no summary.json), a missing or malformed motion or model
// file. The task file (run.json task_file) is read for what pictures show of it (the
// landing region); if it cannot be, `task` is null and task_note says why.
RunView load_run_view(const std::filesystem::path& dir);

}  // namespace diverse
