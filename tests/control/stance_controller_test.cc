// Stance control of the 3D characters (control/stance_controller.h): each stands for 10 s
// from its standing pose, and recovers from 0.3 m/s of initial COM velocity forward,
// backward and sideways (an initial root velocity, never an external force), with every
// joint's net torque (motor plus damping) within its limit at every step.
//
// Standing means, over the whole rollout: the COM stays above 85 % of its standing height,
// no body but the feet touches the floor, the pelvis (root) stays within 20 degrees of
// upright, neither foot slides more than 2 cm; and at the end the character is at rest
// (COM speed below 2 cm/s, every joint slower than 0.05 rad/s).
#include "control/stance_controller.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "character/character.h"
#include "physics/drive.h"
#include "physics/model.h"
#include "physics/rollout.h"
#include "render/film_strip.h"
#include "render/image.h"

namespace diverse {
namespace {

constexpr double kComFraction = 0.85;     // of the standing COM height
constexpr double kMaxTiltDeg = 20.0;      // root from upright
constexpr double kMaxSlide = 0.02;        // m, each foot
constexpr double kRestComSpeed = 0.02;    // m/s at the end
constexpr double kRestJointSpeed = 0.05;  // rad/s at the end
constexpr double kRestComError = 0.02;    // m, COM from the soles' centre at the end

std::string character_file(const std::string& name) {
  return std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/" + name + ".toml";
}

struct Loaded {
  std::shared_ptr<const CharacterSpec> spec;
  std::shared_ptr<const SharedModel> model;
  Character body;
};

Loaded load(const std::string& name) {
  Loaded l;
  l.spec = std::make_shared<CharacterSpec>(load_character_file(character_file(name)));
  l.model = SharedModel::from_file(l.spec->model);
  l.body = bind_character(l.spec, l.model->get(), l.spec->model);
  return l;
}

JointDrive drive_for(const Character& body, Damping damping = Damping::kMujoco) {
  std::vector<DrivenJoint> joints;
  for (const CharacterJoint& j : body.joints) joints.push_back({j.actuator, j.dof, j.torque_limit});
  return JointDrive(std::move(joints), SaturatedDrive::kExplicit, damping);
}

// What the rollout saw.
struct Outcome {
  double standing_com = 0;    // COM height at the start (m)
  double min_com = INFINITY;  // lowest COM height (m)
  double max_tilt_deg = 0;    // root from upright
  double max_slide = 0;       // m, largest horizontal foot displacement from the start
  int non_foot_contacts = 0;  // steps with a contact of a body other than the feet
  double final_com_speed = 0, final_joint_speed = 0;
  double max_com_offset = 0;   // m, largest horizontal COM distance from its start
  double final_com_error = 0;  // m, horizontal COM distance from the soles' centre at the end
  std::vector<std::vector<double>> frames;  // qpos at the requested steps
  RolloutStats stats;
  NetTorqueCheck torque;
};

class StanceHooks : public StepHooks {
 public:
  StanceHooks(const Character& body, StanceController& stance, JointDrive& drive, Outcome& out)
      : body_(body), stance_(stance), drive_(drive), out_(out) {}

  void start(const mjModel* m, const mjData* d) {
    for (int s = 0; s < 2; ++s) {
      const double* x = d->xpos + 3 * body_.feet[static_cast<size_t>(s)];
      foot0_[static_cast<size_t>(s)] = {x[0], x[1]};
    }
    const double* c = d->subtree_com + 3 * body_.root_body;
    com0_ = {c[0], c[1]};
    out_.standing_com = c[2];
    (void)m;
  }

  void control(mjModel* m, mjData* d) override { stance_.control(m, d, drive_); }

  // Steps at which observe() keeps the state's qpos (Outcome::frames).
  std::vector<int> capture;

  bool observe(const mjModel* m, const mjData* d) override {
    if (std::find(capture.begin(), capture.end(), step_) != capture.end()) {
      out_.frames.emplace_back(d->qpos, d->qpos + m->nq);
    }
    ++step_;
    const int root = body_.root_body;
    out_.min_com = std::min(out_.min_com, d->subtree_com[3 * root + 2]);
    out_.max_com_offset = std::max(
        out_.max_com_offset,
        std::hypot(d->subtree_com[3 * root] - com0_[0], d->subtree_com[3 * root + 1] - com0_[1]));
    const double up = std::clamp(d->xmat[9 * root + 8], -1.0, 1.0);
    out_.max_tilt_deg = std::max(out_.max_tilt_deg, std::acos(up) * 180.0 / M_PI);
    for (int s = 0; s < 2; ++s) {
      const double* x = d->xpos + 3 * body_.feet[static_cast<size_t>(s)];
      out_.max_slide =
          std::max(out_.max_slide, std::hypot(x[0] - foot0_[static_cast<size_t>(s)][0],
                                              x[1] - foot0_[static_cast<size_t>(s)][1]));
    }
    bool non_foot = false;
    for (int c = 0; c < d->ncon; ++c) {
      for (int g : {d->contact[c].geom1, d->contact[c].geom2}) {
        const int b = m->geom_bodyid[g];
        if (body_.is_link(m, b) && !body_.is_foot_geom(m, g)) non_foot = true;
      }
    }
    if (non_foot) ++out_.non_foot_contacts;
    out_.final_com_speed =
        std::hypot(stance_.com_velocity()[0], stance_.com_velocity()[1], stance_.com_velocity()[2]);
    double joint_speed = 0;
    for (const CharacterJoint& j : body_.joints)
      joint_speed = std::max(joint_speed, std::fabs(d->qvel[j.dof]));
    out_.final_joint_speed = joint_speed;
    out_.final_com_error = std::hypot(stance_.com()[0] - stance_.support_centre()[0],
                                      stance_.com()[1] - stance_.support_centre()[1]);
    return false;
  }

 private:
  const Character& body_;
  StanceController& stance_;
  JointDrive& drive_;
  Outcome& out_;
  std::array<std::array<double, 2>, 2> foot0_{};
  std::array<double, 2> com0_{};
  int step_ = 0;
};

// Runs `seconds` from the standing pose with the root's linear velocity `v` (world),
// keeping the qpos at the steps in `capture`.
Outcome stand(const Loaded& c, const std::array<double, 3>& v, double seconds,
              const std::vector<int>& capture = {}, Damping damping = Damping::kMujoco) {
  SimWorker worker(c.model);
  worker.reset();
  mjModel* m = worker.model();
  mjData* d = worker.data();
  StanceController stance(c.body, m);
  const std::vector<double> pose = stance.standing_pose(m);
  mju_copy(d->qpos, pose.data(), m->nq);
  for (int i = 0; i < 3; ++i) d->qvel[c.body.root_dof + i] = v[static_cast<size_t>(i)];
  mj_forward(m, d);
  stance.reset(m, d);
  JointDrive drive = drive_for(c.body, damping);
  Outcome out;
  StanceHooks hooks(c.body, stance, drive, out);
  hooks.capture = capture;
  hooks.start(m, d);
  StepRecorder record;
  out.stats = run_rollout(worker, hooks, static_cast<int>(std::lround(seconds / m->opt.timestep)),
                          drive, &record);
  mjModel* plain = mj_copyModel(nullptr, c.model->get());
  out.torque = check_net_torque(plain, record, drive.joints());
  mj_deleteModel(plain);
  return out;
}

void expect_stood(const Outcome& o, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_FALSE(o.stats.unstable) << o.stats.instability;
  EXPECT_GT(o.min_com, kComFraction * o.standing_com);
  EXPECT_EQ(o.non_foot_contacts, 0);
  EXPECT_LT(o.max_tilt_deg, kMaxTiltDeg);
  EXPECT_LT(o.max_slide, kMaxSlide);
  EXPECT_LT(o.final_com_speed, kRestComSpeed);
  EXPECT_LT(o.final_joint_speed, kRestJointSpeed);
  EXPECT_LT(o.final_com_error, kRestComError) << "back over the middle of the feet";
  EXPECT_LE(o.torque.worst_excess, 0.01)
      << "net torque over a limit at step " << o.torque.worst_step;
  EXPECT_FALSE(o.torque.blew_up);
}

std::string describe(const Outcome& o) {
  char buf[500];
  std::snprintf(
      buf, sizeof buf,
      "COM %.3f..%.3f m, tilt %.1f deg, slide %.4f m, COM moved %.3f m, non-foot contacts %d, "
      "end COM speed %.4f m/s, joint speed %.4f rad/s, COM off the feet %.4f m, "
      "worst torque excess %.4f",
      o.min_com, o.standing_com, o.max_tilt_deg, o.max_slide, o.max_com_offset, o.non_foot_contacts,
      o.final_com_speed, o.final_joint_speed, o.final_com_error, o.torque.worst_excess);
  return buf;
}

class Stance3d : public ::testing::TestWithParam<const char*> {};

// The start pose: the legs leaned about the feet until the COM is over the soles' centre,
// the soles flat on the floor, the root upright.
TEST_P(Stance3d, StandingPoseHasTheComOverFlatFeet) {
  const Loaded c = load(GetParam());
  const mjModel* m = c.model->get();
  StanceController stance(c.body, m);
  const std::vector<double> pose = stance.standing_pose(m);
  ASSERT_EQ(pose.size(), static_cast<size_t>(m->nq));
  mjData* d = mj_makeData(m);
  mju_copy(d->qpos, pose.data(), m->nq);
  mj_forward(m, d);
  double centre_x = 0, centre_y = 0, n = 0;
  for (int g = 0; g < m->ngeom; ++g) {
    if (!c.body.is_foot_geom(m, g)) continue;
    EXPECT_NEAR(d->geom_xmat[9 * g + 8], 1.0, 1e-9) << "sole flat";
    const double* R = d->geom_xmat + 9 * g;
    const double bottom = d->geom_xpos[3 * g + 2] - (std::fabs(R[6]) * m->geom_size[3 * g] +
                                                     std::fabs(R[7]) * m->geom_size[3 * g + 1] +
                                                     std::fabs(R[8]) * m->geom_size[3 * g + 2]);
    EXPECT_NEAR(bottom, 0.0, 1e-6) << "sole on the floor";
    centre_x += d->geom_xpos[3 * g];
    centre_y += d->geom_xpos[3 * g + 1];
    n += 1;
  }
  ASSERT_GT(n, 0);
  EXPECT_NEAR(d->subtree_com[3 * c.body.root_body], centre_x / n, 1e-4);
  EXPECT_NEAR(d->subtree_com[3 * c.body.root_body + 1], centre_y / n, 1e-4);
  EXPECT_NEAR(d->xmat[9 * c.body.root_body + 8], 1.0, 1e-9) << "root upright";
  mj_deleteData(d);
}

// A push-off's speed: the virtual force's damping drives the COM towards the velocity set
// with set_com_velocity, F_xy = M (com_kp e - com_kd (v - v_d)); a push is not held to the
// support polygon, so the force differs by exactly M com_kd v_d.
TEST_P(Stance3d, APushDrivesTheComTowardsItsSpeed) {
  const Loaded c = load(GetParam());
  SimWorker worker(c.model);
  worker.reset();
  mjModel* m = worker.model();
  mjData* d = worker.data();
  StanceController stance(c.body, m);
  const std::vector<double> pose = stance.standing_pose(m);
  mju_copy(d->qpos, pose.data(), m->nq);
  mj_forward(m, d);
  stance.reset(m, d);
  JointDrive drive = drive_for(c.body);
  // Settle onto the feet (the standing pose's soles touch the floor within a few steps).
  for (int k = 0; k < 50; ++k) {
    mj_step1(m, d);
    stance.control(m, d, drive);
    drive.apply(m, d);
    mj_step2(m, d);
  }
  mj_forward(m, d);
  stance.set_com_force(StanceController::ComForce::kPush);
  stance.control(m, d, drive);
  ASSERT_TRUE(stance.stance()[0] && stance.stance()[1]) << "both feet on the ground";
  const std::array<double, 3> still = stance.virtual_force();
  stance.set_com_velocity(3.0, -1.0);
  stance.control(m, d, drive);
  const std::array<double, 3> pushed = stance.virtual_force();
  const double M = stance.mass(), kd = StanceGains{}.com_kd;
  EXPECT_NEAR(pushed[0] - still[0], M * kd * 3.0, 1e-6 * M);
  EXPECT_NEAR(pushed[1] - still[1], -M * kd * 1.0, 1e-6 * M);
  EXPECT_DOUBLE_EQ(pushed[2], still[2]);
}

TEST_P(Stance3d, StandsTenSeconds) {
  const Loaded c = load(GetParam());
  const Outcome o = stand(c, {0, 0, 0}, 10.0);
  std::printf("%s stands: %s\n", GetParam(), describe(o).c_str());
  expect_stood(o, "standing");
  EXPECT_LT(o.max_com_offset, 0.1);
}

TEST_P(Stance3d, RecoversFromAPushForward) {
  const Loaded c = load(GetParam());
  const Outcome o = stand(c, {0.3, 0, 0}, 10.0);
  std::printf("%s forward 0.3 m/s: %s\n", GetParam(), describe(o).c_str());
  expect_stood(o, "0.3 m/s forward");
}

TEST_P(Stance3d, RecoversFromAPushBackward) {
  const Loaded c = load(GetParam());
  const Outcome o = stand(c, {-0.3, 0, 0}, 10.0);
  std::printf("%s backward 0.3 m/s: %s\n", GetParam(), describe(o).c_str());
  expect_stood(o, "0.3 m/s backward");
}

TEST_P(Stance3d, RecoversFromAPushSideways) {
  const Loaded c = load(GetParam());
  const Outcome left = stand(c, {0, 0.3, 0}, 10.0);
  std::printf("%s left 0.3 m/s: %s\n", GetParam(), describe(left).c_str());
  expect_stood(left, "0.3 m/s to the left");
  const Outcome right = stand(c, {0, -0.3, 0}, 10.0);
  std::printf("%s right 0.3 m/s: %s\n", GetParam(), describe(right).c_str());
  expect_stood(right, "0.3 m/s to the right");
}

// Under constrained damping (physics/drive.h) the stance controller's world-frame dampers
// (the feet's and the torso's world angular velocities about each joint's axis, the root's
// damping shared by the stance legs) are rows of the drive's solve, so that they act on the
// end-of-step velocities the contacts allow, as the planar jump's world-pitch dampers do.
// The character stands and recovers from each push as under MuJoCo's damping.
TEST_P(Stance3d, StandsAndRecoversUnderConstrainedDamping) {
  const Loaded c = load(GetParam());
  for (const std::array<double, 3>& v : std::vector<std::array<double, 3>>{
           {0, 0, 0}, {0.3, 0, 0}, {-0.3, 0, 0}, {0, 0.3, 0}, {0, -0.3, 0}}) {
    const Outcome o = stand(c, v, 10.0, {}, Damping::kConstrained);
    std::printf("%s (%.1f, %.1f) m/s, constrained damping: %s\n", GetParam(), v[0], v[1], describe(o).c_str());
    expect_stood(o, "constrained damping");
  }
}

// A film strip of each character standing and recovering from the three pushes, at
// 0, 0.25, 0.5, 1, 2 and 10 s. Written to DIVERSE_STANCE_IMAGES/<name>-stand.png when that
// variable names a directory (docs/images/ holds the committed ones), else to a temporary
// directory; either way the picture must not be blank.
TEST_P(Stance3d, FilmStrip) {
  const Loaded c = load(GetParam());
  const double h = c.model->get()->opt.timestep;
  const std::vector<double> times{0, 0.25, 0.5, 1, 2, 10};
  std::vector<int> steps;
  for (double t : times) steps.push_back(static_cast<int>(std::lround(t / h)) - (t > 0 ? 1 : 0));
  struct Case {
    const char* label;
    std::array<double, 3> v;
  };
  const std::vector<Case> cases{
      {"stand", {0, 0, 0}}, {"fwd", {0.3, 0, 0}}, {"back", {-0.3, 0, 0}}, {"left", {0, 0.3, 0}}};
  std::vector<FilmRow> rows;
  for (const Case& k : cases) {
    Outcome o = stand(c, k.v, times.back(), steps);
    ASSERT_EQ(o.frames.size(), times.size()) << k.label;
    rows.push_back(FilmRow{c.model->get(), k.label, std::move(o.frames)});
  }
  FilmStripOptions options;
  options.title = std::string(GetParam()) + ": standing, and 0.3 m/s pushes (initial velocity)";
  options.column_labels = {"0 s", "0.25 s", "0.5 s", "1 s", "2 s", "10 s"};
  options.tile_width = 200;
  options.tile_height = 260;
  options.camera_direction.azimuth = 125;
  options.camera_direction.elevation = -8;
  const char* dir = std::getenv("DIVERSE_STANCE_IMAGES");
  const std::filesystem::path out =
      (dir != nullptr && *dir != 0 ? std::filesystem::path(dir)
                                   : std::filesystem::temp_directory_path()) /
      (std::string(GetParam()) + "-stand.png");
  const Image image = render_film_strip(rows, options);
  write_png(out.string(), image);
  const size_t bytes = static_cast<size_t>(image.width()) * static_cast<size_t>(image.height()) * 3;
  size_t dark = 0;
  for (size_t i = 0; i < bytes; ++i) dark += image.data()[i] < 180 ? 1 : 0;
  EXPECT_GT(dark, bytes / 50) << "the picture shows something";
  std::printf("film strip: %s\n", out.string().c_str());
}

// The planar human (a root of x, z and pitch): stance control as the land phase of
// skills/jump_forward.toml runs it (the `stance` module), with knee and foot gains (its
// character file leaves the hips, knees and ankles to the jump's phases).
Outcome stand_planar(const std::array<double, 3>& v, double seconds) {
  const Loaded c = load("human2d");
  SimWorker worker(c.model);
  worker.reset();
  mjModel* m = worker.model();
  mjData* d = worker.data();
  StanceController stance(c.body, m);
  for (std::size_t k = 0; k < c.body.joints.size(); ++k) {
    const JointRole role = c.body.groups[static_cast<std::size_t>(c.body.joints[k].group)].role;
    if (role == JointRole::kKnee || role == JointRole::kAnkle) stance.set_joint_gains(static_cast<int>(k), 300, 30);
  }
  const std::vector<double> pose = stance.standing_pose(m);
  mju_copy(d->qpos, pose.data(), m->nq);
  d->qvel[c.body.root_x_dof] = v[0];
  mj_forward(m, d);
  stance.reset(m, d);
  JointDrive drive = drive_for(c.body);
  Outcome out;
  StanceHooks hooks(c.body, stance, drive, out);
  hooks.start(m, d);
  StepRecorder record;
  out.stats = run_rollout(worker, hooks, static_cast<int>(std::lround(seconds / m->opt.timestep)), drive, &record);
  mjModel* plain = mj_copyModel(nullptr, c.model->get());
  out.torque = check_net_torque(plain, record, drive.joints());
  mj_deleteModel(plain);
  return out;
}

TEST(Stance2d, StandsAndRecoversFromPushesInItsPlane) {
  for (double v : {0.0, 0.3, -0.3}) {
    const Outcome o = stand_planar({v, 0, 0}, 10.0);
    std::printf("human2d %+.1f m/s: %s\n", v, describe(o).c_str());
    expect_stood(o, "human2d at " + std::to_string(v) + " m/s");
  }
}

INSTANTIATE_TEST_SUITE_P(Characters, Stance3d, ::testing::Values("human3d", "robot3d"),
                         [](const ::testing::TestParamInfo<const char*>& param_info) {
                           return std::string(param_info.param);
                         });

}  // namespace
}  // namespace diverse
