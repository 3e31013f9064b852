#include "render/gallery.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <optional>
#include <stdexcept>
#include <utility>
#include <unistd.h>

#include "core/error.h"
#include "io/files.h"
#include "render/run_media.h"
#include "render/view_plan.h"

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

// A number as the page shows it: null when it is not finite (unknown).
nlohmann::json number_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json numbers_json(const std::vector<double>& v) {
  nlohmann::json a = nlohmann::json::array();
  for (double x : v) a.push_back(number_or_null(x));
  return a;
}

nlohmann::json rows_json(const std::vector<std::vector<double>>& rows) {
  nlohmann::json a = nlohmann::json::array();
  for (const std::vector<double>& row : rows) a.push_back(numbers_json(row));
  return a;
}

// Every picked point of every variation's path; null first (M0 has no path).
nlohmann::json paths_json(const std::vector<GalleryPath>& paths, nlohmann::json& models) {
  nlohmann::json out = nlohmann::json::array();
  if (paths.empty()) return out;
  out.push_back(nullptr);
  for (const GalleryPath& path : paths) {
    nlohmann::json points = nlohmann::json::array();
    for (const GalleryPathPoint& p : path.points)
      points.push_back({{"fraction", p.fraction},
                        {"point", p.point},
                        {"generation", p.generation},
                        {"step", p.step},
                        {"result", p.result},
                        {"distance", number_or_null(p.distance)},
                        {"constraint", number_or_null(p.constraint)},
                        {"failed", p.failed},
                        {"feasible", p.feasible},
                        {"model", add_model(models, p.poses.model->get())},
                        {"duration", p.poses.duration},
                        {"frames", body_frames_json(p.poses.model->get(), p.poses.qpos)}});
    out.push_back({{"variation", path.variation},
                   {"label", path.label},
                   {"points_total", path.points_total},
                   {"points_measured", path.points_measured},
                   {"end_distance", number_or_null(path.end_distance)},
                   {"by_index", path.by_index},
                   {"points", points}});
  }
  return out;
}

nlohmann::json blends_json(const std::optional<GalleryBlends>& blends, nlohmann::json& models) {
  if (!blends) return nullptr;
  nlohmann::json points = nlohmann::json::array();
  for (const GalleryBlend& b : blends->blends)
    points.push_back({{"label", b.label},
                      {"weights", b.weights},
                      {"constraint", number_or_null(b.constraint)},
                      {"failed", b.failed},
                      {"fell", b.fell},
                      {"feasible", b.feasible},
                      {"distances", numbers_json(b.distances)},
                      {"nearest", b.nearest >= 0 ? nlohmann::json(b.nearest) : nlohmann::json(nullptr)},
                      {"model", add_model(models, b.poses.model->get())},
                      {"duration", b.poses.duration},
                      {"frames", body_frames_json(b.poses.model->get(), b.poses.qpos)}});
  return {{"samples", blends->samples},
          {"seed", blends->seed},
          {"feasible", blends->feasible},
          {"feasible_fraction", number_or_null(blends->feasible_fraction)},
          {"path_points", blends->path_points},
          {"path_feasible_fraction", number_or_null(blends->path_feasible_fraction)},
          {"points", points}};
}

nlohmann::json progress_json(const std::optional<GalleryProgress>& p) {
  if (!p) return nlohmann::json::object();
  return {{"generations_total", p->generations_total}, {"generation", p->generation},
          {"D", numbers_json(p->D)}, {"best_D", numbers_json(p->best_D)},
          {"constraint", rows_json(p->constraint)}, {"dmin", rows_json(p->dmin)}};
}

nlohmann::json shapes_json(const std::optional<GalleryShapes>& shapes) {
  if (!shapes) return nullptr;
  return {{"names", shapes->names}, {"scales", rows_json(shapes->scales)}};
}

// Per motion (null where the suite's file has no entry for it): {"held", "count", "share",
// "kinds": {KIND: {"held", "count"}}}, KIND as robustness.json names them.
nlohmann::json robustness_json(const std::optional<GallerySuite>& suite) {
  if (!suite) return nullptr;
  nlohmann::json motions = nlohmann::json::array();
  for (const std::optional<GalleryRobustness>& r : suite->motions) {
    if (!r) {
      motions.push_back(nullptr);
      continue;
    }
    nlohmann::json kinds = nlohmann::json::object();
    for (const auto& [key, c] : r->kinds) kinds[key] = {{"held", c.held}, {"count", c.count}};
    motions.push_back({{"held", r->all.held}, {"count", r->all.count}, {"share", r->share}, {"kinds", kinds}});
  }
  return {{"source", suite->source}, {"suite", suite->suite}, {"motions", motions}};
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

nlohmann::json gallery_json(const GalleryData& g, std::span<const GroundStrip> ground) {
  nlohmann::json data = {{"format", "diverse.gallery"},
                         {"version", 1},
                         {"task", g.task},
                         {"metric", g.metric},
                         {"fps", g.fps}};
  for (const auto& [key, value] : g.settings.items()) data["run"][key] = value;

  nlohmann::json models = nlohmann::json::array();
  nlohmann::json motions = nlohmann::json::array();
  // How the page first looks at the motions (render/view_plan.h): from the side or
  // three-quarters, following each character or not; the same choice as the film strip's.
  std::vector<PosedModel> posed;
  for (const GalleryMotion& m : g.motions) posed.push_back({m.poses.model->get(), m.poses.qpos});
  const ViewPlan plan = plan_view(posed);
  data["view"] = {{"three_quarter", plan.three_quarter},
                  {"follow", plan.follow},
                  {"heading", plan.heading},
                  {"azimuth", plan.direction.azimuth},
                  {"elevation", plan.direction.elevation}};
  for (const GalleryMotion& m : g.motions) {
    nlohmann::json motion = {{"label", m.label},
                             {"index", m.index},
                             {"model", add_model(models, m.poses.model->get())},
                             {"constraint", m.constraint},
                             {"dmin", m.dmin},
                             {"fell", m.fell},
                             {"failed", m.failed},
                             {"status", m.status},
                             {"duration", m.poses.duration},
                             {"frames", body_frames_json(m.poses.model->get(), m.poses.qpos)}};
    // Effort and distance from M0, whether the motion keeps the run's bounds, and how far
    // its planted feet slide (task/foot_slip.h).
    const std::pair<const char*, const std::optional<double>*> figures[] = {
        {"effort", &m.effort}, {"effort_ratio", &m.effort_ratio},
        {"positive_work", &m.positive_work}, {"distance_to_m0", &m.distance_to_m0}};
    for (const auto& [key, value] : figures)
      if (*value) motion[key] = number_or_null(**value);
    if (m.within_bounds) motion["within_bounds"] = *m.within_bounds;
    if (m.foot_slip) motion["foot_slip"] = *m.foot_slip;
    motions.push_back(std::move(motion));
  }
  nlohmann::json strips = nlohmann::json::array();
  // [x0, x1] along the track, or [x0, x1, y, radius] for a disc centred between x0 and x1.
  for (const GroundStrip& s : ground) {
    if (s.radius > 0) {
      strips.push_back({round4(s.x_min), round4(s.x_max), round4(s.y), round4(s.radius)});
    } else {
      strips.push_back({round4(s.x_min), round4(s.x_max)});
    }
  }
  data["scene"] = {{"strips", strips}};
  data["motions"] = motions;
  data["distances"] = g.distances;
  data["progress"] = progress_json(g.progress);
  data["shape"] = shapes_json(g.shapes);
  data["notes"] = g.notes;
  data["robustness"] = robustness_json(g.robustness);
  data["paths"] = paths_json(g.paths, models);
  data["blend"] = blends_json(g.blends, models);
  data["models"] = models;
  return data;
}

nlohmann::json gallery_data(const RunView& run, const GalleryOptions& options) {
  return gallery_json(collect_gallery_data(run, options), run_ground_strips(run));
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
