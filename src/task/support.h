// Whether a character standing on its feet is balanced: its capture point over the support
// polygon of its feet's contacts.
//
// The capture point of the linear inverted pendulum, c + v sqrt(h / g) (c and v the
// whole-body COM's horizontal position and velocity, h its height above the contacts), is
// where the COM would come to rest if the feet held still. While it lies inside the convex
// hull of the points where the feet touch the ground, the stance can stop the COM over the
// feet; outside it no contact force can, and the body topples, however slowly it moves
// now. A jump's landing counts as at rest only when it is slow and balanced
// (task/task.h, TaskSimulation::balanced_rest).
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <vector>

#include "character/character.h"
#include "control/controller.h"
#include "core/polygon.h"

namespace diverse {

// The signed distance (m) from the capture point to the edge of the support polygon of
// the feet's contacts in the current state: positive inside, negative outside. A planar
// character's support is the x-interval of its contacts (it cannot fall sideways); a free
// root's the convex hull of their horizontal positions. -infinity without a foot contact.
double capture_point_margin(const mjModel* m, const mjData* d, const Character& body,
                            const std::array<double, 3>& com, const std::array<double, 3>& com_velocity);

// The outline of the soles of the feet that touch the ground (`contacts`): their whole
// outline, not just the points that touch now, so a foot landing on its heel supports the
// COM over its middle. It is each foot geom's horizontal extent: a capsule's axis end
// points lengthened by its radius, a box's corners, a sphere's centre and radius along x
// and y. A planar character's support is the outline's x-interval; a free root's its
// convex hull. Built once per state; margin() is the signed distance (m) of a horizontal
// point from its edge, positive inside, -infinity without a foot on the ground.
struct SoleOutline {
  bool planar = false;
  double lo = 0, hi = -1;   // planar: the x-interval (empty when lo > hi)
  std::vector<Vec2> hull;   // free root: the convex hull
  double margin(const Vec2& p) const;
};
SoleOutline sole_outline(const mjModel* m, const mjData* d, const Character& body, const ContactState& contacts);

}  // namespace diverse
