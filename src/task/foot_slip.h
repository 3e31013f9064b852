// How far planted feet slide: the "foot skate" of a motion, measured from its exact replay.
//
//   FootSlip s = measure_foot_slip(m, record, body);   // a copy of the saved model
//   s.sides[0].largest                                 // m, the left feet's worst stance
//
// The record (physics/rollout.h) is replayed with plain mj_step on the motion's saved
// model. After step k, mjData holds the contacts and contact forces of the state before
// the step and the velocity v_{k+1} the Euler step moved the positions with, so a point of
// the foot moves by J_p(q_k) v_{k+1} h over the step: its displacement, not an estimate.
//
// A side's feet (the foot body and the bodies below it, Character::is_foot_geom) are down
// while one of their geoms touches a geom that is not the character's. A stance runs from
// a touch-down to the last contact before the feet leave the ground for at least
// min_air_time (a shorter lift is contact chatter, as in task/walk_audit.h). In a stance,
// at every step past its first impact_time (the impact; a stance the record starts in has
// none), the side's slide speed is the SLOWEST tangential speed, over its loaded contact
// points (normal force above min_normal_force), of the foot's material point there
// relative to the other body's: a foot that pivots or rolls about a point has that point
// still, a foot that slides has none. MuJoCo's soft contacts chatter under a sliding foot
// (it hops by a fraction of a millimetre, and has no loaded point for a few steps), so a
// step without a loaded point counts with the slowest of the points that last carried
// load, if load comes back in the stance; the steps after the last loaded one (lift-off)
// do not count. The slide of a stance is that speed integrated over its steps (m). The
// definition and the published "skate" figures it compares with are in
// docs/reference/foot-slip.md.
#pragma once

#include <mujoco/mujoco.h>

#include <algorithm>
#include <array>
#include <nlohmann/json.hpp>
#include <vector>

#include "character/character.h"
#include "physics/rollout.h"

namespace diverse {

struct FootSlipOptions {
  double min_normal_force = 20;  // N: a contact point carries load above this
  double impact_time = 0.010;    // s after a contact begins, left out as the impact
  double min_air_time = 0.05;    // s: a shorter lift does not end the stance
};

struct FootSlip {
  struct Stance {
    double begin = 0, end = 0;  // s: the first and the last step with the feet down
    double slide = 0;           // m: the slowest loaded point's speed, integrated
    double max_speed = 0;       // m/s: the largest such speed in the stance
  };
  struct Side {
    std::vector<Stance> stances;
    double total = 0;            // m: over all stances
    double mean = 0;             // m per stance (0 without stances)
    double largest = 0;          // m: the stance that slid most
    double max_speed = 0;        // m/s: over all stances
    double max_speed_time = -1;  // s: when (-1 if the feet never slid)
  };
  std::array<Side, 2> sides;  // left, right
  int steps = 0;              // steps replayed
  bool blew_up = false;       // the replay hit a MuJoCo error before the record's end
  double largest() const { return std::max(sides[0].largest, sides[1].largest); }
  double max_speed() const { return std::max(sides[0].max_speed, sides[1].max_speed); }
};

// What each geom is to the measure: a foot of a side, another part of the character (its
// contacts with a foot are not with the ground), or the scene.
inline constexpr int kSceneGeom = -1;
inline constexpr int kBodyGeom = -2;

// Per geom of `m`: 0 or 1 (the left or right feet), kBodyGeom or kSceneGeom.
std::vector<int> foot_geom_sides(const mjModel* m, const Character& body);

// The measure step by step, for a rollout that measures itself (task/evaluate.h) or a
// replay: after_step() after each integration step, with mjData as mj_step leaves it
// (the contacts and forces of the state before the step, the velocity after it).
class FootSlipMeter {
 public:
  // `m` gives the timestep and the dofs; `geom_sides` as foot_geom_sides() gives it.
  FootSlipMeter(const mjModel* m, std::vector<int> geom_sides, const FootSlipOptions& options = {});
  void after_step(const mjModel* m, const mjData* d);
  // m: the largest slide of any stance so far, the open ones included.
  double largest_so_far() const;
  // The measure of the steps seen, open stances closed at the last one.
  FootSlip finish() const;

 private:
  // A material point of a foot where it last carried load: its body, its position in
  // that body's frame, and the surface normal there.
  struct HeldPoint {
    int body = -1;
    mjtNum local[3] = {0, 0, 0};
    mjtNum normal[3] = {0, 0, 1};
  };
  // One side's stance being measured.
  struct Track {
    bool open = false;            // a stance is under way
    bool from_start = false;      // it was under way when the record began (no impact)
    double last_down = 0;         // s: the last step with the feet down
    std::vector<HeldPoint> held;  // where the feet last carried load in this stance
    double pending = 0;           // m: slid since then, over steps without a loaded point
    double pending_speed = 0;     // m/s: the largest speed among those steps
    double pending_time = -1;     // s: when
    FootSlip::Stance stance;
  };
  // The velocity of body b's material point at p over the step: J_p(q_k) v_{k+1}.
  static void point_velocity(const mjModel* m, const mjData* d, int b, const mjtNum* p,
                             std::vector<mjtNum>& jac, mjtNum v[3]);

  std::vector<int> geom_sides_;
  FootSlipOptions options_;
  double h_ = 0;
  std::vector<mjtNum> jac_foot_, jac_other_;
  std::array<Track, 2> tracks_;
  std::array<std::vector<HeldPoint>, 2> loaded_;
  FootSlip slip_;
};

// Replays `record` on `m` (a private copy of the motion's saved model: its dof_damping is
// written) and measures both sides' feet. `geom_sides` as foot_geom_sides() gives it.
FootSlip measure_foot_slip(mjModel* m, const StepRecorder& record, const std::vector<int>& geom_sides,
                           const FootSlipOptions& options = {});

// The same for a character bound to `m`.
FootSlip measure_foot_slip(mjModel* m, const StepRecorder& record, const Character& body,
                           const FootSlipOptions& options = {});

// {"left": {...}, "right": {...}, "largest_per_stance", "max_speed"}: per side "stances",
// "total", "mean_per_stance", "largest_per_stance" (m), "max_speed" (m/s),
// "max_speed_time" (s) and "stance_slides" (m, in order); the options under "definition".
nlohmann::json foot_slip_json(const FootSlip& slip, const FootSlipOptions& options = {});

}  // namespace diverse
