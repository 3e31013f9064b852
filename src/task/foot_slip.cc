#include "task/foot_slip.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "physics/mujoco_guard.h"

namespace diverse {
namespace {

// Ends the stance; what slid since the feet last carried load is not part of it (they were
// lifting off).
template <class Track>
void close_stance(Track& track, FootSlip::Side& side) {
  side.stances.push_back(track.stance);
  track.open = false;
  track.held.clear();
  track.pending = track.pending_speed = 0;
  track.pending_time = -1;
}

void add_speed(FootSlip::Stance& stance, FootSlip::Side& side, double speed, double time, double h) {
  stance.slide += speed * h;
  stance.max_speed = std::max(stance.max_speed, speed);
  if (speed > side.max_speed) {
    side.max_speed = speed;
    side.max_speed_time = time;
  }
}

}  // namespace

std::vector<int> foot_geom_sides(const mjModel* m, const Character& body) {
  std::vector<int> sides(static_cast<size_t>(m->ngeom), kSceneGeom);
  for (int g = 0; g < m->ngeom; ++g) {
    int foot = -1;
    if (body.is_foot_geom(m, g, &foot)) {
      sides[static_cast<size_t>(g)] = foot;
    } else if (body.is_link(m, m->geom_bodyid[g])) {
      sides[static_cast<size_t>(g)] = kBodyGeom;
    }
  }
  return sides;
}


FootSlipMeter::FootSlipMeter(const mjModel* m, std::vector<int> geom_sides, const FootSlipOptions& options)
    : geom_sides_(std::move(geom_sides)), options_(options), h_(m->opt.timestep),
      jac_foot_(3 * static_cast<size_t>(m->nv)), jac_other_(3 * static_cast<size_t>(m->nv)) {}

void FootSlipMeter::point_velocity(const mjModel* m, const mjData* data, int b, const mjtNum* p,
                                   std::vector<mjtNum>& jac, mjtNum v[3]) {
  v[0] = v[1] = v[2] = 0;
  if (m->body_weldid[b] == 0) return;  // welded to the world: still
  mj_jac(m, data, jac.data(), nullptr, p, b);
  for (int r = 0; r < 3; ++r)
    for (int j = 0; j < m->nv; ++j) v[r] += jac[static_cast<size_t>(r * m->nv + j)] * data->qvel[j];
}

void FootSlipMeter::after_step(const mjModel* m, const mjData* data) {
  // The part of v along the surface with normal n.
  auto tangential = [](const mjtNum v[3], const mjtNum n[3]) {
    const mjtNum along = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
    return std::hypot(v[0] - along * n[0], v[1] - along * n[1], v[2] - along * n[2]);
  };
  const int k = slip_.steps++;
  const double h = h_;
  const double t = k * h;
  // Per side: touching the scene at all, the slowest loaded point's tangential speed
  // relative to what it touches, and the loaded points.
  std::array<bool, 2> touching{false, false};
  std::array<double, 2> slowest{INFINITY, INFINITY};
  std::array<std::vector<HeldPoint>, 2>& loaded = loaded_;
  loaded[0].clear();
  loaded[1].clear();
  for (int c = 0; c < data->ncon; ++c) {
    const mjContact& con = data->contact[c];
    const int a = geom_sides_[static_cast<size_t>(con.geom1)], b = geom_sides_[static_cast<size_t>(con.geom2)];
    int side = -1, foot_geom = -1, other_geom = -1;
    if (a >= 0 && b == kSceneGeom) {
      side = a, foot_geom = con.geom1, other_geom = con.geom2;
    } else if (b >= 0 && a == kSceneGeom) {
      side = b, foot_geom = con.geom2, other_geom = con.geom1;
    } else {
      continue;
    }
    const size_t s = static_cast<size_t>(side);
    touching[s] = true;
    mjtNum force[6];
    mj_contactForce(m, data, c, force);
    if (!(force[0] > options_.min_normal_force)) continue;
    const int foot_body = m->geom_bodyid[foot_geom];
    mjtNum vf[3], vo[3];
    point_velocity(m, data, foot_body, con.pos, jac_foot_, vf);
    point_velocity(m, data, m->geom_bodyid[other_geom], con.pos, jac_other_, vo);
    const mjtNum rel[3] = {vf[0] - vo[0], vf[1] - vo[1], vf[2] - vo[2]};
    slowest[s] = std::min(slowest[s], tangential(rel, con.frame));
    // The point in the foot's frame: x_local = R^T (p - x_body).
    HeldPoint held;
    held.body = foot_body;
    const mjtNum* R = data->xmat + 9 * foot_body;
    const mjtNum* x = data->xpos + 3 * foot_body;
    for (int r = 0; r < 3; ++r)
      held.local[r] = R[r] * (con.pos[0] - x[0]) + R[3 + r] * (con.pos[1] - x[1]) + R[6 + r] * (con.pos[2] - x[2]);
    std::copy(con.frame, con.frame + 3, held.normal);
    loaded[s].push_back(held);
  }
  for (size_t s = 0; s < 2; ++s) {
    Track& track = tracks_[s];
    FootSlip::Side& side = slip_.sides[s];
    if (touching[s]) {
      if (!track.open) {
        track.open = true;
        track.from_start = k == 0;
        track.stance = FootSlip::Stance{t, t, 0, 0};
      }
      track.last_down = t;
      track.stance.end = t;
    } else if (track.open && t - track.last_down >= options_.min_air_time - 1e-9) {
      close_stance(track, side);
    }
    if (!track.open) continue;
    if (!track.from_start && t - track.stance.begin < options_.impact_time - 1e-9) continue;  // the impact
    if (!loaded[s].empty()) {
      // Loaded again: the steps since the last loaded one belong to the stance.
      if (track.pending > 0) {
        track.stance.slide += track.pending;
        track.stance.max_speed = std::max(track.stance.max_speed, track.pending_speed);
        if (track.pending_speed > side.max_speed) {
          side.max_speed = track.pending_speed;
          side.max_speed_time = track.pending_time;
        }
      }
      track.pending = track.pending_speed = 0;
      add_speed(track.stance, side, slowest[s], t, h);
      std::swap(track.held, loaded[s]);
    } else if (!track.held.empty()) {
      // No loaded point (soft contacts chatter, or the feet are lifting off): the feet's
      // points that last carried load stand for them, counted if load comes back.
      double speed = INFINITY;
      for (const HeldPoint& p : track.held) {
        const mjtNum* R = data->xmat + 9 * p.body;
        const mjtNum* x = data->xpos + 3 * p.body;
        mjtNum world[3];
        for (int r = 0; r < 3; ++r) world[r] = x[r] + R[3 * r] * p.local[0] + R[3 * r + 1] * p.local[1] + R[3 * r + 2] * p.local[2];
        mjtNum v[3];
        point_velocity(m, data, p.body, world, jac_foot_, v);
        speed = std::min(speed, tangential(v, p.normal));
      }
      track.pending += speed * h;
      if (speed > track.pending_speed) {
        track.pending_speed = speed;
        track.pending_time = t;
      }
    }
  }
}

double FootSlipMeter::largest_so_far() const {
  double worst = 0;
  for (size_t s = 0; s < 2; ++s) {
    for (const FootSlip::Stance& st : slip_.sides[s].stances) worst = std::max(worst, st.slide);
    if (tracks_[s].open) worst = std::max(worst, tracks_[s].stance.slide);
  }
  return worst;
}

FootSlip FootSlipMeter::finish() const {
  FootSlip slip = slip_;
  std::array<Track, 2> tracks = tracks_;
  for (size_t s = 0; s < 2; ++s) {
    if (tracks[s].open) close_stance(tracks[s], slip.sides[s]);
    FootSlip::Side& side = slip.sides[s];
    for (const FootSlip::Stance& st : side.stances) {
      side.total += st.slide;
      side.largest = std::max(side.largest, st.slide);
    }
    if (!side.stances.empty()) side.mean = side.total / static_cast<double>(side.stances.size());
  }
  return slip;
}

FootSlip measure_foot_slip(mjModel* m, const StepRecorder& record, const std::vector<int>& geom_sides,
                           const FootSlipOptions& options) {
  FootSlipMeter meter(m, geom_sides, options);
  mjData* d = mj_makeData(m);
  std::string why;
  bool blew_up = false;
  const bool ok = replay_each_step(m, d, record, record.steps(), [&](int, const mjData* data) {
    if (simulation_unstable(m, data, &why)) {
      blew_up = true;
      return false;
    }
    meter.after_step(m, data);
    return true;
  });
  mj_deleteData(d);
  FootSlip slip = meter.finish();
  slip.blew_up = blew_up || !ok;
  return slip;
}

FootSlip measure_foot_slip(mjModel* m, const StepRecorder& record, const Character& body,
                           const FootSlipOptions& options) {
  return measure_foot_slip(m, record, foot_geom_sides(m, body), options);
}

nlohmann::json foot_slip_json(const FootSlip& slip, const FootSlipOptions& options) {
  nlohmann::json j = {{"largest_per_stance", slip.largest()},
                      {"max_speed", slip.max_speed()},
                      {"steps", slip.steps},
                      {"blew_up", slip.blew_up},
                      {"definition",
                       {{"min_normal_force", options.min_normal_force},
                        {"impact_time", options.impact_time},
                        {"min_air_time", options.min_air_time}}}};
  const char* names[2] = {"left", "right"};
  for (size_t s = 0; s < 2; ++s) {
    const FootSlip::Side& side = slip.sides[s];
    std::vector<double> slides;
    for (const FootSlip::Stance& st : side.stances) slides.push_back(st.slide);
    j[names[s]] = {{"stances", side.stances.size()},
                   {"total", side.total},
                   {"mean_per_stance", side.mean},
                   {"largest_per_stance", side.largest},
                   {"max_speed", side.max_speed},
                   {"max_speed_time", side.max_speed_time},
                   {"stance_slides", slides}};
  }
  return j;
}

}  // namespace diverse
