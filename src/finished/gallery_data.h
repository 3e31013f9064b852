// What the gallery of a finished run shows (`diverse gallery RUN`), gathered from the run
// into plain structs: everything read from its files, simulated and measured. How the page
// looks is render/gallery.h's; nothing here draws.
//
//   GalleryData data = collect_gallery_data(load_run_view(dir), options);
//
//   - per motion M0..MN: C, dmin, fell, failed and its status line (summary.json), its
//     effort, distance from M0, whether it keeps the run's bounds and how far its planted
//     feet slide (summary.json motions[i], task/foot_slip.h), those the run has; and its
//     poses: the recorded qpos sampled at `fps` on the model it was simulated with;
//   - the run's settings and every metric's distances between the motions, as summary.json
//     holds them;
//   - per variation i, points of its optimization path at 0, 25, 50, 75 and 100 % of the
//     path's distance from M0. The path runs from M0 through the means CMA-ES took for
//     variation i (paths/m<i>.json) to the variation's result (motions/m<i>.json). Paper
//     figure 6a parameterizes it by the metric distance of each point's motion from M0, so
//     the path's points are simulated here (TaskEvaluator on the run's task file, each
//     point on its own body when the run varied the shape; at most `max_path_candidates`
//     of them, evenly spaced, to measure distances), and the point nearest to each
//     fraction of the result's distance is simulated again with recording on; a
//     variation's result is its recorded motion. Points that miss the task (C > 0) are
//     marked;
//   - the run's progress from log.jsonl: per generation (the last CMA step of each), D of
//     the current set, D of the best set so far, and every motion's C and dmin; at most
//     max_progress_points generations, thinned evenly;
//   - for a run whose bodies varied, every motion's link-length scales (summary.json);
//   - every motion's shares of the robustness suite (robust/robustness.h), over all and by
//     kind, from RUN/robustness.json, or from summary.json "robustness" without it; none
//     (and a note) for a run with neither, made before every run ended with the suite;
//   - the run's blends, when `diverse blend RUN` made them (run/blend.h, RUN/blend/): per
//     blend its weights on M0..MN, C, whether it meets the task, its distances to the
//     motions and its poses (from its motion file), and the share that meets the task,
//     against the path points'. Blends made from an earlier run in the same directory
//     (another run_fingerprint) are left out with a note;
//   - notes: what is left out and why.
//
// A number the run's files hold as null (not finite when written) is NaN here.
#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "finished/run_view.h"
#include "physics/model.h"

namespace diverse {

struct GalleryDataOptions {
  double fps = 30.0;              // poses per second of motion
  bool paths = true;              // simulate optimization path points (needs the task file)
  std::vector<double> path_fractions{0.0, 0.25, 0.5, 0.75, 1.0};
  int max_path_candidates = 64;   // path points per variation simulated to measure distances
  bool blends = true;             // the run's blends (RUN/blend/), if it has any
  int max_progress_points = 400;  // generations of log.jsonl kept (thinned evenly)
  int threads = 0;                // simulation threads; 0 = one per core
};

// States every 1/fps s of motion time from 0 to the end, on the model they ran on.
struct GalleryPoses {
  std::shared_ptr<const SharedModel> model;
  std::vector<std::vector<double>> qpos;
  double duration = 0;  // s
};

struct GalleryMotion {
  std::string label;                  // "M0", "M1", ...
  int index = 0;
  double constraint = 0;              // C; 0 = meets the task
  double dmin = 0;                    // distance to the nearest other motion
  bool fell = false;
  bool failed = false;
  std::string status;                 // "C = 0, meets the task", ...
  GalleryPoses poses;
  // From summary.json motions[i], where it has them.
  std::optional<double> effort, effort_ratio, positive_work, distance_to_m0;
  std::optional<bool> within_bounds;
  std::optional<nlohmann::json> foot_slip;  // as task/foot_slip.h's foot_slip_json wrote it
};

// One picked point of a variation's optimization path.
struct GalleryPathPoint {
  double fraction = 0;        // of the result's distance from M0 it was picked for
  int point = 0;              // index in the path
  long long generation = -1;
  long long step = -1;
  bool result = false;        // the variation's result, the path's last point
  double distance = 0;        // from M0 (NaN: unknown, a failed simulation)
  double constraint = 0;      // C (NaN: unknown)
  bool failed = false;
  bool feasible = false;      // C = 0 and not failed
  GalleryPoses poses;
};

struct GalleryPath {
  std::size_t variation = 0;
  std::string label;
  std::size_t points_total = 0;     // the path's points, its result included
  std::size_t points_measured = 0;  // those simulated to measure distances
  double end_distance = 0;          // the result's distance from M0 (NaN: unknown)
  bool by_index = false;            // points picked by index (end no farther than start)
  std::vector<GalleryPathPoint> points;  // one per path fraction
};

// Generations of log.jsonl, each where the set stood after it.
struct GalleryProgress {
  std::size_t generations_total = 0;  // before thinning
  std::vector<long long> generation;
  std::vector<double> D, best_D;
  std::vector<std::vector<double>> constraint, dmin;  // per generation, per motion
};

// Link-length scales of a run whose bodies varied, by parameter name.
struct GalleryShapes {
  std::vector<std::string> names;
  std::vector<std::vector<double>> scales;  // per motion, in the order of names
};

struct GalleryCount {
  long long held = 0;
  long long count = 0;
};

// One motion's shares of the robustness suite.
struct GalleryRobustness {
  GalleryCount all;
  double share = 0;                           // all.held / all.count (0 without rollouts)
  std::map<std::string, GalleryCount> kinds;  // by robustness.json's kind keys
};

struct GallerySuite {
  std::string source;   // "robustness.json" or "summary.json"
  nlohmann::json suite; // what the suite ran, as the file describes it
  std::vector<std::optional<GalleryRobustness>> motions;  // per motion; none without an entry
};

struct GalleryBlend {
  std::string label;
  std::vector<double> weights;    // on M0..MN
  double constraint = 0;          // NaN: unknown
  bool failed = false;
  bool fell = false;
  bool feasible = false;
  std::vector<double> distances;  // to M0..MN (NaN: unknown)
  int nearest = -1;               // the nearest motion, -1 if none
  GalleryPoses poses;
};

struct GalleryBlends {
  int samples = 0;
  int seed = 0;
  int feasible = 0;
  double feasible_fraction = 0;       // NaN: no blends
  int path_points = 0;
  double path_feasible_fraction = 0;  // NaN: no path points
  std::vector<GalleryBlend> blends;
};

struct GalleryData {
  std::string task;
  std::string metric;
  double fps = 30.0;
  nlohmann::json settings;   // summary.json's N, K, strategy, seed, generations, evaluations,
                             // D, all_satisfied, stop, strength and bounds, those it has
  nlohmann::json distances;  // summary.json "distances" (every metric's matrix), or {}
  std::vector<GalleryMotion> motions;          // M0..MN
  std::vector<GalleryPath> paths;              // variations 1..N; empty without paths
  std::optional<GalleryProgress> progress;     // none without log.jsonl
  std::optional<GalleryShapes> shapes;         // none unless the bodies varied
  std::optional<GallerySuite> robustness;      // none for a run without the suite
  std::optional<GalleryBlends> blends;         // none without (current) blends
  std::vector<std::string> notes;
};

// Everything above. Throws UserError if paths are asked for and the task file is missing or
// changed since the run, or a path file is missing or malformed, and on a malformed
// log.jsonl, robustness.json or blend summary (naming the file and the field or line);
// std::invalid_argument unless fps > 0.
GalleryData collect_gallery_data(const RunView& run, const GalleryDataOptions& options = {});

// Indices of the path points nearest to each fraction of the path's distance from M0.
// `distances[k]` is point k's distance from M0 (NaN if unknown: a failed simulation);
// the last point is the path's end. Point 0 answers fraction 0 and the last point
// fraction 1 when their distances are 0 and the end's; ties go to the point nearest in
// index to fraction * (points - 1). If the end is no farther than the start (distance 0
// or unknown), points are picked by index instead. Throws std::invalid_argument if
// `distances` is empty.
std::vector<int> pick_path_points(std::span<const double> distances,
                                  std::span<const double> fractions);

}  // namespace diverse
