// Pictures and videos of a finished run (`diverse render RUN`), and the run reader that
// `diverse gallery` and `diverse export` share.
//
// A run directory (run/run.h) holds, per motion M0..MN, the motion file motions/m<i>.json
// with its exact-replay record (io/motion_record.h) and the model it was simulated with,
// model/m<i>.xml. Everything here is drawn from those recorded states: nothing is
// simulated again, so pictures show exactly the motions the run found, each on its own
// model (rows and tiles may differ in body shape).
//
//   filmstrip.png     the paper's figure 5: one row per motion (M0 on top), one column
//                     per phase event of the jump (A crouch, B extend, C take-off, ...;
//                     render/film_columns.h, jump_film_columns), one shared side camera, scene
//                     objects drawn and the landing region marked on the floor
//   videos/m<i>.mp4   each motion alone, labelled with its constraint value
//   videos/all.mp4    all motions side by side in step, through one shared camera;
//                     shorter motions hold their last frame
//
// Videos sample the recorded states at the video's frame rate (the state nearest in time
// to each frame), in real time or at half speed; the time stamp is the motion's time.
#pragma once

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "control/controller.h"
#include "physics/model.h"
#include "physics/rollout.h"
#include "render/offscreen.h"

namespace diverse {

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

// A video's header line holds a title on the left and the time stamp on the right: the
// first of `titles` that leaves `stamp` room (FontSize::kMedium, margins of `gap` pixels)
// in `width` pixels, else the last. Longest first: "robot_silly_walk M1, real time", then
// "M1, real time", then "M1".
std::string fitting_title(const std::vector<std::string>& titles, const std::string& stamp, int width, int gap);

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
  std::vector<GroundStrip> ground_strips;  // the task's landing region, if it has one
  std::string task_note;                   // why the task file could not be read, or ""
};

// Reads run.json, summary.json, every motion file and its model. Throws UserError with
// one line naming what is wrong: not a directory, not a run directory (no run.json), a
// run that has not finished (no summary.json), a missing or malformed motion or model
// file. The task file (run.json task_file) is read only for the landing region; if it
// cannot be, task_note says why and the region is not drawn.
RunView load_run_view(const std::filesystem::path& dir);

// The film strip of the run (layout above) written as a PNG.
void write_run_film_strip(const RunView& run, const std::filesystem::path& png);

struct RunVideoOptions {
  double fps = 30.0;    // frames per second of the files
  double speed = 1.0;   // 1 = real time, 0.5 = half speed
  int tile_width = 384;   // px, one motion's picture
  int tile_height = 384;  // px
  int columns = 5;        // at most this many motions per row of all.mp4
};

// Writes videos/m<i>.mp4 for every motion and videos/all.mp4 (layout above); returns the
// paths written. Each motion's frames are rendered once and go to both files. Throws
// UserError if ffmpeg is missing or fails.
std::vector<std::filesystem::path> write_run_videos(const RunView& run,
                                                    const RunVideoOptions& options = {});

}  // namespace diverse
