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

#include "character/character.h"

namespace diverse {

// The signed distance (m) from the capture point to the edge of the support polygon of
// the feet's contacts in the current state: positive inside, negative outside. A planar
// character's support is the x-interval of its contacts (it cannot fall sideways); a free
// root's the convex hull of their horizontal positions. -infinity without a foot contact.
double capture_point_margin(const mjModel* m, const mjData* d, const Character& body,
                            const std::array<double, 3>& com, const std::array<double, 3>& com_velocity);

}  // namespace diverse
