#include "render/gallery.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <stdexcept>
#include <unistd.h>

#include "core/error.h"
#include "core/thread_pool.h"
#include "eval/motion_problem.h"
#include "finished/run_problem.h"
#include "io/files.h"
#include "metric/metric.h"
#include "task/evaluate.h"
#include "task/task.h"
#include "render/run_media.h"
#include "render/view_plan.h"
#include "robust/robustness.h"

// Where the build put the page template (set for this file by the top-level CMakeLists).
#ifndef DIVERSE_GALLERY_TEMPLATE
#define DIVERSE_GALLERY_TEMPLATE ""
#endif

namespace diverse {
namespace fs = std::filesystem;

namespace {

constexpr const char* kDataMarker = "__DIVERSE_GALLERY_DATA__";

// 4 decimals: 0.1 mm for positions, 1e-4 for unit quaternions and colours.
double round4(double v) {
  const double r = std::round(v * 1e4) / 1e4;
  return r == 0.0 ? 0.0 : r;  // no "-0.0"
}

nlohmann::json rounded(const double* v, int n) {
  nlohmann::json a = nlohmann::json::array();
  for (int i = 0; i < n; ++i) a.push_back(round4(v[i]));
  return a;
}
nlohmann::json rounded(const float* v, int n) {
  nlohmann::json a = nlohmann::json::array();
  for (int i = 0; i < n; ++i) a.push_back(round4(static_cast<double>(v[i])));
  return a;
}

const char* geom_type_name(int type) {
  switch (type) {
    case mjGEOM_PLANE: return "plane";
    case mjGEOM_HFIELD: return "hfield";
    case mjGEOM_SPHERE: return "sphere";
    case mjGEOM_CAPSULE: return "capsule";
    case mjGEOM_ELLIPSOID: return "ellipsoid";
    case mjGEOM_CYLINDER: return "cylinder";
    case mjGEOM_BOX: return "box";
    case mjGEOM_MESH: return "mesh";
    default: return "other";
  }
}

nlohmann::json geom_json(const mjModel* m, int g) {
  // A material's colour wins over the geom's, as MuJoCo draws it.
  const float* rgba = m->geom_matid[g] >= 0 ? m->mat_rgba + 4 * m->geom_matid[g] : m->geom_rgba + 4 * g;
  return {{"type", geom_type_name(m->geom_type[g])},
          {"size", rounded(m->geom_size + 3 * g, 3)},
          {"body", m->geom_bodyid[g] - 1},  // -1: the world (scene objects)
          {"pos", rounded(m->geom_pos + 3 * g, 3)},
          {"quat", rounded(m->geom_quat + 4 * g, 4)},
          {"rgba", rounded(rgba, 4)}};
}

bool on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return false;
  const std::string paths = path;
  std::size_t start = 0;
  while (start <= paths.size()) {
    const std::size_t end = std::min(paths.find(':', start), paths.size());
    const std::string dir = paths.substr(start, end - start);
    if (!dir.empty() && access((dir + "/" + program).c_str(), X_OK) == 0) return true;
    start = end + 1;
  }
  return false;
}

// Adds `model` to the page's models unless an identical one is there; returns its index.
int add_model(nlohmann::json& models, const mjModel* model) {
  nlohmann::json j = model_json(model);
  for (std::size_t i = 0; i < models.size(); ++i)
    if (models[i] == j) return static_cast<int>(i);
  models.push_back(std::move(j));
  return static_cast<int>(models.size()) - 1;
}

// The path points' data: distances from M0 of (up to max_path_candidates of) every path's
// points, the picked points simulated again with recording on.
nlohmann::json path_data(const RunView& run, const GalleryOptions& options, nlohmann::json& models) {
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
  struct Pick {
    std::size_t variation = 0;
    int point = 0;
    double fraction = 0;
    double distance = 0;
    const Outcome* outcome = nullptr;
    nlohmann::json frames;
    std::shared_ptr<const SharedModel> model;  // what a point that is not the result ran on
    double duration = 0;
  };
  std::vector<Pick> picks;
  std::vector<double> end_distance(variations + 1, 0.0);
  std::vector<bool> by_index(variations + 1, false);
  std::size_t job = 1;
  for (std::size_t v = 1; v <= variations; ++v) {
    std::vector<double> distances;
    std::vector<const Outcome*> outs;
    for (std::size_t c = 0; c < candidates[v].size(); ++c, ++job) {
      const Outcome& o = *outcomes[job];
      distances.push_back(is_failure(o) || is_failure(reference)
                              ? std::numeric_limits<double>::quiet_NaN()
                              : problem.distance(reference, o));
      outs.push_back(&o);
    }
    end_distance[v] = distances.back();
    by_index[v] = !(distances.back() > distances.front());
    const std::vector<int> chosen = pick_path_points(distances, options.path_fractions);
    for (std::size_t f = 0; f < chosen.size(); ++f) {
      const auto c = static_cast<std::size_t>(chosen[f]);
      picks.push_back({v, candidates[v][c], options.path_fractions[f], distances[c], outs[c], {}, nullptr, 0});
    }
  }

  // Simulate the picked points with recording on, each on its own body; a variation's
  // result is its recorded motion, exactly as the run left it.
  pool.parallel_for(picks.size(), [&](std::size_t i, int) {
    Pick& pick = picks[i];
    const RunPathPoint& point = paths[pick.variation][static_cast<std::size_t>(pick.point)];
    if (point.result) {
      const RunMotion& m = run.motions[pick.variation];
      pick.frames = body_frames_json(m.model->get(), m.sample(options.fps));
      pick.duration = m.duration();
      return;
    }
    RunMotion sim;
    EvaluationOptions eval;
    eval.recorder = &sim.record;
    problem.simulate(point.x, eval, &pick.model);
    pick.frames = body_frames_json(pick.model->get(), sim.sample(options.fps));
    pick.duration = sim.duration();
  });

  nlohmann::json out = nlohmann::json::array();
  out.push_back(nullptr);  // M0 has no path
  for (std::size_t v = 1; v <= variations; ++v) {
    nlohmann::json points = nlohmann::json::array();
    for (const Pick& pick : picks) {
      if (pick.variation != v) continue;
      const RunPathPoint& point = paths[v][static_cast<std::size_t>(pick.point)];
      const RunMotion& m = run.motions[v];
      const double c = point.result ? m.constraint : pick.outcome->constraint;
      const bool failed = point.result ? m.failed : pick.outcome->failed;
      points.push_back(
          {{"fraction", pick.fraction},
           {"point", pick.point},
           {"generation", point.generation},
           {"step", point.step},
           {"result", point.result},
           {"distance", std::isfinite(pick.distance) ? nlohmann::json(pick.distance) : nlohmann::json(nullptr)},
           {"constraint", std::isfinite(c) ? nlohmann::json(c) : nlohmann::json(nullptr)},
           {"failed", failed},
           {"feasible", c == 0.0 && !failed},
           {"model", add_model(models, point.result ? m.model->get() : pick.model->get())},
           {"duration", pick.duration},
           {"frames", pick.frames}});
    }
    out.push_back({{"variation", v},
                   {"label", run.motions[v].label},
                   {"points_total", paths[v].size()},
                   {"points_measured", candidates[v].size()},
                   {"end_distance", std::isfinite(end_distance[v]) ? nlohmann::json(end_distance[v]) : nlohmann::json(nullptr)},
                   {"by_index", by_index[v]},
                   {"points", points}});
  }
  return out;
}

// The run's blends (RUN/blend/, run/blend.h) as the page plays them; null when there are
// none, or (with a note) when they were made from another run in this directory.
nlohmann::json blend_data(const RunView& run, const GalleryOptions& options, nlohmann::json& models,
                          nlohmann::json& notes) {
  const fs::path dir = run.dir / "blend";
  const fs::path file = dir / "summary.json";
  if (!options.blends || !fs::exists(file)) return nullptr;
  const std::string remedy = "the blends are incomplete (`diverse blend " + run.dir.string() + "` makes them again)";
  const nlohmann::json b = read_json(file);
  if (!b.is_object() || b.value("format", "") != "diverse.blend")
    throw_field_error(file.string(), "format", "\"diverse.blend\" (written by `diverse blend`)");
  if (b.value("run_fingerprint", "") != run_fingerprint(run)) {
    notes.push_back("blends left out: " + dir.string() + " was made from an earlier run in this directory (`diverse blend " +
                    run.dir.string() + "` makes them again)");
    return nullptr;
  }
  if (!b.contains("blends") || !b["blends"].is_array())
    throw_field_error(file.string(), "blends", "a list of blends");
  const std::size_t vertices = run.motions.size();
  std::vector<RunMotion> motions(b["blends"].size());
  for (std::size_t k = 0; k < motions.size(); ++k) {
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
    motions[k] = load_motion_file(dir / e["file"].get<std::string>(), e["label"].get<std::string>(), remedy);
  }
  std::vector<nlohmann::json> frames(motions.size());
  const int threads = options.threads > 0 ? options.threads : ThreadPool::hardware_threads();
  ThreadPool pool(threads);
  pool.parallel_for(motions.size(), [&](std::size_t k, int) {
    frames[k] = body_frames_json(motions[k].model->get(), motions[k].sample(options.fps));
  });
  nlohmann::json points = nlohmann::json::array();
  for (std::size_t k = 0; k < motions.size(); ++k) {
    const nlohmann::json& e = b["blends"][k];
    points.push_back({{"label", e["label"]},
                      {"weights", e["weights"]},
                      {"constraint", e.value("constraint", nlohmann::json(nullptr))},
                      {"failed", e.value("failed", false)},
                      {"fell", e.value("fell", false)},
                      {"feasible", e.value("feasible", false)},
                      {"distances", e.value("distances", nlohmann::json::array())},
                      {"nearest", e.value("nearest", nlohmann::json(nullptr))},
                      {"model", add_model(models, motions[k].model->get())},
                      {"duration", motions[k].duration()},
                      {"frames", std::move(frames[k])}});
  }
  const nlohmann::json paths = b.value("paths", nlohmann::json::object());
  return {{"samples", b.value("samples", 0)},
          {"seed", b.value("seed", 0)},
          {"feasible", b.value("feasible", 0)},
          {"feasible_fraction", b.value("feasible_fraction", nlohmann::json(nullptr))},
          {"path_points", paths.value("points", 0)},
          {"path_feasible_fraction", paths.value("feasible_fraction", nlohmann::json(nullptr))},
          {"points", points}};
}

// The run's progress per generation from log.jsonl (one record per CMA step; a generation's
// last record is where the set stood after it): D, the best set's D, and every motion's C
// and dmin. Long runs are thinned to at most max_points generations (evenly, keeping the
// first and the last). A missing log gives an empty object; a malformed line is a
// UserError naming it.
nlohmann::json progress_data(const fs::path& log_file, int max_points) {
  if (!fs::exists(log_file)) return nlohmann::json::object();
  const std::string text = read_file(log_file);
  std::vector<nlohmann::json> last;  // per generation, its last record
  std::size_t start = 0;
  for (int line = 1; start < text.size(); ++line) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    const std::string row = text.substr(start, end - start);
    start = end + 1;
    if (row.empty()) continue;
    nlohmann::json r;
    try {
      r = nlohmann::json::parse(row);
      const long long g = r.at("generation").get<long long>();
      (void)r.at("D").get<double>();
      (void)r.at("best_D").get<double>();
      if (!r.at("constraint").is_array() || !r.at("dmin").is_array()) throw std::invalid_argument("");
      if (!last.empty() && last.back()["generation"].get<long long>() == g) last.back() = r;
      else last.push_back(r);
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
  nlohmann::json generation = nlohmann::json::array(), d = nlohmann::json::array(),
                 best = nlohmann::json::array(), c = nlohmann::json::array(),
                 dmin = nlohmann::json::array();
  for (std::size_t k : keep) {
    const nlohmann::json& r = last[k];
    generation.push_back(r["generation"]);
    d.push_back(r["D"]);
    best.push_back(r["best_D"]);
    c.push_back(r["constraint"]);
    dmin.push_back(r["dmin"]);
  }
  return {{"generations_total", n}, {"generation", generation}, {"D", d}, {"best_D", best},
          {"constraint", c}, {"dmin", dmin}};
}

// For a run whose bodies varied (vary includes "shape"): each motion's link-length scales
// (summary.json motions[i].shape_scales), by parameter name in the order of the first.
nlohmann::json shape_data(const nlohmann::json& summary) {
  const nlohmann::json vary = summary.value("vary", nlohmann::json::array());
  if (std::find(vary.begin(), vary.end(), "shape") == vary.end()) return nullptr;
  nlohmann::json names = nlohmann::json::array();
  nlohmann::json scales = nlohmann::json::array();
  for (const nlohmann::json& m : summary["motions"]) {
    const nlohmann::json s = m.value("shape_scales", nlohmann::json::object());
    if (names.empty())
      for (auto it = s.begin(); it != s.end(); ++it) names.push_back(it.key());
    nlohmann::json row = nlohmann::json::array();
    for (const auto& name : names) row.push_back(s.contains(name) ? s[name] : nlohmann::json(1.0));
    scales.push_back(row);
  }
  if (names.empty()) return nullptr;
  return {{"names", names}, {"scales", scales}};
}

// Each motion's shares of the robustness suite (robust/robustness.h) that every run ends
// with: from RUN/robustness.json when it is there (`diverse robustness RUN` may have
// measured the run again since), else from summary.json "robustness". Null for a run
// with neither (made before the suite), with a note: the page says the suite was not
// run. Per motion of the run (matched by label; null where the file has no entry for it):
// {"held", "count", "share", "kinds": {KIND: {"held", "count"}}}, KIND as robustness.json
// names them. A malformed file is a UserError naming it and the field, as in `diverse
// report`.
nlohmann::json robustness_data(const RunView& run, nlohmann::json& notes) {
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
    return nullptr;
  }
  const std::string prefix = origin.ends_with("summary.json") ? "robustness." : "";
  if (!source.is_object() || !source.contains("motions") || !source["motions"].is_array())
    throw_field_error(origin, prefix + "motions", "expected a list of motions");
  nlohmann::json motions = nlohmann::json::array();
  for (const RunMotion& motion : run.motions) {
    nlohmann::json entry = nullptr;
    for (const nlohmann::json& m : source["motions"]) {
      if (!m.is_object() || !m.contains("label") || !m["label"].is_string())
        throw_field_error(origin, prefix + "motions[].label", "expected a motion's label");
      if (m["label"] != motion.label) continue;
      (void)robustness_shares(m, origin);  // every kind's counts, checked
      nlohmann::json kinds = nlohmann::json::object();
      long long held = 0, count = 0;
      for (int k = 0; k < kPerturbationKinds; ++k) {
        const char* key = perturbation_key(static_cast<PerturbationKind>(k));
        const nlohmann::json& kind = m["kinds"][key];
        kinds[key] = {{"held", kind["held"]}, {"count", kind["count"]}};
        held += kind["held"].get<long long>();
        count += kind["count"].get<long long>();
      }
      entry = {{"held", held},
               {"count", count},
               {"share", count > 0 ? static_cast<double>(held) / static_cast<double>(count) : 0.0},
               {"kinds", kinds}};
      break;
    }
    motions.push_back(entry);
  }
  return {{"source", fs::path(origin).filename().string()},
          {"suite", source.value("suite", nlohmann::json::object())},
          {"motions", motions}};
}

}  // namespace

fs::path gallery_template_path() {
  const char* env = std::getenv("DIVERSE_GALLERY_TEMPLATE");
  // An installed program (`cmake --install`) uses the template installed with it, in
  // PREFIX/share/diverse beside its bin/, whether or not its build tree is still there.
  if (!(env && *env)) {
    std::error_code error;
    const fs::path exe = fs::read_symlink("/proc/self/exe", error);
    const fs::path installed = exe.parent_path().parent_path() / "share" / "diverse" / "gallery-template.html";
    if (!error && fs::exists(installed)) return installed;
  }
  const fs::path path = env && *env ? fs::path(env) : fs::path(DIVERSE_GALLERY_TEMPLATE);
  if (!path.empty() && fs::exists(path)) return path;
  const std::string where = path.empty() ? "(no path configured)" : path.string();
  if (!on_path("node") || !on_path("npm"))
    throw UserError("gallery: the page template " + where +
                    " is not built: it needs node and npm; install them (Debian: apt-get install "
                    "nodejs npm) and run scripts/build.sh");
  throw UserError("gallery: the page template " + where + " is not built: run `npm ci` in " +
                  std::string(DIVERSE_SOURCE_DIR) + "/web and rebuild (scripts/build.sh does both)");
}

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

nlohmann::json model_json(const mjModel* m) {
  nlohmann::json bodies = nlohmann::json::array();
  for (int b = 1; b < m->nbody; ++b) {
    const char* name = mj_id2name(m, mjOBJ_BODY, b);
    bodies.push_back({{"name", name ? name : ""}, {"parent", m->body_parentid[b] - 1}});
  }
  nlohmann::json geoms = nlohmann::json::array();
  for (int g = 0; g < m->ngeom; ++g) {
    // Visible groups only (MuJoCo shows 0-2); the floor plane is drawn by the page itself.
    if (m->geom_group[g] > 2 || m->geom_type[g] == mjGEOM_PLANE) continue;
    if (m->geom_rgba[4 * g + 3] == 0.0f && m->geom_matid[g] < 0) continue;
    geoms.push_back(geom_json(m, g));
  }
  double floor = 0;
  bool has_floor = false;
  for (int g = 0; g < m->ngeom && !has_floor; ++g) {
    if (m->geom_bodyid[g] != 0 || m->geom_type[g] != mjGEOM_PLANE) continue;
    floor = m->geom_pos[3 * g + 2];
    has_floor = true;
  }
  return {{"bodies", bodies},
          {"root", root_body(m) - 1},  // index into bodies of the root (-1: none)
          {"geoms", geoms},
          {"floor", has_floor ? nlohmann::json(round4(floor)) : nlohmann::json(nullptr)}};
}

nlohmann::json body_frames_json(const mjModel* m, std::span<const std::vector<double>> frames) {
  std::unique_ptr<mjData, void (*)(mjData*)> d(mj_makeData(m), mj_deleteData);
  nlohmann::json data = nlohmann::json::array();
  for (const std::vector<double>& qpos : frames) {
    if (static_cast<int>(qpos.size()) != m->nq)
      throw std::invalid_argument("body_frames_json: qpos of size " + std::to_string(qpos.size()));
    std::copy(qpos.begin(), qpos.end(), d->qpos);
    mj_kinematics(m, d.get());
    for (int b = 1; b < m->nbody; ++b) {
      for (int i = 0; i < 3; ++i) data.push_back(round4(d->xpos[3 * b + i]));
      for (int i = 0; i < 4; ++i) data.push_back(round4(d->xquat[4 * b + i]));
    }
  }
  return {{"count", frames.size()}, {"bodies", m->nbody - 1}, {"data", data}};
}

nlohmann::json gallery_data(const RunView& run, const GalleryOptions& options) {
  if (!(options.fps > 0)) throw std::invalid_argument("gallery_data: fps must be > 0");
  const nlohmann::json& s = run.summary;
  nlohmann::json data = {{"format", "diverse.gallery"},
                         {"version", 1},
                         {"task", run.task_name},
                         {"metric", run.metric},
                         {"fps", options.fps}};
  for (const char* key : {"N", "K", "strategy", "seed", "generations", "evaluations", "D",
                          "all_satisfied", "stop", "strength", "bounds"})
    if (s.contains(key)) data["run"][key] = s[key];

  nlohmann::json models = nlohmann::json::array();
  nlohmann::json motions = nlohmann::json::array();
  // How the page first looks at the motions (render/view_plan.h): from the side or
  // three-quarters, following each character or not; the same choice as the film strip's.
  std::vector<std::vector<std::vector<double>>> sampled;
  for (const RunMotion& m : run.motions) sampled.push_back(m.sample(options.fps));
  std::vector<PosedModel> posed;
  for (std::size_t i = 0; i < run.motions.size(); ++i) posed.push_back({run.motions[i].model->get(), sampled[i]});
  const ViewPlan plan = plan_view(posed);
  data["view"] = {{"three_quarter", plan.three_quarter},
                  {"follow", plan.follow},
                  {"heading", plan.heading},
                  {"azimuth", plan.direction.azimuth},
                  {"elevation", plan.direction.elevation}};
  for (std::size_t i = 0; i < run.motions.size(); ++i) {
    const RunMotion& m = run.motions[i];
    motions.push_back({{"label", m.label},
                       {"index", m.index},
                       {"model", add_model(models, m.model->get())},
                       {"constraint", m.constraint},
                       {"dmin", m.dmin},
                       {"fell", m.fell},
                       {"failed", m.failed},
                       {"status", m.status()},
                       {"duration", m.duration()},
                       {"frames", body_frames_json(m.model->get(), sampled[i])}});
    // Effort and distance from M0, whether the motion keeps the run's bounds, and how far
    // its planted feet slide (task/foot_slip.h).
    if (s.contains("motions") && s["motions"].is_array() && i < s["motions"].size() &&
        s["motions"][i].is_object())
      for (const char* key : {"effort", "effort_ratio", "positive_work", "distance_to_m0", "within_bounds", "foot_slip"})
        if (s["motions"][i].contains(key)) motions.back()[key] = s["motions"][i][key];
  }
  nlohmann::json strips = nlohmann::json::array();
  // [x0, x1] along the track, or [x0, x1, y, radius] for a disc centred between x0 and x1.
  for (const GroundStrip& g : run_ground_strips(run)) {
    if (g.radius > 0) {
      strips.push_back({round4(g.x_min), round4(g.x_max), round4(g.y), round4(g.radius)});
    } else {
      strips.push_back({round4(g.x_min), round4(g.x_max)});
    }
  }
  data["scene"] = {{"strips", strips}};
  data["motions"] = motions;
  data["distances"] = s.contains("distances") ? s["distances"] : nlohmann::json::object();
  data["progress"] = progress_data(run.dir / "log.jsonl", options.max_progress_points);
  data["shape"] = shape_data(s);
  data["notes"] = nlohmann::json::array();
  if (!run.task_note.empty()) data["notes"].push_back("landing region not drawn: " + run.task_note);
  data["robustness"] = robustness_data(run, data["notes"]);
  if (options.paths && run.motions.size() > 1) {
    data["paths"] = path_data(run, options, models);
  } else {
    data["paths"] = nlohmann::json::array();
    if (!options.paths) data["notes"].push_back("optimization paths left out (--no-paths)");
  }
  data["blend"] = blend_data(run, options, models, data["notes"]);
  data["models"] = models;
  return data;
}

std::string gallery_html(const std::string& page_template, const nlohmann::json& data) {
  const std::size_t at = page_template.find(kDataMarker);
  if (at == std::string::npos || page_template.find(kDataMarker, at + 1) != std::string::npos)
    throw UserError(std::string("gallery: the page template has no single ") + kDataMarker +
                    " data marker; rebuild it from web/");
  // JSON inside <script>: "</" would end the element; "<\/" is the same JSON string.
  std::string json = data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string escaped;
  escaped.reserve(json.size());
  for (std::size_t i = 0; i < json.size(); ++i) {
    escaped += json[i];
    if (json[i] == '<' && i + 1 < json.size() && json[i + 1] == '/') escaped += '\\';
  }
  std::string html = page_template;
  html.replace(at, std::string(kDataMarker).size(), escaped);
  return html;
}

fs::path write_gallery(const fs::path& run_dir, const GalleryOptions& options) {
  const RunView run = load_run_view(run_dir);
  const fs::path page = options.page_template.empty() ? gallery_template_path() : options.page_template;
  const std::string page_template = read_file(page);
  const fs::path out = run.dir / "gallery.html";
  write_file_atomic(out, gallery_html(page_template, gallery_data(run, options)));
  return out;
}

}  // namespace diverse
