#include "render/view_plan.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>

namespace diverse {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};

// World position and x axis of the root body in each frame.
struct RootTrack {
  std::vector<std::array<double, 3>> position;
  std::vector<std::array<double, 3>> x_axis;
};

RootTrack root_track(const mjModel* m, std::span<const std::vector<double>> frames) {
  RootTrack track;
  const int root = root_body(m);
  if (root < 0) return track;
  std::unique_ptr<mjData, DataDeleter> d(mj_makeData(m));
  for (const std::vector<double>& qpos : frames) {
    if (static_cast<int>(qpos.size()) != m->nq) continue;
    std::copy(qpos.begin(), qpos.end(), d->qpos);
    mj_kinematics(m, d.get());
    const double* p = d->xpos + 3 * root;
    const double* r = d->xmat + 9 * root;
    track.position.push_back({p[0], p[1], p[2]});
    track.x_axis.push_back({r[0], r[3], r[6]});
  }
  return track;
}

}  // namespace

int root_body(const mjModel* m) {
  for (int b = 1; b < m->nbody; ++b) {
    if (m->body_parentid[b] != 0) continue;
    // The first world child whose subtree has a joint.
    for (int c = b; c < m->nbody; ++c) {
      int up = c;
      while (up > 0 && up != b) up = m->body_parentid[up];
      if (up == b && m->body_jntnum[c] > 0) return b;
    }
  }
  return -1;
}

bool has_free_root(const mjModel* m) {
  const int root = root_body(m);
  if (root < 0) return false;
  for (int k = 0; k < m->body_jntnum[root]; ++k)
    if (m->jnt_type[m->body_jntadr[root] + k] == mjJNT_FREE) return true;
  return false;
}

ViewPlan plan_view(std::span<const PosedModel> motions) {
  ViewPlan plan;
  std::optional<double> heading;
  for (const PosedModel& motion : motions) {
    if (motion.model == nullptr || motion.frames.empty()) continue;
    const RootTrack track = root_track(motion.model, motion.frames);
    if (track.position.empty()) continue;
    if (has_free_root(motion.model)) plan.three_quarter = true;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (const auto& p : track.position)
      for (int i = 0; i < 2; ++i) lo[i] = std::min(lo[i], p[static_cast<std::size_t>(i)]), hi[i] = std::max(hi[i], p[static_cast<std::size_t>(i)]);
    if (std::hypot(hi[0] - lo[0], hi[1] - lo[1]) > kFollowDistance) plan.follow = true;
    if (!heading) {
      const auto& x = track.x_axis.front();
      const auto& a = track.position.front();
      const auto& b = track.position.back();
      if (std::hypot(x[0], x[1]) > 0.5) {
        heading = std::atan2(x[1], x[0]) / kDegree;
      } else if (std::hypot(b[0] - a[0], b[1] - a[1]) > kTravelForHeading) {
        heading = std::atan2(b[1] - a[1], b[0] - a[0]) / kDegree;
      } else {
        heading = 0.0;
      }
    }
  }
  if (plan.three_quarter) {
    plan.heading = heading.value_or(0.0);
    // The side view of a character facing +x has azimuth 90 (it looks along +y from the
    // character's right); turning the camera toward the front adds to it.
    plan.direction.azimuth = plan.heading + 90.0 + kThreeQuarterTurn;
    plan.direction.elevation = kThreeQuarterElevation;
  }
  return plan;
}

std::array<double, 3> follow_anchor(const mjModel* m, std::span<const double> qpos) {
  const std::vector<double> frame(qpos.begin(), qpos.end());
  const RootTrack track = root_track(m, std::span<const std::vector<double>>(&frame, 1));
  if (track.position.empty()) return {0, 0, 0};
  return {track.position[0][0], track.position[0][1], 0.0};
}

std::vector<std::array<double, 3>> follow_anchors(const mjModel* m,
                                                  std::span<const std::vector<double>> frames,
                                                  int half_window) {
  const RootTrack track = root_track(m, frames);
  std::vector<std::array<double, 3>> raw(frames.size(), {0, 0, 0});
  // Frames with no qpos (empty tiles) take no part; root_track skipped them.
  std::size_t t = 0;
  for (std::size_t k = 0; k < frames.size(); ++k)
    if (static_cast<int>(frames[k].size()) == m->nq && t < track.position.size()) {
      raw[k] = {track.position[t][0], track.position[t][1], 0.0};
      ++t;
    }
  std::vector<std::array<double, 3>> smooth(frames.size(), {0, 0, 0});
  const long n = static_cast<long>(frames.size());
  for (long k = 0; k < n; ++k) {
    const long a = std::max(0L, k - half_window), b = std::min(n - 1, k + half_window);
    double sx = 0, sy = 0;
    for (long j = a; j <= b; ++j) sx += raw[static_cast<std::size_t>(j)][0], sy += raw[static_cast<std::size_t>(j)][1];
    const double count = static_cast<double>(b - a + 1);
    smooth[static_cast<std::size_t>(k)] = {sx / count, sy / count, 0.0};
  }
  return smooth;
}

SideCamera fit_following_camera(std::span<const PosedModel> motions,
                                std::span<const std::vector<std::array<double, 3>>> anchors,
                                double aspect, const SideCamera& direction, double margin) {
  Bounds relative;
  for (std::size_t i = 0; i < motions.size() && i < anchors.size(); ++i) {
    const PosedModel& motion = motions[i];
    if (motion.model == nullptr) continue;
    const std::vector<Bounds> each = pose_bounds_each(motion.model, motion.frames);
    const std::optional<double> floor = floor_height(motion.model);
    for (std::size_t k = 0; k < each.size() && k < anchors[i].size(); ++k) {
      if (each[k].empty()) continue;
      const auto& a = anchors[i][k];
      Bounds b;
      b.add({each[k].lo[0] - a[0], each[k].lo[1] - a[1], each[k].lo[2]});
      b.add({each[k].hi[0] - a[0], each[k].hi[1] - a[1], each[k].hi[2]});
      if (floor) b.add({0.0, 0.0, *floor});
      relative.merge(b);
    }
  }
  return fit_side_camera(relative, aspect, direction, margin);
}

SideCamera at_anchor(const SideCamera& camera, const std::array<double, 3>& anchor) {
  SideCamera moved = camera;
  for (int i = 0; i < 3; ++i) moved.lookat[static_cast<std::size_t>(i)] += anchor[static_cast<std::size_t>(i)];
  return moved;
}

}  // namespace diverse
