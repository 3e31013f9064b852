// The interactive gallery of a run (`diverse gallery RUN`): one self-contained HTML file,
// RUN/gallery.html, that any browser opens from disk with no network.
//
// The page (source in web/, bundled with three.js into a template at build time; see
// docs/guide/viewing-results.md) shows all motions side by side in 3D, in step, with play/pause,
// a time scrubber and half speed; each motion's constraint value C and its distances to
// the others (summary.json, every motion metric); and, per variation, a slider along its
// optimization path (paper figure 6a).
//
// What goes into the page, as JSON (gallery_data):
//   - per model: its bodies and geoms (type, size, body, position and quaternion in the
//     body frame, colour); the world body's geoms (boxes, obstacles) are the scene;
//   - per motion: the world position and orientation (xpos, xquat from mj_kinematics) of
//     every body, sampled at `fps` from the recorded states; numbers are rounded to 4
//     decimals (0.1 mm, 1e-4 of a unit quaternion), which keeps a run of 5 motions and 4
//     paths at a few megabytes;
//   - per variation i, points of its optimization path at 0, 25, 50, 75 and 100 % of the
//     path's distance from M0. The path runs from M0 through the means CMA-ES took for
//     variation i (paths/m<i>.json) to the variation's result (motions/m<i>.json). Paper
//     figure 6a parameterizes it by the metric distance of each point's motion from M0, so
//     the path's points are simulated when the gallery is made (TaskEvaluator on the run's
//     task file, each point on its own body when the run varied the shape; at most
//     `max_path_candidates` of them, evenly spaced, to measure distances), and the point
//     nearest to each fraction of the result's distance is simulated again with
//     recording on. Points that miss the task (C > 0) are marked.
//   - the run's progress for the plots panel, from log.jsonl: per generation (the last CMA
//     step of each), D of the current set, D of the best set so far, and every motion's
//     constraint value C and dmin; at most max_progress_points generations, thinned evenly;
//   - for a run whose bodies varied, every motion's link-length scales (summary.json);
//   - every motion's foot slip (summary.json, task/foot_slip.h), for runs that have it;
//   - every motion's shares of the robustness suite (robust/robustness.h), over all and
//     by kind, from RUN/robustness.json, or from summary.json "robustness" without it;
//     null (and a note) for a run with neither, made before every run ended with the
//     suite: the page says the suite was not run;
//   - the run's blends, when `diverse blend RUN` made them (run/blend.h, RUN/blend/): per
//     blend its weights on M0..MN, C, whether it meets the task, its distances to the
//     motions and its frames (from its motion file), and the share that meets the task,
//     against the path points'. Blends made from an earlier run in the same directory
//     (another run_fingerprint) are left out with a note.
#pragma once

#include <mujoco/mujoco.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "finished/run_view.h"

namespace diverse {

struct GalleryOptions {
  double fps = 30.0;              // body poses per second of motion
  bool paths = true;              // simulate optimization path points (needs the task file)
  std::vector<double> path_fractions{0.0, 0.25, 0.5, 0.75, 1.0};
  int max_path_candidates = 64;   // path points per variation simulated to measure distances
  bool blends = true;             // the run's blends (RUN/blend/), if it has any
  int max_progress_points = 400;  // generations of log.jsonl kept for the plots (thinned evenly)
  int threads = 0;                // simulation threads; 0 = one per core
  std::filesystem::path page_template;  // "" = gallery_template_path()
};

// The page template built from web/: the environment variable DIVERSE_GALLERY_TEMPLATE if
// set; else, for an installed program, PREFIX/share/diverse/gallery-template.html beside
// its bin/; else the path fixed at build time. Throws UserError saying what is missing
// (node and npm, or `npm ci` in web/) if it does not exist.
std::filesystem::path gallery_template_path();

// Indices of the path points nearest to each fraction of the path's distance from M0.
// `distances[k]` is point k's distance from M0 (NaN if unknown: a failed simulation);
// the last point is the path's end. Point 0 answers fraction 0 and the last point
// fraction 1 when their distances are 0 and the end's; ties go to the point nearest in
// index to fraction * (points - 1). If the end is no farther than the start (distance 0
// or unknown), points are picked by index instead. Throws std::invalid_argument if
// `distances` is empty.
std::vector<int> pick_path_points(std::span<const double> distances,
                                  std::span<const double> fractions);

// The model's bodies and geoms, as the page draws them (see above).
nlohmann::json model_json(const mjModel* model);
// Per frame, xpos (3) and xquat (4, w first) of bodies 1 .. nbody-1, rounded, flattened.
nlohmann::json body_frames_json(const mjModel* model, std::span<const std::vector<double>> frames);

// Everything the page shows (see above). Throws UserError if paths are asked for and the
// task file is missing or changed since the run, or a path file is missing or malformed.
nlohmann::json gallery_data(const RunView& run, const GalleryOptions& options = {});

// The template with the data put in its place (JSON inside a <script> element, with "</"
// escaped). Throws UserError if the template lacks the data marker.
std::string gallery_html(const std::string& page_template, const nlohmann::json& data);

// Reads the run, makes the data and writes RUN/gallery.html; returns its path.
std::filesystem::path write_gallery(const std::filesystem::path& run_dir,
                                    const GalleryOptions& options = {});

}  // namespace diverse
