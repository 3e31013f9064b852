#include "finished/gallery_data.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include "core/error.h"
#include "core/thread_pool.h"
#include "eval/motion_problem.h"
#include "finished/run_problem.h"
#include "io/files.h"
#include "robust/robustness.h"
#include "task/evaluate.h"

namespace diverse {
namespace fs = std::filesystem;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A number of a run's file; null (a number that was not finite) is NaN.
double number_or_nan(const nlohmann::json& v, const std::string& file, const std::string& field) {
  if (v.is_null()) return kNaN;
  if (!v.is_number()) throw_field_error(file, field, "expected a number");
  return v.get<double>();
}

std::vector<double> numbers_or_nan(const nlohmann::json& v, const std::string& file, const std::string& field) {
  if (!v.is_array()) throw_field_error(file, field, "expected a list of numbers");
  std::vector<double> out;
  for (const nlohmann::json& x : v) out.push_back(number_or_nan(x, file, field));
  return out;
}

// The poses of a recorded motion.
GalleryPoses recorded_poses(const RunMotion& m, double fps) {
  return {m.model, m.sample(fps), m.duration()};
}

// Every motion's figures: C, dmin and status as the run view has them, the rest from
// summary.json motions[i] where it has them.
std::vector<GalleryMotion> motion_data(const RunView& run, double fps) {
  const nlohmann::json& s = run.summary;
  const std::string file = (run.dir / "summary.json").string();
  std::vector<GalleryMotion> motions;
  for (std::size_t i = 0; i < run.motions.size(); ++i) {
    const RunMotion& m = run.motions[i];
    GalleryMotion g;
    g.label = m.label;
    g.index = m.index;
    g.constraint = m.constraint;
    g.dmin = m.dmin;
    g.fell = m.fell;
    g.failed = m.failed;
    g.status = m.status();
    g.poses = recorded_poses(m, fps);
    if (s.contains("motions") && s["motions"].is_array() && i < s["motions"].size() &&
        s["motions"][i].is_object()) {
      const nlohmann::json& e = s["motions"][i];
      const std::string field = "motions[" + std::to_string(i) + "].";
      const auto number = [&](const char* key, std::optional<double>& to) {
        if (e.contains(key)) to = number_or_nan(e[key], file, field + key);
      };
      number("effort", g.effort);
      number("effort_ratio", g.effort_ratio);
      number("positive_work", g.positive_work);
      number("distance_to_m0", g.distance_to_m0);
      if (e.contains("within_bounds")) {
        if (!e["within_bounds"].is_boolean()) throw_field_error(file, field + "within_bounds", "expected true or false");
        g.within_bounds = e["within_bounds"].get<bool>();
      }
      if (e.contains("foot_slip")) g.foot_slip = e["foot_slip"];
    }
    motions.push_back(std::move(g));
  }
  return motions;
}

// The path points: distances from M0 of (up to max_path_candidates of) every path's
// points, the picked points simulated again with recording on.
std::vector<GalleryPath> path_data(const RunView& run, const GalleryDataOptions& options) {
  const RunProblem rp = open_run_problem(
      run, options.threads, "the optimization paths cannot be simulated (restore it, or make the gallery with --no-paths)");
  const MotionProblem& problem = *rp.problem;
  const int threads = problem.workers();
  ThreadPool pool(threads);

  // Which points of each path are simulated to measure distances: all, or evenly spaced.
  const std::size_t variations = run.motions.size() - 1;
  std::vector<std::vector<RunPathPoint>> paths(variations + 1);
  std::vector<std::vector<int>> candidates(variations + 1);
  struct Job {
    std::size_t variation = 0;
    int point = 0;
  };
  std::vector<Job> jobs;
  for (std::size_t v = 1; v <= variations; ++v) {
    paths[v] = read_run_path(run, v, rp.like);
    const int n = static_cast<int>(paths[v].size());
    const int want = std::max(2, options.max_path_candidates);
    for (int k = 0; k < std::min(n, want); ++k) {
      const int index = n <= want ? k : static_cast<int>(std::lround(static_cast<double>(k) * (n - 1) / (want - 1)));
      if (candidates[v].empty() || candidates[v].back() != index) candidates[v].push_back(index);
    }
    for (int index : candidates[v]) jobs.push_back({v, index});
  }
  std::vector<std::shared_ptr<const Outcome>> outcomes(jobs.size() + 1);
  pool.parallel_for(jobs.size() + 1, [&](std::size_t j, int worker) {
    outcomes[j] = j == 0 ? problem.evaluate_confirmed(problem.reference(), worker)
                         : problem.evaluate_confirmed(paths[jobs[j - 1].variation][static_cast<std::size_t>(jobs[j - 1].point)].x, worker);
  });
  const Outcome& reference = *outcomes[0];

  // Per variation, the picked points.
  std::vector<GalleryPath> out;
  std::vector<const Outcome*> picked;  // per picked point, in order, its outcome
  std::size_t job = 1;
  for (std::size_t v = 1; v <= variations; ++v) {
    std::vector<double> distances;
    std::vector<const Outcome*> outs;
    for (std::size_t c = 0; c < candidates[v].size(); ++c, ++job) {
      const Outcome& o = *outcomes[job];
      distances.push_back(is_failure(o) || is_failure(reference) ? kNaN : problem.distance(reference, o));
      outs.push_back(&o);
    }
    GalleryPath path;
    path.variation = v;
    path.label = run.motions[v].label;
    path.points_total = paths[v].size();
    path.points_measured = candidates[v].size();
    path.end_distance = distances.back();
    path.by_index = !(distances.back() > distances.front());
    const std::vector<int> chosen = pick_path_points(distances, options.path_fractions);
    for (std::size_t f = 0; f < chosen.size(); ++f) {
      const auto c = static_cast<std::size_t>(chosen[f]);
      GalleryPathPoint p;
      p.fraction = options.path_fractions[f];
      p.point = candidates[v][c];
      p.distance = distances[c];
      path.points.push_back(std::move(p));
      picked.push_back(outs[c]);
    }
    out.push_back(std::move(path));
  }

  // What each picked point is; its poses simulated with recording on, each on its own
  // body; a variation's result is its recorded motion, exactly as the run left it.
  struct Pick {
    GalleryPathPoint* point = nullptr;
    const RunPathPoint* at = nullptr;
    const RunMotion* motion = nullptr;  // the variation's result
  };
  std::vector<Pick> picks;
  for (GalleryPath& path : out)
    for (GalleryPathPoint& p : path.points) {
      const RunPathPoint& at = paths[path.variation][static_cast<std::size_t>(p.point)];
      const RunMotion& m = run.motions[path.variation];
      const Outcome& o = *picked[picks.size()];
      p.generation = at.generation;
      p.step = at.step;
      p.result = at.result;
      p.constraint = at.result ? m.constraint : o.constraint;
      p.failed = at.result ? m.failed : o.failed;
      p.feasible = p.constraint == 0.0 && !p.failed;
      picks.push_back({&p, &at, &m});
    }
  pool.parallel_for(picks.size(), [&](std::size_t i, int) {
    const Pick& pick = picks[i];
    if (pick.at->result) {
      pick.point->poses = recorded_poses(*pick.motion, options.fps);
      return;
    }
    RunMotion sim;
    EvaluationOptions eval;
    eval.recorder = &sim.record;
    problem.simulate(pick.at->x, eval, &pick.point->poses.model);
    pick.point->poses.qpos = sim.sample(options.fps);
    pick.point->poses.duration = sim.duration();
  });
  return out;
}

// The run's blends (RUN/blend/, run/blend.h); none when there are none, or (with a note)
// when they were made from another run in this directory.
std::optional<GalleryBlends> blend_data(const RunView& run, const GalleryDataOptions& options,
                                        std::vector<std::string>& notes) {
  const fs::path dir = run.dir / "blend";
  const fs::path file = dir / "summary.json";
  if (!options.blends || !fs::exists(file)) return std::nullopt;
  const std::string remedy = "the blends are incomplete (`diverse blend " + run.dir.string() + "` makes them again)";
  const nlohmann::json b = read_json(file);
  if (!b.is_object() || b.value("format", "") != "diverse.blend")
    throw_field_error(file.string(), "format", "\"diverse.blend\" (written by `diverse blend`)");
  if (b.value("run_fingerprint", "") != run_fingerprint(run)) {
    notes.push_back("blends left out: " + dir.string() + " was made from an earlier run in this directory (`diverse blend " +
                    run.dir.string() + "` makes them again)");
    return std::nullopt;
  }
  if (!b.contains("blends") || !b["blends"].is_array())
    throw_field_error(file.string(), "blends", "a list of blends");
  const std::size_t vertices = run.motions.size();
  GalleryBlends out;
  for (std::size_t k = 0; k < b["blends"].size(); ++k) {
    const nlohmann::json& e = b["blends"][k];
    const std::string field = "blends[" + std::to_string(k) + "]";
    if (!e.is_object() || !e.contains("file") || !e["file"].is_string() || !e.contains("label") ||
        !e["label"].is_string())
      throw_field_error(file.string(), field, "an object with the blend's \"label\" and motion \"file\"");
    if (!e.contains("weights") || !e["weights"].is_array() || e["weights"].size() != vertices)
      throw_field_error(file.string(), field + ".weights", "one weight per motion of the run (" +
                                                               std::to_string(vertices) + ")");
    for (const auto& w : e["weights"])
      if (!w.is_number()) throw_field_error(file.string(), field + ".weights", "numbers");
    const RunMotion motion = load_motion_file(dir / e["file"].get<std::string>(), e["label"].get<std::string>(), remedy);
    GalleryBlend blend;
    blend.label = e["label"].get<std::string>();
    blend.weights = e["weights"].get<std::vector<double>>();
    blend.constraint = number_or_nan(e.value("constraint", nlohmann::json(nullptr)), file.string(), field + ".constraint");
    blend.failed = e.value("failed", false);
    blend.fell = e.value("fell", false);
    blend.feasible = e.value("feasible", false);
    blend.distances = numbers_or_nan(e.value("distances", nlohmann::json::array()), file.string(), field + ".distances");
    const nlohmann::json nearest = e.value("nearest", nlohmann::json(nullptr));
    if (!nearest.is_null() && !nearest.is_number_integer())
      throw_field_error(file.string(), field + ".nearest", "expected the index of a motion or null");
    blend.nearest = nearest.is_null() ? -1 : nearest.get<int>();
    blend.poses = recorded_poses(motion, options.fps);
    out.blends.push_back(std::move(blend));
  }
  const nlohmann::json paths = b.value("paths", nlohmann::json::object());
  out.samples = b.value("samples", 0);
  out.seed = b.value("seed", 0);
  out.feasible = b.value("feasible", 0);
  out.feasible_fraction =
      number_or_nan(b.value("feasible_fraction", nlohmann::json(nullptr)), file.string(), "feasible_fraction");
  out.path_points = paths.value("points", 0);
  out.path_feasible_fraction = number_or_nan(paths.value("feasible_fraction", nlohmann::json(nullptr)),
                                             file.string(), "paths.feasible_fraction");
  return out;
}

// The run's progress per generation from log.jsonl (one record per CMA step; a generation's
// last record is where the set stood after it). Long runs are thinned to at most max_points
// generations (evenly, keeping the first and the last). None without the log; a malformed
// line is a UserError naming it.
std::optional<GalleryProgress> progress_data(const fs::path& log_file, int max_points) {
  if (!fs::exists(log_file)) return std::nullopt;
  GalleryProgress out;
  const std::string text = read_file(log_file);
  struct Record {
    long long generation = 0;
    double D = 0, best_D = 0;
    std::vector<double> constraint, dmin;
  };
  std::vector<Record> last;  // per generation, its last record
  std::size_t start = 0;
  for (int line = 1; start < text.size(); ++line) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    const std::string row = text.substr(start, end - start);
    start = end + 1;
    if (row.empty()) continue;
    try {
      const nlohmann::json r = nlohmann::json::parse(row);
      Record record;
      record.generation = r.at("generation").get<long long>();
      record.D = r.at("D").get<double>();
      record.best_D = r.at("best_D").get<double>();
      if (!r.at("constraint").is_array() || !r.at("dmin").is_array()) throw std::invalid_argument("");
      record.constraint = numbers_or_nan(r["constraint"], log_file.string(), "constraint");
      record.dmin = numbers_or_nan(r["dmin"], log_file.string(), "dmin");
      if (!last.empty() && last.back().generation == record.generation) last.back() = std::move(record);
      else last.push_back(std::move(record));
    } catch (const std::exception&) {
      throw UserError(log_file.string() + ": line " + std::to_string(line) +
                      ": expected a JSON record with generation, D, best_D, constraint and dmin");
    }
  }
  std::vector<std::size_t> keep;
  const std::size_t n = last.size();
  const std::size_t want = static_cast<std::size_t>(std::max(2, max_points));
  for (std::size_t k = 0; k < std::min(n, want); ++k) {
    const std::size_t index = n <= want ? k : static_cast<std::size_t>(std::llround(static_cast<double>(k) * (n - 1) / (want - 1)));
    if (keep.empty() || keep.back() != index) keep.push_back(index);
  }
  out.generations_total = n;
  for (std::size_t k : keep) {
    const Record& r = last[k];
    out.generation.push_back(r.generation);
    out.D.push_back(r.D);
    out.best_D.push_back(r.best_D);
    out.constraint.push_back(r.constraint);
    out.dmin.push_back(r.dmin);
  }
  return out;
}

// For a run whose bodies varied (vary includes "shape"): each motion's link-length scales
// (summary.json motions[i].shape_scales), by parameter name in the order of the first.
std::optional<GalleryShapes> shape_data(const RunView& run) {
  const nlohmann::json& summary = run.summary;
  const nlohmann::json vary = summary.value("vary", nlohmann::json::array());
  if (std::find(vary.begin(), vary.end(), "shape") == vary.end()) return std::nullopt;
  const std::string file = (run.dir / "summary.json").string();
  GalleryShapes out;
  for (const nlohmann::json& m : summary["motions"]) {
    const nlohmann::json s = m.value("shape_scales", nlohmann::json::object());
    if (out.names.empty())
      for (auto it = s.begin(); it != s.end(); ++it) out.names.push_back(it.key());
    std::vector<double> row;
    for (const auto& name : out.names)
      row.push_back(s.contains(name) ? number_or_nan(s[name], file, "motions[].shape_scales." + name) : 1.0);
    out.scales.push_back(std::move(row));
  }
  if (out.names.empty()) return std::nullopt;
  return out;
}

// Each motion's shares of the robustness suite (robust/robustness.h) that every run ends
// with: from RUN/robustness.json when it is there (`diverse robustness RUN` may have
// measured the run again since), else from summary.json "robustness". None for a run with
// neither (made before the suite), with a note. Per motion of the run, matched by label.
// A malformed file is a UserError naming it and the field, as in `diverse report`.
std::optional<GallerySuite> robustness_data(const RunView& run, std::vector<std::string>& notes) {
  const fs::path file = run.dir / "robustness.json";
  nlohmann::json source;
  std::string origin;
  if (fs::exists(file)) {
    source = read_json(file);
    origin = file.string();
    if (!source.is_object() || source.value("format", std::string()) != "diverse.robustness")
      throw_field_error(origin, "format", "expected \"diverse.robustness\" (written by `diverse robustness`)");
  } else if (run.summary.contains("robustness")) {
    source = run.summary["robustness"];
    origin = (run.dir / "summary.json").string();
  } else {
    notes.push_back("robustness suite not run on these motions: diverse robustness " + run.dir.string() +
                    " runs it, then make the gallery again");
    return std::nullopt;
  }
  const std::string prefix = origin.ends_with("summary.json") ? "robustness." : "";
  if (!source.is_object() || !source.contains("motions") || !source["motions"].is_array())
    throw_field_error(origin, prefix + "motions", "expected a list of motions");
  GallerySuite out;
  out.source = fs::path(origin).filename().string();
  out.suite = source.value("suite", nlohmann::json::object());
  for (const RunMotion& motion : run.motions) {
    std::optional<GalleryRobustness> entry;
    for (const nlohmann::json& m : source["motions"]) {
      if (!m.is_object() || !m.contains("label") || !m["label"].is_string())
        throw_field_error(origin, prefix + "motions[].label", "expected a motion's label");
      if (m["label"] != motion.label) continue;
      (void)robustness_shares(m, origin);  // every kind's counts, checked
      GalleryRobustness r;
      for (int k = 0; k < kPerturbationKinds; ++k) {
        const char* key = perturbation_key(static_cast<PerturbationKind>(k));
        const nlohmann::json& kind = m["kinds"][key];
        const GalleryCount c{kind["held"].get<long long>(), kind["count"].get<long long>()};
        r.kinds[key] = c;
        r.all.held += c.held;
        r.all.count += c.count;
      }
      r.share = r.all.count > 0 ? static_cast<double>(r.all.held) / static_cast<double>(r.all.count) : 0.0;
      entry = std::move(r);
      break;
    }
    out.motions.push_back(std::move(entry));
  }
  return out;
}

}  // namespace

std::vector<int> pick_path_points(std::span<const double> distances,
                                  std::span<const double> fractions) {
  if (distances.empty()) throw std::invalid_argument("pick_path_points: no points");
  const int n = static_cast<int>(distances.size());
  const double start = std::isfinite(distances.front()) ? distances.front() : 0.0;
  const double end = distances.back();
  const bool by_index = !(end > start);
  std::vector<int> picked;
  for (double f : fractions) {
    const double index_target = f * (n - 1);
    if (by_index) {
      picked.push_back(std::clamp(static_cast<int>(std::lround(index_target)), 0, n - 1));
      continue;
    }
    const double target = start + f * (end - start);
    int best = -1;
    double best_gap = 0, best_index_gap = 0;
    for (int k = 0; k < n; ++k) {
      const double d = distances[static_cast<std::size_t>(k)];
      if (!std::isfinite(d)) continue;
      const double gap = std::abs(d - target);
      const double index_gap = std::abs(k - index_target);
      if (best < 0 || gap < best_gap || (gap == best_gap && index_gap < best_index_gap)) {
        best = k;
        best_gap = gap;
        best_index_gap = index_gap;
      }
    }
    picked.push_back(best);
  }
  return picked;
}

GalleryData collect_gallery_data(const RunView& run, const GalleryDataOptions& options) {
  if (!(options.fps > 0)) throw std::invalid_argument("collect_gallery_data: fps must be > 0");
  const nlohmann::json& s = run.summary;
  GalleryData data;
  data.task = run.task_name;
  data.metric = run.metric;
  data.fps = options.fps;
  data.settings = nlohmann::json::object();
  for (const char* key : {"N", "K", "strategy", "seed", "generations", "evaluations", "D",
                          "all_satisfied", "stop", "strength", "bounds"})
    if (s.contains(key)) data.settings[key] = s[key];
  data.motions = motion_data(run, options.fps);
  data.distances = s.contains("distances") ? s["distances"] : nlohmann::json::object();
  data.progress = progress_data(run.dir / "log.jsonl", options.max_progress_points);
  data.shapes = shape_data(run);
  if (!run.task_note.empty()) data.notes.push_back("landing region not drawn: " + run.task_note);
  data.robustness = robustness_data(run, data.notes);
  if (options.paths && run.motions.size() > 1) {
    data.paths = path_data(run, options);
  } else if (!options.paths) {
    data.notes.push_back("optimization paths left out (--no-paths)");
  }
  data.blends = blend_data(run, options, data.notes);
  return data;
}

}  // namespace diverse
