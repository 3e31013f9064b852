// "aim_legs": the landing controller of a character with a free root, the 3D form of the
// paper's (section 6; control/module_foot_placement.h for planar characters). While the
// root is within 60 degrees of upright (blended in from 60 to 0 degrees), the hips point
// each leg at
//     x_c + offset_s f + velocity_gain_s v + w_s l,
// x_c where the COM is predicted to come down ballistically to its take-off height (plus
// the landing surface's), v the COM's horizontal velocity, f and l the forward and lateral
// axes of the heading the motion began with and w_s the foot's standing lateral offset.
// The hip's pitch and roll angles that point the leg there come from the leg's geometry at
// the model's standing pose with the joints between hip and foot at their targets, solved
// exactly for a universal hip with orthogonal axes (hip_angles_for).
//
// Settings: offset_left, offset_right (m), velocity_gain_left, velocity_gain_right (s).
#pragma once

#include <array>
#include <vector>

#include "control/skill_module.h"

namespace diverse {

// The hip angles that point a leg in a given direction, for a hip of two orthogonal hinges
// (pitch, then roll; `has_roll` false: pitch only). All vectors in one frame (the root's);
// `leg` is the unit vector from the hip to the foot with both hip angles at their reference
// (qpos0) values, `direction` the unit vector the leg should point along. Returns the
// angles to add to the references, the roll nearest 0 of the two exact solutions; a
// direction the hip cannot reach exactly (roll alone limits the component along the pitch
// axis) gets the nearest one.
struct HipAngles {
  double pitch = 0, roll = 0;
};
HipAngles hip_angles_for(const std::array<double, 3>& leg, const std::array<double, 3>& pitch_axis,
                         const std::array<double, 3>& roll_axis, bool has_roll,
                         const std::array<double, 3>& direction);

class AimLegsModule : public SkillModule {
 public:
  AimLegsModule(const ModuleSettings& settings, const Character& body);
  void reset(const mjModel* m, const mjData* d, SkillState& s) override;
  void set_targets(const mjModel* m, const mjData* d, SkillState& s) override;

 private:
  // A leg at the model's qpos0, in the root's frame: the hip, then the joints between the
  // hip and the foot (the knee; the bird's ankle), top down, and the foot's joint.
  struct LegGeometry {
    int hip_pitch = -1, hip_roll = -1;            // Character::joints indices (-1: none)
    double pitch0 = 0, roll0 = 0;                 // their qpos0 values (rad)
    std::array<double, 3> pitch_axis{}, roll_axis{};
    std::vector<int> middle;                      // joints between hip and foot, top down
    std::vector<double> middle0;                  // their qpos0 values
    std::vector<std::array<double, 3>> axes;      // their axes
    std::vector<std::array<double, 3>> segments;  // hip -> first, ..., last -> foot joint
    double lateral = 0;  // m, the foot's standing offset along the root's y from the feet's middle
  };
  // Sets the hip targets so that each leg points at its goal (world x, y on the ground).
  void point_legs(const mjData* d, const std::array<std::array<double, 2>, 2>& goals, std::vector<double>& targets) const;

  const Character& body_;
  std::array<double, 2> offset_, velocity_gain_;  // left, right
  std::array<LegGeometry, 2> legs_{};
  int foot_group_ = -1;  // the sagittal left/right group on the foot bodies
  std::array<double, 4> root0_inv_{1, 0, 0, 0};  // inverse of the root's qpos0 orientation
  double heading_ = 0;  // rad, the root's yaw as the motion began
};

}  // namespace diverse
