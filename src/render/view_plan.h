// How a set of motions is looked at: from the side or three-quarters, from one fixed camera
// or from cameras that follow each character.
//
//   ViewPlan plan = plan_view(motions);     // motions: PosedModel per motion (all frames)
//
// - Direction. A planar character (its root is not a free joint) is seen from its side, as
//   the paper's figures are (SideCamera's defaults: azimuth 90, looking along +y). A
//   character with a free root (the 3D human, the bird robot) is seen three-quarters: from
//   its right and kThreeQuarterTurn degrees toward its front, and from kThreeQuarterElevation
//   degrees above, so both the direction it moves in and the width of its body (arms out,
//   legs apart, a lean to one side) show. Its front is where its root faces (the root
//   body's x axis, the characters' forward) in the first motion's first frame, so a jump
//   backwards is seen from the front as well, travelling away to the side; a root whose x
//   axis points up or down there takes the direction the motion travels (from first to
//   last frame, if more than kTravelForHeading), else +x.
// - Following. When any motion's root travels more than kFollowDistance horizontally (a
//   walk of 15 m, a long jump), one camera fitted to everything would show the character
//   a few pixels tall. Then every picture is centred on its own character instead: the
//   camera keeps its direction and distance, fitted to every pose relative to the pose's
//   anchor (the root's x and y; the height stays), and moves with the anchor. Videos
//   smooth the anchor over a window of time (follow_anchors), so the stride's sway does not
//   shake the picture. Positions then no longer compare across pictures; the floor's bands
//   and the metre label in each picture tell where the character is.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <span>
#include <vector>

#include "render/offscreen.h"

namespace diverse {

constexpr double kThreeQuarterTurn = 45.0;        // deg from the side toward the front
constexpr double kThreeQuarterElevation = -18.0;  // deg (negative looks down)
constexpr double kTravelForHeading = 0.5;         // m
constexpr double kFollowDistance = 4.0;           // m of root travel

struct ViewPlan {
  SideCamera direction;     // azimuth, elevation and fovy (lookat and distance are fitted)
  bool three_quarter = false;
  bool follow = false;
  double heading = 0.0;     // deg, the characters' front (world azimuth of +x is 0)
};

// True if the model's root (the first body with degrees of freedom under the world) moves
// on a free joint.
bool has_free_root(const mjModel* model);

// The root body (the first child of the world body with degrees of freedom), or -1.
int root_body(const mjModel* model);

// The plan for these motions (rules above). Motions without frames are skipped.
ViewPlan plan_view(std::span<const PosedModel> motions);

// Where a following camera centres one pose: the root body's world x and y, z = 0.
std::array<double, 3> follow_anchor(const mjModel* model, std::span<const double> qpos);

// follow_anchor of every frame, averaged over the frames within `half_window` frames on
// either side (fewer at the ends), so a camera that follows moves smoothly.
std::vector<std::array<double, 3>> follow_anchors(const mjModel* model,
                                                  std::span<const std::vector<double>> frames,
                                                  int half_window);

// The camera that follows (see above) for pictures of the given aspect ratio: its lookat is
// relative to each picture's anchor (add the anchor to place it). `anchors[i][k]` is the
// anchor of motions[i].frames[k]; the floor under every pose is kept in view.
SideCamera fit_following_camera(std::span<const PosedModel> motions,
                                std::span<const std::vector<std::array<double, 3>>> anchors,
                                double aspect, const SideCamera& direction, double margin = 0.08);

// `camera` moved to look at anchor + its relative lookat.
SideCamera at_anchor(const SideCamera& camera, const std::array<double, 3>& anchor);

}  // namespace diverse
