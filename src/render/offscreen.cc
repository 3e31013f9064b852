#include "render/offscreen.h"

#include <GL/osmesa.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace diverse {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
// Room in the scene for the model's geoms plus the floor, its bands and ground strips.
constexpr int kMaxBands = 400;
constexpr int kMaxDecorGeoms = kMaxBands + 200;
// Thickness of the floor, its bands and ground strips (m); each sits on the one before.
constexpr double kBandThickness = 0.002;

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};

void check_qpos(const mjModel* model, std::size_t size) {
  if (size != static_cast<std::size_t>(model->nq)) {
    throw std::invalid_argument("render: qpos has " + std::to_string(size) +
                                " values, model has nq = " + std::to_string(model->nq));
  }
}

// Grows `bounds` by the world-axis-aligned box around one geom in its pose in `data`:
// exact for spheres, capsules, cylinders, boxes and ellipsoids, the bounding sphere else.
void add_geom_bounds(const mjModel* m, const mjData* d, int g, Bounds& bounds) {
  const mjtNum* p = d->geom_xpos + 3 * g;
  const mjtNum* R = d->geom_xmat + 9 * g;  // row-major: R[3 * i + k] = axis k's world i
  const mjtNum* s = m->geom_size + 3 * g;
  for (int i = 0; i < 3; ++i) {
    const double* row = R + 3 * i;
    double extent = m->geom_rbound[g];
    switch (m->geom_type[g]) {
      case mjGEOM_SPHERE: extent = s[0]; break;
      case mjGEOM_CAPSULE: extent = std::abs(row[2]) * s[1] + s[0]; break;
      case mjGEOM_CYLINDER:
        extent = std::abs(row[2]) * s[1] + s[0] * std::sqrt(std::max(0.0, 1.0 - row[2] * row[2]));
        break;
      case mjGEOM_BOX:
        extent = std::abs(row[0]) * s[0] + std::abs(row[1]) * s[1] + std::abs(row[2]) * s[2];
        break;
      case mjGEOM_ELLIPSOID:
        extent = std::sqrt(row[0] * row[0] * s[0] * s[0] + row[1] * row[1] * s[1] * s[1] +
                           row[2] * row[2] * s[2] * s[2]);
        break;
      default: break;
    }
    std::array<double, 3> lo{p[0], p[1], p[2]};
    std::array<double, 3> hi = lo;
    lo[i] -= extent;
    hi[i] += extent;
    bounds.add(lo);
    bounds.add(hi);
  }
}

// Shadow-map texels wider than this (m) show self-shadowing "acne" on the floor.
constexpr double kMaxTexel = 0.0022;

// Radius of the sphere around a bounding box, with 5 cm to spare.
double radius_of(const Bounds& b) {
  double diagonal = 0.0;
  for (int i = 0; i < 3; ++i) diagonal += (b.hi[i] - b.lo[i]) * (b.hi[i] - b.lo[i]);
  return 0.5 * std::sqrt(diagonal) + 0.05;
}

// The shadow map's side (px) for a model: at least `least`, doubled (up to 4096) until a
// map over the bodies standing at qpos0 has texels of at most kMaxTexel, so a tall
// character (the 2.9 m bird robot) casts clean shadows too.
int shadow_size_for(const mjModel* m, mjData* d, int least) {
  mju_copy(d->qpos, m->qpos0, m->nq);
  mj_kinematics(m, d);
  Bounds b;
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_bodyid[g] == 0 || m->geom_group[g] > 2) continue;
    add_geom_bounds(m, d, g, b);
  }
  int size = std::max(least, 64);
  if (b.empty()) return size;
  while (size < 4096 && 2.0 * radius_of(b) / size > kMaxTexel) size *= 2;
  return size;
}

int floor_geom(const mjModel* m) {
  for (int g = 0; g < m->ngeom; ++g) {
    // A plane's normal is its local z axis; world-body geoms are posed in the world frame,
    // so the normal's world z component is entry zz of geom_quat's rotation matrix.
    if (m->geom_bodyid[g] != 0 || m->geom_type[g] != mjGEOM_PLANE) continue;
    mjtNum mat[9];
    mju_quat2Mat(mat, m->geom_quat + 4 * g);
    if (mat[8] > 0.999) return g;
  }
  return -1;
}

}  // namespace

void Bounds::add(const std::array<double, 3>& point) {
  for (int i = 0; i < 3; ++i) {
    lo[i] = std::min(lo[i], point[i]);
    hi[i] = std::max(hi[i], point[i]);
  }
}

void Bounds::merge(const Bounds& other) {
  if (other.empty()) return;
  add(other.lo);
  add(other.hi);
}

std::vector<Bounds> pose_bounds_each(const mjModel* model,
                                     std::span<const std::vector<double>> frames) {
  std::vector<Bounds> each(frames.size());
  std::unique_ptr<mjData, DataDeleter> data(mj_makeData(model));
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const std::vector<double>& qpos = frames[k];
    if (qpos.empty()) continue;  // a tile left empty on purpose
    check_qpos(model, qpos.size());
    std::copy(qpos.begin(), qpos.end(), data->qpos);
    mj_kinematics(model, data.get());
    for (int g = 0; g < model->ngeom; ++g) {
      if (model->geom_bodyid[g] == 0 || model->geom_group[g] > 2) continue;
      add_geom_bounds(model, data.get(), g, each[k]);
    }
  }
  return each;
}

Bounds pose_bounds(const mjModel* model, std::span<const std::vector<double>> frames) {
  Bounds bounds;
  for (const Bounds& b : pose_bounds_each(model, frames)) bounds.merge(b);
  return bounds;
}

std::optional<double> floor_height(const mjModel* model) {
  const int g = floor_geom(model);
  if (g < 0) return std::nullopt;
  return model->geom_pos[3 * g + 2];
}

SideCamera fit_side_camera(const Bounds& bounds, double aspect, const SideCamera& direction,
                           double margin) {
  SideCamera camera = direction;
  if (bounds.empty()) return camera;
  const double az = camera.azimuth * kDegree;
  const double el = camera.elevation * kDegree;
  // MuJoCo's free-camera frame (mjv_updateCamera): forward, up, right = forward x up.
  const std::array<double, 3> forward{std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                                      std::sin(el)};
  const std::array<double, 3> up{-std::sin(el) * std::cos(az), -std::sin(el) * std::sin(az),
                                 std::cos(el)};
  const std::array<double, 3> right{forward[1] * up[2] - forward[2] * up[1],
                                    forward[2] * up[0] - forward[0] * up[2],
                                    forward[0] * up[1] - forward[1] * up[0]};
  const double tan_v = std::tan(0.5 * camera.fovy * kDegree) * (1.0 - margin);
  const double tan_h = tan_v * aspect;
  for (int i = 0; i < 3; ++i) camera.lookat[i] = 0.5 * (bounds.lo[i] + bounds.hi[i]);
  // A point at offset q from lookat has depth distance + q.forward in the camera; it is in
  // view when |q.right| <= tan_h * depth and |q.up| <= tan_v * depth. Checking the eight
  // corners bounds the whole box.
  double distance = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    std::array<double, 3> q{};
    for (int i = 0; i < 3; ++i) {
      q[i] = ((corner >> i & 1) ? bounds.hi[i] : bounds.lo[i]) - camera.lookat[i];
    }
    auto dot = [&q](const std::array<double, 3>& v) {
      return q[0] * v[0] + q[1] * v[1] + q[2] * v[2];
    };
    distance = std::max(distance, std::abs(dot(right)) / tan_h - dot(forward));
    distance = std::max(distance, std::abs(dot(up)) / tan_v - dot(forward));
  }
  camera.distance = std::max(distance, 0.1);
  return camera;
}

SideCamera fit_shared_camera(std::span<const PosedModel> motions, double aspect,
                             const std::vector<GroundStrip>& ground_strips,
                             const SideCamera& direction, double margin) {
  Bounds bounds;
  std::optional<double> floor;
  for (std::size_t i = 0; i < motions.size(); ++i) {
    if (motions[i].model == nullptr) {
      throw std::invalid_argument("render: motion " + std::to_string(i) + " has no model");
    }
    bounds.merge(pose_bounds(motions[i].model, motions[i].frames));
    if (const auto z = floor_height(motions[i].model)) floor = floor ? std::min(*floor, *z) : *z;
  }
  if (bounds.empty()) return direction;
  // Ground strips lie on the floor in the middle of the motions' depth.
  const double y = 0.5 * (bounds.lo[1] + bounds.hi[1]);
  if (floor) bounds.add({bounds.lo[0], y, *floor});
  const double strip_z = floor.value_or(bounds.lo[2]);
  for (const GroundStrip& strip : ground_strips) {
    const double y0 = strip.radius > 0 ? strip.y - strip.radius : y;
    const double y1 = strip.radius > 0 ? strip.y + strip.radius : y;
    bounds.add({strip.x_min, y0, strip_z});
    bounds.add({strip.x_max, y1, strip_z});
  }
  return fit_side_camera(bounds, aspect, direction, margin);
}

struct OffscreenRenderer::Impl {
  const mjModel* model = nullptr;
  std::unique_ptr<mjModel, ModelDeleter> copy;
  std::unique_ptr<mjData, DataDeleter> data;
  int width = 0;
  int height = 0;
  RenderStyle style;
  int floor = -1;  // floor geom id, -1 if none
  std::vector<GroundStrip> strips;

  OSMesaContext context = nullptr;
  std::vector<unsigned char> window;  // OSMesa's default framebuffer (unused; must exist)
  mjvScene scene;
  mjvOption option;
  mjrContext gl;
  std::vector<unsigned char> rgb;  // supersampled picture, bottom row first
  std::vector<float> depth;
  float clear_depth = 1.0f;  // depth where nothing was drawn (1 in MuJoCo 2.2; 0 if reverse-Z)
  bool scene_made = false;
  bool gl_made = false;

  // Frees MuJoCo's GL resources inside their own context, then the context; also after a
  // constructor that failed part way.
  ~Impl() {
    if (context == nullptr) return;
    if (gl_made && OSMesaMakeCurrent(context, window.data(), GL_UNSIGNED_BYTE, 1, 1)) {
      mjr_freeContext(&gl);
    }
    if (scene_made) mjv_freeScene(&scene);
    OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
    OSMesaDestroyContext(context);
  }

  void make_current() {
    if (!OSMesaMakeCurrent(context, window.data(), GL_UNSIGNED_BYTE, 1, 1)) {
      throw std::runtime_error("render: cannot make the OSMesa context current");
    }
  }

  // A flat, unlit-looking decoration on the floor: a box from (x0, y0) to (x1, y1), or a
  // disc, its top at z_top.
  void add_box(double x0, double x1, double y0, double y1, double z_top, Rgb color,
               float emission) {
    const mjtNum size[3] = {0.5 * (x1 - x0), 0.5 * (y1 - y0), 0.5 * kBandThickness};
    add_floor_geom(mjGEOM_BOX, size, 0.5 * (x0 + x1), 0.5 * (y0 + y1), z_top, color, emission);
  }
  void add_disc(double x, double y, double radius, double z_top, Rgb color, float emission) {
    // mjv_initGeom reads a cylinder's size as the model does: radius, half-height.
    const mjtNum size[3] = {radius, 0.5 * kBandThickness, 0};
    add_floor_geom(mjGEOM_CYLINDER, size, x, y, z_top, color, emission);
  }
  void add_floor_geom(int type, const mjtNum size[3], double x, double y, double z_top, Rgb color,
                      float emission) {
    if (scene.ngeom >= scene.maxgeom) return;
    mjvGeom* geom = scene.geoms + scene.ngeom++;
    const mjtNum pos[3] = {x, y, z_top - 0.5 * kBandThickness};
    const float rgba[4] = {color.r / 255.0f, color.g / 255.0f, color.b / 255.0f, 1.0f};
    mjv_initGeom(geom, type, size, pos, nullptr, rgba);
    geom->category = mjCAT_DECOR;
    geom->emission = emission;
    geom->specular = 0.0f;
    geom->reflectance = 0.0f;
  }

  // Emission that tops up the light falling on an upward-facing surface to full strength,
  // so the floor shows its style colours under any model's lights and only shadows darken
  // it (MuJoCo's lighting: colour = rgba * (emission + sum of ambient + diffuse * cos)).
  float floor_emission(const SideCamera& camera) const {
    double light = 0.0;
    for (int i = 0; i < scene.nlight; ++i) {
      const mjvLight& l = scene.lights[i];
      double down = -l.dir[2];
      if (l.headlight) {  // shines along the camera's forward axis (set in mjr_render)
        down = -std::sin(camera.elevation * kDegree);
      } else if (!l.directional) {  // point or spot light: take it as shining straight down
        down = l.pos[2] > 0 ? 1.0 : 0.0;
      }
      light += l.ambient[1] + l.diffuse[1] * std::max(0.0, down);
    }
    return static_cast<float>(std::max(0.0, 1.0 - light));
  }

  void add_floor(const SideCamera& camera) {
    if (floor < 0 || !style.floor_bands) return;
    const double z = copy->geom_pos[3 * floor + 2];
    // Drop the model's own floor: a plain floor and a banded track replace it, with no
    // depth fighting. The plain floor reaches far enough to meet the sky near the horizon.
    int kept = 0;
    for (int i = 0; i < scene.ngeom; ++i) {
      const mjvGeom& geom = scene.geoms[i];
      if (geom.objtype == mjOBJ_GEOM && geom.objid == floor) continue;
      scene.geoms[kept++] = geom;
    }
    scene.ngeom = kept;
    const float emission = floor_emission(camera);
    const double reach = 20.0 * camera.distance + 20.0;
    const double cx = camera.lookat[0];
    const double cy = camera.lookat[1];
    add_box(cx - reach, cx + reach, cy - reach, cy + reach, z, style.floor, emission);
    // The track: bands only as wide as the view at the far edge of the track.
    const double track = style.track_half_width;
    const double aspect = static_cast<double>(width) / height;
    const double half_view =
        (camera.distance + track) * std::tan(0.5 * camera.fovy * kDegree) * aspect;
    const double band = style.band_width;
    if (band > 0.0 && track > 0.0) {
      const double half = std::min(half_view + 2.0 * band, 0.5 * kMaxBands * band);
      const long first = std::lround(std::floor((cx - half) / band));
      const long last = std::lround(std::ceil((cx + half) / band));
      for (long k = first; k < last; ++k) {
        const Rgb color = (k % 2 == 0) ? style.band_light : style.band_dark;
        add_box(k * band, (k + 1) * band, cy - track, cy + track, z + kBandThickness, color,
                emission);
      }
    }
    for (const GroundStrip& strip : strips) {
      if (strip.radius > 0) {
        add_disc(0.5 * (strip.x_min + strip.x_max), strip.y, strip.radius, z + 2.0 * kBandThickness, strip.color,
                 emission);
      } else {
        add_box(strip.x_min, strip.x_max, cy - std::max(track, 0.5), cy + std::max(track, 0.5),
                z + 2.0 * kBandThickness, strip.color, emission);
      }
    }
  }

  // Adds an overhead light when the model has none.
  void add_light() {
    if (!style.add_light || copy->nlight > 0 || scene.nlight >= mjMAXLIGHT) return;
    mjvLight& light = scene.lights[scene.nlight++];
    light = mjvLight{};
    // From above, in front of the character and to the left: the shadow falls on the floor
    // behind and to the right, where it shows contact and flight without hiding the feet.
    const std::array<double, 3> dir{0.3, 0.4, -1.0};
    const double norm = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    for (int i = 0; i < 3; ++i) {
      light.dir[i] = static_cast<float>(dir[i] / norm);
      light.diffuse[i] = 0.5f;
      light.specular[i] = 0.2f;
    }
    light.attenuation[0] = 1.0f;
    light.cutoff = 180.0f;
    light.directional = 1;
    light.castshadow = 1;
  }

  // MuJoCo maps the shadows of a directional light over a cylinder of radius shadowClip
  // around the light's ray through its position. The ray is moved to pass through the
  // centre of the bodies (and the static objects in view) in the current pose, and the
  // radius is made just wide enough for them: all their shadows fall inside (the map is an
  // orthographic projection along the light), shadows follow a character that travels, and
  // the small radius keeps the map's texels at about 2 mm, free of the self-shadowing "acne"
  // a map spread over the whole view shows on the floor.
  void fit_shadows(const SideCamera& camera) {
    const double half_view = camera.distance * std::tan(0.5 * camera.fovy * kDegree) *
                             static_cast<double>(width) / height;
    const auto region = [&](bool with_static) {
      Bounds b;
      for (int g = 0; g < copy->ngeom; ++g) {
        if (copy->geom_group[g] > 2 || copy->geom_type[g] == mjGEOM_PLANE) continue;
        if (copy->geom_bodyid[g] == 0 &&
            (!with_static || std::abs(data->geom_xpos[3 * g] - camera.lookat[0]) > half_view)) {
          continue;
        }
        add_geom_bounds(copy.get(), data.get(), g, b);
      }
      return b;
    };
    // Past kMaxTexel per texel the floor shows acne: then only the moving bodies count.
    Bounds bodies = region(true);
    if (!bodies.empty() && 2.0 * radius_of(bodies) / gl.shadowSize > kMaxTexel) {
      bodies = region(false);
    }
    if (bodies.empty()) return;
    std::array<double, 3> centre{};
    for (int i = 0; i < 3; ++i) centre[i] = 0.5 * (bodies.lo[i] + bodies.hi[i]);
    const double radius = radius_of(bodies);
    gl.shadowClip = static_cast<float>(radius);
    // Far enough back along the ray that the near plane of the projection misses the bodies.
    const double back = radius + 0.2 * camera.distance + 2.0;
    for (int i = 0; i < scene.nlight; ++i) {
      mjvLight& light = scene.lights[i];
      if (!light.directional || !light.castshadow || light.headlight) continue;
      for (int k = 0; k < 3; ++k) {
        light.pos[k] = static_cast<float>(centre[k] - back * light.dir[k]);
      }
    }
  }
};

OffscreenRenderer::OffscreenRenderer(const mjModel* model, int width, int height,
                                     RenderStyle style)
    : impl_(std::make_unique<Impl>()) {
  if (width <= 0 || height <= 0 || style.supersample < 1 || style.supersample > 4) {
    throw std::invalid_argument("OffscreenRenderer: bad size " + std::to_string(width) + "x" +
                                std::to_string(height) + " or supersample " +
                                std::to_string(style.supersample));
  }
  Impl& r = *impl_;
  r.model = model;
  r.width = width;
  r.height = height;
  r.style = style;
  r.copy.reset(mj_copyModel(nullptr, model));
  r.data.reset(mj_makeData(r.copy.get()));
  r.floor = floor_geom(model);

  // The offscreen framebuffer is sized from the model (MuJoCo 2.2.2); multisampling is
  // replaced by supersampling, and the headlight is set for a light, even look.
  mjModel* m = r.copy.get();
  const int ss = style.supersample;
  m->vis.global.offwidth = width * ss;
  m->vis.global.offheight = height * ss;
  m->vis.quality.offsamples = 0;
  m->vis.quality.shadowsize = shadow_size_for(m, r.data.get(), style.shadow_size);
  // Coarser built-in meshes than MuJoCo's defaults (28 slices, 16 stacks, 4 quads per box
  // side): llvmpipe lights per vertex and draws the scene up to three times with shadows, so
  // vertices dominate the cost; at these sizes the silhouettes look the same.
  m->vis.quality.numslices = std::min(m->vis.quality.numslices, 20);
  m->vis.quality.numstacks = std::min(m->vis.quality.numstacks, 10);
  m->vis.quality.numquads = 1;
  m->vis.headlight.active = 1;
  for (int i = 0; i < 3; ++i) {
    m->vis.headlight.ambient[i] = 0.35f;
    m->vis.headlight.diffuse[i] = 0.45f;
    m->vis.headlight.specular[i] = 0.1f;
  }
  if (m->stat.extent <= 0) m->stat.extent = 1.0;

  r.context = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
  if (r.context == nullptr) {
    throw std::runtime_error("render: cannot create an OSMesa context (is libOSMesa installed?)");
  }
  r.window.assign(4, 0);
  r.make_current();

  mjv_defaultOption(&r.option);
  for (int i = 0; i < mjNGROUP; ++i) r.option.sitegroup[i] = 0;  // sites are markers, not bodies
  mjv_defaultScene(&r.scene);
  mjv_makeScene(m, &r.scene, m->ngeom + m->nsite + kMaxDecorGeoms);
  r.scene_made = true;
  mjr_defaultContext(&r.gl);
  mjr_makeContext(m, &r.gl, mjFONTSCALE_50);  // fonts unused: labels are drawn on the CPU
  r.gl_made = true;
  mjr_setBuffer(mjFB_OFFSCREEN, &r.gl);
  if (r.gl.currentBuffer != mjFB_OFFSCREEN || r.gl.offWidth < width * ss ||
      r.gl.offHeight < height * ss) {
    throw std::runtime_error("render: MuJoCo could not create its offscreen framebuffer");
  }
  // Read the depth an empty picture leaves, rather than assume MuJoCo's depth convention.
  {
    mj_kinematics(m, r.data.get());
    mjvCamera cam;
    mjv_defaultFreeCamera(m, &cam);
    mjv_updateScene(m, r.data.get(), &r.option, nullptr, &cam, mjCAT_ALL, &r.scene);
    r.scene.ngeom = 0;
    r.scene.flags[mjRND_SKYBOX] = 0;
    const mjrRect pixel{0, 0, 1, 1};
    mjr_render(pixel, &r.scene, &r.gl);
    mjr_readPixels(nullptr, &r.clear_depth, pixel, &r.gl);
  }
  r.rgb.resize(static_cast<std::size_t>(width) * height * ss * ss * 3);
  r.depth.resize(static_cast<std::size_t>(width) * height * ss * ss);
}

OffscreenRenderer::~OffscreenRenderer() = default;

Image OffscreenRenderer::render(std::span<const double> qpos, const SideCamera& camera) {
  Impl& r = *impl_;
  check_qpos(r.model, qpos.size());
  r.make_current();
  mjModel* m = r.copy.get();
  mjData* d = r.data.get();
  std::copy(qpos.begin(), qpos.end(), d->qpos);
  mj_kinematics(m, d);
  mj_camlight(m, d);

  // Near and far planes follow the camera so depth precision suits the distance; they are
  // given to MuJoCo relative to the model's extent.
  m->vis.global.fovy = static_cast<float>(camera.fovy);
  m->vis.map.znear = static_cast<float>(0.1 * camera.distance / m->stat.extent);
  m->vis.map.zfar = static_cast<float>((25.0 * camera.distance + 50.0) / m->stat.extent);
  mjvCamera cam;
  mjv_defaultCamera(&cam);
  cam.type = mjCAMERA_FREE;
  for (int i = 0; i < 3; ++i) cam.lookat[i] = camera.lookat[i];
  cam.distance = camera.distance;
  cam.azimuth = camera.azimuth;
  cam.elevation = camera.elevation;
  mjv_updateScene(m, d, &r.option, nullptr, &cam, mjCAT_ALL, &r.scene);
  r.add_light();
  r.fit_shadows(camera);
  r.add_floor(camera);
  r.scene.flags[mjRND_SKYBOX] = 0;  // the sky is painted from the depth buffer below
  r.scene.flags[mjRND_SHADOW] = r.style.shadows ? 1 : 0;

  const int ss = r.style.supersample;
  const int W = r.width * ss;
  const int H = r.height * ss;
  const mjrRect viewport{0, 0, W, H};
  mjr_setBuffer(mjFB_OFFSCREEN, &r.gl);
  mjr_render(viewport, &r.scene, &r.gl);
  mjr_readPixels(r.rgb.data(), r.depth.data(), viewport, &r.gl);

  // Paint the sky where nothing was drawn (the depth is still at its cleared value), from
  // sky_top at the top of the picture to sky_bottom at the horizon (the lowest row with
  // sky), then average ss x ss samples per pixel. GL rows run bottom-up, the image's down.
  int horizon = 0;  // supersampled rows from the top
  for (int row = 0; row < H; ++row) {
    const float* line = r.depth.data() + static_cast<std::size_t>(row) * W;
    if (std::any_of(line, line + W, [&r](float z) { return z == r.clear_depth; })) {
      horizon = std::max(horizon, H - 1 - row);
    }
  }
  std::vector<Rgb> sky(H);
  for (int row = 0; row < H; ++row) {
    const double t = horizon > 0 ? std::min(1.0, static_cast<double>(row) / horizon) : 0.0;
    auto mix = [t](std::uint8_t a, std::uint8_t b) {
      return static_cast<std::uint8_t>(std::lround(a + t * (b - a)));
    };
    sky[row] = {mix(r.style.sky_top.r, r.style.sky_bottom.r),
                mix(r.style.sky_top.g, r.style.sky_bottom.g),
                mix(r.style.sky_top.b, r.style.sky_bottom.b)};
  }
  Image image(r.width, r.height);
  const int samples = ss * ss;
  for (int y = 0; y < r.height; ++y) {
    for (int x = 0; x < r.width; ++x) {
      int sum[3] = {0, 0, 0};
      for (int j = 0; j < ss; ++j) {
        const int row_from_top = y * ss + j;
        const std::size_t row = static_cast<std::size_t>(H - 1 - row_from_top);
        for (int i = 0; i < ss; ++i) {
          const std::size_t k = row * W + x * ss + i;
          if (r.depth[k] == r.clear_depth) {
            const Rgb& c = sky[row_from_top];
            sum[0] += c.r;
            sum[1] += c.g;
            sum[2] += c.b;
          } else {
            for (int c = 0; c < 3; ++c) sum[c] += r.rgb[3 * k + c];
          }
        }
      }
      image.set_pixel(x, y,
                      Rgb{static_cast<std::uint8_t>((sum[0] + samples / 2) / samples),
                          static_cast<std::uint8_t>((sum[1] + samples / 2) / samples),
                          static_cast<std::uint8_t>((sum[2] + samples / 2) / samples)});
    }
  }
  return image;
}

void OffscreenRenderer::set_ground_strips(std::vector<GroundStrip> strips) {
  impl_->strips = std::move(strips);
}

int OffscreenRenderer::width() const { return impl_->width; }
int OffscreenRenderer::height() const { return impl_->height; }
const mjModel* OffscreenRenderer::model() const { return impl_->model; }

}  // namespace diverse
