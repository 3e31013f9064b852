// Offscreen rendering of MuJoCo models on machines with no display and no GPU.
//
// GL: OSMesa (Mesa's off-screen interface, Debian package libosmesa6-dev) with the llvmpipe
// software rasterizer. It needs no X server, no DISPLAY, no GPU and no environment variable,
// and a context is one call. EGL's surfaceless platform also works on Mesa, but has to be
// chosen with EGL_PLATFORM=surfaceless and goes through libglvnd's vendor selection: two
// more ways to fail on a user's machine for no gain in software. libmujoco does not link GL;
// it loads its GL entry points from the context current when mjr_makeContext runs, so the
// context is made current first (as MuJoCo's `record` sample does with -DMJ_OSMESA). Costs
// are measured in docs/guide/rendering.md.
//
// Each renderer keeps its own copy of the model, adjusted for pictures: MuJoCo 2.2.2 draws
// offscreen into a framebuffer sized by <visual><global offwidth offheight>, so the copy
// gets the picture's size (any model works, whatever it sets); the camera's field of view
// and near/far planes follow the camera; the headlight is set for an even look; built-in
// meshes are coarser (vertices dominate llvmpipe's cost). The caller's model is untouched.
//
// The look, chosen to read well on screen and in print: the scene is drawn at `supersample`
// times the picture size without multisampling; where nothing was drawn (the depth buffer
// still at its cleared value) a sky gradient is painted; the result is box-filtered down,
// so edges are smooth and silhouettes blend with the sky rather than the GL clear colour.
// The model's floor plane is replaced by a plain light floor with a track along x whose tone
// alternates every `band_width`, so travelled distance can be read; ground strips mark
// x-intervals such as a landing region. A model without lights gets one overhead light;
// directional lights cast shadows mapped around the bodies in each picture (see
// fit_shadows in offscreen.cc). Body colours are the model's geom rgba and materials.
//
// Threads: a GL context can be current on only one thread at a time, and MuJoCo keeps its
// renderer state in that context. An OffscreenRenderer must therefore be used by one thread
// at a time. render() makes its own context current on the calling thread, so several
// renderers may take turns on one thread, and distinct renderers may run on distinct threads
// at once (each owns its context, scene and mjData).
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "render/image.h"

namespace diverse {

// Free camera for side views of planar characters (which move in the world x-z plane).
// MuJoCo's convention: the camera looks at `lookat` from `distance` away along the direction
// (cos(el) cos(az), cos(el) sin(az), sin(el)).
struct SideCamera {
  std::array<double, 3> lookat{0.0, 0.0, 1.0};  // m, world frame
  double distance = 6.0;                         // m from lookat
  double azimuth = 90.0;    // deg; 90 looks along +y with +x to the right, -90 along -y
  double elevation = -6.0;  // deg; negative looks down onto the floor
  double fovy = 30.0;       // deg, vertical field of view; narrow keeps perspective mild
};

// Axis-aligned box in world coordinates (m); empty until a point is added.
struct Bounds {
  std::array<double, 3> lo{std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::infinity()};
  std::array<double, 3> hi{-std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity()};

  bool empty() const { return !(lo[0] <= hi[0]); }
  void add(const std::array<double, 3>& point);
  void merge(const Bounds& other);
};

// Box around the visible geoms (groups 0-2) of every body except the world body, over all
// frames (each a qpos of size model->nq; throws std::invalid_argument otherwise). Spheres,
// capsules, cylinders, boxes and ellipsoids are bounded exactly, meshes and other shapes by
// their bounding sphere.
Bounds pose_bounds(const mjModel* model, std::span<const std::vector<double>> frames);
// The same box for each frame on its own (an empty qpos gives an empty box).
std::vector<Bounds> pose_bounds_each(const mjModel* model,
                                     std::span<const std::vector<double>> frames);

// Height (m) of the model's floor: the first plane geom of the world body whose normal
// points up. Empty if the model has none.
std::optional<double> floor_height(const mjModel* model);

// A camera looking in the direction of `direction` (its azimuth, elevation and fovy are
// kept) placed so that the whole box is in view for a picture of the given aspect ratio
// (width / height), leaving `margin` of the half-width and half-height free on each side.
SideCamera fit_side_camera(const Bounds& bounds, double aspect, const SideCamera& direction = {},
                           double margin = 0.08);

// Poses of one model, e.g. the frames of one motion.
struct PosedModel {
  const mjModel* model = nullptr;
  std::span<const std::vector<double>> frames;  // each a qpos of size model->nq
};

// A coloured interval of the floor along world x, e.g. a landing region; or, with
// radius > 0, a disc of that radius centred at ((x_min + x_max) / 2, y) (a landing
// point with a radius, as 3D tasks have).
struct GroundStrip {
  double x_min = 0.0;  // m, world x
  double x_max = 0.0;  // m, world x
  Rgb color{96, 180, 96};
  double radius = 0.0;  // m; > 0: a disc
  double y = 0.0;       // m, world y of the disc's centre
};

// The camera shared by every picture of a set of motions: fitted to all their poses, the
// floor under them (a character in flight is still read against the ground) and the ground
// strips, for pictures of the given aspect ratio (width / height). Throws
// std::invalid_argument if a motion has no model.
SideCamera fit_shared_camera(std::span<const PosedModel> motions, double aspect,
                             const std::vector<GroundStrip>& ground_strips,
                             const SideCamera& direction = {}, double margin = 0.08);

// Look of the pictures; defaults are chosen to read well on screen and in print.
struct RenderStyle {
  Rgb sky_top{250, 251, 253};     // background at the top of the picture
  Rgb sky_bottom{218, 227, 238};  // background at the horizon
  // Replace the model's floor plane (if any) by a plain floor with a track along x whose
  // tones alternate every band_width, so travelled distance can be read off.
  bool floor_bands = true;
  Rgb floor{236, 236, 234};
  double track_half_width = 1.0;  // m, across the track (world y about the camera's lookat)
  double band_width = 0.5;        // m, along world x
  Rgb band_light{222, 222, 220};
  Rgb band_dark{198, 198, 196};
  bool add_light = true;    // add a shadow-casting overhead light if the model has none
  bool shadows = true;      // about 3/4 of a picture's cost with llvmpipe
  int shadow_size = 1024;   // px, least side of the shadow map (doubled for a tall character, up to 4096)
  int supersample = 2;      // render at this multiple of the size, then box-filter (1..4)
};

class OffscreenRenderer {
 public:
  // Pictures of width x height pixels of `model`, which must outlive the renderer. Throws
  // std::invalid_argument on a bad size or supersample, std::runtime_error if no GL context
  // can be created (see docs/guide/rendering.md).
  OffscreenRenderer(const mjModel* model, int width, int height, RenderStyle style = {});
  ~OffscreenRenderer();
  OffscreenRenderer(const OffscreenRenderer&) = delete;
  OffscreenRenderer& operator=(const OffscreenRenderer&) = delete;

  // The model posed at qpos (size model->nq, else std::invalid_argument), seen from camera.
  Image render(std::span<const double> qpos, const SideCamera& camera);

  // Strips drawn on the floor in every later picture.
  void set_ground_strips(std::vector<GroundStrip> strips);

  int width() const;
  int height() const;
  const mjModel* model() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace diverse
