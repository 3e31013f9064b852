// Task files: the committed tasks parse; every kind of bad input is a one-line UserError
// naming file, field and expectation; the constraint penalty follows SPEC 2.4.
#include "task/task.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "task/constraints.h"
#include "task/evaluate.h"
#include "task/term_landing.h"
#include "task/term_min_length.h"
#include "task/term_peak_height.h"
#include "task/term_pitch.h"
#include "task/term_rotation.h"

namespace diverse {
namespace {

namespace fs = std::filesystem;
const std::string kTasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";

// A valid task file whose text the tests then break one way at a time.
std::string valid_text() {
  return "name = \"t\"\n"
         "character = \"" + std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/human2d.xml\"\n"
         "metric = \"md\"\n"
         "variations = 4\n"
         "m0 = \"t.m0.json\"\n"
         "[controller]\n"
         "skill = \"" + std::string(DIVERSE_SOURCE_DIR) + "/skills/jump2d.toml\"\n"
         "[constraints]\n"
         "weight = 5000.0\n"
         "fall_penalty = 100000.0\n"
         "landing = { center = 1.0, half_width = 0.15 }\n";
}

class TaskFileTest : public ::testing::Test {
 protected:
  std::string write(const std::string& text) {
    const fs::path dir = fs::temp_directory_path() / ("diverse_task_test_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path p = dir / "t.toml";
    std::ofstream(p) << text;
    return p.string();
  }
  std::string error_of(const std::string& text) {
    const std::string path = write(text);
    try {
      load_task(path);
    } catch (const UserError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
      EXPECT_EQ(message.rfind(path, 0), 0u) << message;  // starts with the file
      return message.substr(path.size());
    }
    ADD_FAILURE() << "no error for:\n" << text;
    return "";
  }
  static std::string replace(std::string text, const std::string& from, const std::string& to) {
    text.replace(text.find(from), from.size(), to);
    return text;
  }
};

// The controller is a plug-in chosen by name; an unknown name lists the known ones, and a
// skill that cannot drive the character says why before any simulation.
TEST_F(TaskFileTest, ControllerTypeIsLookedUpAndCheckedAgainstTheCharacter) {
  const std::string skill = "skill = \"" + std::string(DIVERSE_SOURCE_DIR) + "/skills/jump2d.toml\"";
  EXPECT_EQ(error_of(replace(valid_text(), skill, "type = \"walk9\"")),
            ": controller.type: expected one of \"skill\", got \"walk9\"");
  EXPECT_EQ(error_of(replace(valid_text(), skill, skill + "\nbounce = 2")),
            ": controller.bounce: expected no such key (unknown key; known keys: type, skill, landing_height, balance, "
            "landing, the last the skill's modules as tables)");
  const Task planar = load_task(write(valid_text()));
  EXPECT_EQ(planar.controller_type->name(), std::string("skill"));
  EXPECT_EQ(planar.controller, "skill");
  EXPECT_EQ(planar.character_spec->name, "human2d");
  // The 3D human has a free root: the planar skill refuses it when the task is evaluated.
  const std::string path = write(replace(valid_text(), "human2d.xml", "human3d.toml"));
  try {
    TaskEvaluator ev(load_task(path));
    ADD_FAILURE() << "skills/jump2d.toml accepted a free-root character";
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()), std::string(DIVERSE_SOURCE_DIR) +
                                         "/skills/jump2d.toml: line 6: root: expected a character with a planar root, "
                                         "but the character " + std::string(DIVERSE_SOURCE_DIR) +
                                         "/assets/characters/human3d.toml has a free root");
  }
}

// The planar jump controller "jump2d" is the skill file skills/jump2d.toml now: a task
// that names it is told what to write instead, the path relative to the task file.
TEST_F(TaskFileTest, TheRetiredJumpControllerNamesItsSkillFile) {
  const std::string skill = "skill = \"" + std::string(DIVERSE_SOURCE_DIR) + "/skills/jump2d.toml\"";
  const fs::path dir = fs::temp_directory_path() / ("diverse_task_test_" + std::to_string(::getpid()));
  const std::string from = (fs::path(DIVERSE_SOURCE_DIR) / "skills/jump2d.toml")
                               .lexically_normal()
                               .lexically_relative(fs::absolute(dir).lexically_normal())
                               .string();
  for (const char* keys : {"type = \"jump2d\"", "type = \"jump2d\"\nlanding_control = true\nlevel_feet = true"}) {
    EXPECT_EQ(error_of(replace(valid_text(), skill, keys)),
              ": controller.type: expected skill = \"" + from +
                  "\" in place of type = \"jump2d\" (that controller is this skill file now, its keys the settings of "
                  "the skill's modules: docs/reference/skills.md)");
  }
}

TEST_F(TaskFileTest, CommittedTasksParse) {
  for (const char* name : {"backflip", "jump_forward", "jump_onto", "jump_over", "jump_high"}) {
    const Task t = load_task(resolve_task_path(name));
    EXPECT_EQ(t.name, name);
    EXPECT_TRUE(fs::exists(t.character));
    // The m0 path is where the input motion lives (it may not be found yet).
    EXPECT_EQ(fs::path(t.m0).filename(), std::string(name) + ".m0.json");
    EXPECT_EQ(t.constraints.weight, 5000.0);
    EXPECT_EQ(t.variations, 4);
  }
  EXPECT_EQ(load_task(kTasks + "backflip.toml").metric, "wja");
  EXPECT_EQ(load_task(kTasks + "jump_forward.toml").metric, "md");
  EXPECT_EQ(load_task(kTasks + "jump_onto.toml").metric, "wja");
  EXPECT_EQ(load_task(kTasks + "jump_over.toml").metric, "wja");
  EXPECT_EQ(load_task(kTasks + "jump_high.toml").metric, "md");
  const Task onto = load_task(kTasks + "jump_onto.toml");
  ASSERT_NE(onto.find_object("box"), nullptr);
  EXPECT_DOUBLE_EQ(onto.find_object("box")->height, 0.5);
  const Task over = load_task(kTasks + "jump_over.toml");
  EXPECT_DOUBLE_EQ(over.find_object("obstacle")->height, 0.55);
  EXPECT_NE(over.constraints.find<MinLengthConstraint>(), nullptr);
  EXPECT_NE(load_task(kTasks + "backflip.toml").constraints.find<RotationConstraint>(), nullptr);
  EXPECT_NE(load_task(kTasks + "jump_high.toml").constraints.find<PeakHeightConstraint>(), nullptr);
}

// The 3D tasks: a landing disc in the ground plane, the robot's pitch limit, falls by tilt,
// and the robot's seed continuation over the landing distance.
TEST_F(TaskFileTest, ThreeDimensionalTasksParse) {
  const Task back = load_task(kTasks + "jump_backwards.toml");
  EXPECT_EQ(back.controller_type->name(), std::string("skill"));
  EXPECT_EQ(back.controller_config->skill_name(), "jump3d");
  EXPECT_EQ(back.character_spec->name, "human3d");
  EXPECT_DOUBLE_EQ(back.constraints.find<LandingConstraint>()->center, -0.8);
  EXPECT_DOUBLE_EQ(back.constraints.find<LandingConstraint>()->lateral, 0.0);
  EXPECT_DOUBLE_EQ(back.constraints.find<LandingConstraint>()->radius, 0.25);
  EXPECT_DOUBLE_EQ(back.simulation.fall_tilt, 1.0);
  EXPECT_EQ(back.constraints.find<PitchConstraint>(), nullptr);
  const Task robot = load_task(kTasks + "robot_jump.toml");
  EXPECT_EQ(robot.character_spec->name, "robot3d");
  EXPECT_DOUBLE_EQ(robot.constraints.find<LandingConstraint>()->radius, 0.75);
  EXPECT_NE(robot.constraints.find<PitchConstraint>(), nullptr);
  EXPECT_DOUBLE_EQ(robot.constraints.find<PitchConstraint>()->max, 0.7);
  EXPECT_EQ(robot.seed.distances, (std::vector<double>{2.0, 2.8, 3.5, 4.0}));
}

TEST_F(TaskFileTest, LandingDiscAndPitchErrors) {
  const std::string disc = replace(valid_text(), "landing = { center = 1.0, half_width = 0.15 }",
                                   "landing = { center = 1.0, lateral = 0.2, radius = 0.3 }");
  const Task t = load_task(write(disc));
  EXPECT_DOUBLE_EQ(t.constraints.find<LandingConstraint>()->radius, 0.3);
  EXPECT_DOUBLE_EQ(t.constraints.find<LandingConstraint>()->lateral, 0.2);
  EXPECT_EQ(error_of(replace(valid_text(), "half_width = 0.15", "half_width = 0.15, radius = 0.2")),
            ": constraints.landing.radius: expected either half_width (a box along x) or radius (a disc), not both");
  EXPECT_EQ(error_of(replace(valid_text(), "half_width = 0.15", "half_width = 0.15, lateral = 0.2")),
            ": constraints.landing.lateral: expected lateral only with a radius (a disc)");
  EXPECT_EQ(error_of(replace(disc, "radius = 0.3", "radius = -1")),
            ": constraints.landing.radius: expected a number in [0.001, 10], got -1");
  EXPECT_EQ(error_of(valid_text() + "pitch = { max = 4 }\n"),
            ": constraints.pitch.max: expected a number in [0.01, 3.14], got 4");
  EXPECT_EQ(error_of(valid_text() + "[simulation]\nfall_tilt = -1\n"),
            ": simulation.fall_tilt: expected a number in [0, 3.14], got -1");
  EXPECT_EQ(error_of(valid_text() + "[seed]\nbase = \"" + kTasks + "base_jump.json\"\ndistances = [0.5, 0.9]\n"),
            ": seed.distances: expected the last distance to be the task's landing centre (1.000000)");
  EXPECT_EQ(error_of(valid_text() + "[seed]\nbase = \"" + kTasks + "base_jump.json\"\ndistances = \"far\"\n"),
            ": seed.distances: expected a non-empty array of numbers in [-20, 20]");
}

TEST_F(TaskFileTest, ValidTextParses) {
  const Task t = load_task(write(valid_text()));
  EXPECT_EQ(t.name, "t");
  EXPECT_NE(t.constraints.find<LandingConstraint>(), nullptr);
  EXPECT_DOUBLE_EQ(t.constraints.find<LandingConstraint>()->center, 1.0);
  EXPECT_DOUBLE_EQ(t.simulation.settle_time, 1.0);
  EXPECT_DOUBLE_EQ(t.diversity.sigma0, 0.1);  // the default without a [diversity] table
  EXPECT_EQ(t.diversity.generations, 500);
  EXPECT_EQ(load_task(write(valid_text() + "[diversity]\ngenerations = 200\n")).diversity.generations,
            200);
  // The default job's own budget (docs/notes/2026-12-04-where-a-runs-steps-go.md).
  EXPECT_EQ(load_task(kTasks + "jump_high.toml").diversity.generations, 200);
  EXPECT_DOUBLE_EQ(load_task(write(valid_text() + "[diversity]\nsigma0 = 0.03\n")).diversity.sigma0,
                   0.03);
}

TEST_F(TaskFileTest, MissingField) {
  EXPECT_EQ(error_of(replace(valid_text(), "metric = \"md\"\n", "")),
            ": metric: expected a string (missing)");
  EXPECT_EQ(error_of(replace(valid_text(), "weight = 5000.0\n", "")),
            ": constraints.weight: expected a number in [1e-06, 1e+09] (missing)");
}

TEST_F(TaskFileTest, UnknownKey) {
  const std::string e = error_of(replace(valid_text(), "[controller]\n", "[controller]\nspeed = 3\n"));
  EXPECT_EQ(e.rfind(": controller.speed: expected no such key (unknown key; known keys: type,", 0), 0u) << e;
  const std::string top = error_of(valid_text() + "[extra]\n");
  EXPECT_EQ(top.rfind(": extra: expected no such key", 0), 0u) << top;
}

TEST_F(TaskFileTest, WrongType) {
  EXPECT_EQ(error_of(replace(valid_text(), "variations = 4", "variations = \"four\"")),
            ": variations: expected an integer in [1, 100]");
  EXPECT_EQ(error_of(replace(valid_text(), "weight = 5000.0", "weight = \"big\"")),
            ": constraints.weight: expected a number in [1e-06, 1e+09]");
}

TEST_F(TaskFileTest, OutOfRange) {
  EXPECT_EQ(error_of(replace(valid_text(), "half_width = 0.15", "half_width = -1")),
            ": constraints.landing.half_width: expected a number in [0.001, 10], got -1");
  EXPECT_EQ(error_of(replace(valid_text(), "metric = \"md\"", "metric = \"xyz\"")),
            ": metric: expected \"hf\", \"md\" or \"wja\", got \"xyz\"");
  EXPECT_EQ(error_of(valid_text() + "[diversity]\nsigma0 = 2\n"),
            ": diversity.sigma0: expected a number in [0.0001, 1], got 2");
  EXPECT_EQ(error_of(valid_text() + "[diversity]\ngenerations = 0\n"),
            ": diversity.generations: expected an integer in [1, 1000000], got 0");
  const std::string unknown = error_of(valid_text() + "[diversity]\nlambda = 8\n");
  EXPECT_EQ(unknown.rfind(": diversity.lambda: expected no such key", 0), 0u) << unknown;
}

TEST_F(TaskFileTest, SaturatedDrive) {
  EXPECT_EQ(load_task(write(valid_text())).simulation.saturated_drive, SaturatedDrive::kExplicit);
  EXPECT_EQ(load_task(write(valid_text() + "[simulation]\nsaturated_drive = \"stable_pd\"\n"))
                .simulation.saturated_drive,
            SaturatedDrive::kStablePd);
  EXPECT_EQ(error_of(valid_text() + "[simulation]\nsaturated_drive = \"implicit\"\n"),
            ": simulation.saturated_drive: expected \"explicit\" or \"stable_pd\", got \"implicit\"");
  EXPECT_EQ(error_of(valid_text() + "[simulation]\nsaturated_drive = 1\n"),
            ": simulation.saturated_drive: expected a string");
}

TEST_F(TaskFileTest, Damping) {
  EXPECT_EQ(load_task(write(valid_text())).simulation.damping, Damping::kMujoco);
  EXPECT_EQ(load_task(write(valid_text() + "[simulation]\ndamping = \"constrained\"\n")).simulation.damping,
            Damping::kConstrained);
  EXPECT_EQ(load_task(write(valid_text() + "[simulation]\ndamping = \"mujoco\"\nsaturated_drive = \"stable_pd\"\n"))
                .simulation.saturated_drive,
            SaturatedDrive::kStablePd);
  EXPECT_EQ(error_of(valid_text() + "[simulation]\ndamping = \"implicit\"\n"),
            ": simulation.damping: expected \"mujoco\" or \"constrained\", got \"implicit\"");
  EXPECT_EQ(error_of(valid_text() + "[simulation]\ndamping = \"constrained\"\nsaturated_drive = \"stable_pd\"\n"),
            ": simulation.saturated_drive: has no effect with damping = \"constrained\" (every joint is "
            "driven that way); remove it");
}

TEST_F(TaskFileTest, FrictionCone) {
  EXPECT_EQ(load_task(write(valid_text())).simulation.friction_cone, "");
  EXPECT_EQ(load_task(write(valid_text() + "[simulation]\nfriction_cone = \"pyramidal\"\n")).simulation.friction_cone,
            "pyramidal");
  EXPECT_EQ(load_task(write(valid_text() + "[simulation]\nfriction_cone = \"elliptic\"\n")).simulation.friction_cone,
            "elliptic");
  EXPECT_EQ(error_of(valid_text() + "[simulation]\nfriction_cone = \"conical\"\n"),
            ": simulation.friction_cone: expected \"elliptic\" or \"pyramidal\", got \"conical\"");
  EXPECT_EQ(error_of(valid_text() + "[simulation]\nfriction_cone = 2\n"), ": simulation.friction_cone: expected a string");
}

TEST_F(TaskFileTest, ModelPathMissing) {
  const std::string e = error_of(replace(valid_text(), "human2d.xml", "nobody.xml"));
  EXPECT_EQ(e.rfind(": character: expected an existing file (relative to the task file), but ", 0), 0u) << e;
  EXPECT_NE(e.find("nobody.xml does not exist"), std::string::npos) << e;
}

TEST_F(TaskFileTest, MalformedToml) {
  const std::string e = error_of(valid_text() + "this is = = not toml\n");
  EXPECT_EQ(e.rfind(": line 12: expected valid TOML (", 0), 0u) << e;
}

TEST_F(TaskFileTest, ObjectReferences) {
  const std::string e = error_of(valid_text() + "on_box = { object = \"crate\", margin = 0.1 }\n");
  EXPECT_EQ(e, ": constraints.on_box.object: expected the name of an object of kind \"box\", got \"crate\"");
}

TEST_F(TaskFileTest, ResolveTaskPath) {
  EXPECT_TRUE(fs::exists(resolve_task_path("backflip")));
  try {
    resolve_task_path("no_such_task");
    FAIL();
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(), "no_such_task: expected a task file or the name of one in tasks/ (no such task)");
  }
}

TEST_F(TaskFileTest, SceneObjectsAndTimestepOverride) {
  Task t = load_task(kTasks + "jump_onto.toml");
  std::string xml = scene_xml(t);
  EXPECT_NE(xml.find("<geom name=\"box\" type=\"box\""), std::string::npos);
  t.simulation.timestep = 0.001;
  xml = scene_xml(t);
  EXPECT_NE(xml.find("timestep=\"0.001\""), std::string::npos);
  EXPECT_EQ(xml.find("timestep=\"0.002\""), std::string::npos);
}

// C = 5000 |d|^2 outside the allowed region (SPEC 2.4), a large constant for a fall.
TEST(Constraints, PenaltiesFollowSpec) {
  Task t = load_task(kTasks + "jump_forward.toml");
  MotionSummary m;
  m.took_off = m.landed = m.settled = true;
  m.fell = false;
  m.feet_x = m.touchdown_feet_x = 1.0;
  ConstraintReport r = evaluate_constraints(t, m);
  EXPECT_EQ(r.total, 0.0);
  m.feet_x = m.touchdown_feet_x = 1.0 + 0.15 + 0.1;  // 10 cm outside the box
  r = evaluate_constraints(t, m);
  EXPECT_NEAR(r.total, 5000 * 0.1 * 0.1, 1e-9);
  m.fell = true;
  m.fall_progress = 1;
  r = evaluate_constraints(t, m);
  EXPECT_NEAR(r.total, 100000 + 50, 1e-9);
  EXPECT_TRUE(r.fell);
  m.fall_progress = 0;  // falling at the very start costs twice the constant
  EXPECT_NEAR(evaluate_constraints(t, m).total, 200000 + 50, 1e-9);
  m.unstable = true;
  EXPECT_NEAR(evaluate_constraints(t, m).total, 300000, 1e-9);

  Task flip = load_task(kTasks + "backflip.toml");
  MotionSummary f;
  f.feet_x = f.touchdown_feet_x = flip.constraints.find<LandingConstraint>()->center;
  f.rotation_total = 2 * M_PI - 0.4;  // within the 0.5 rad tolerance
  EXPECT_EQ(evaluate_constraints(flip, f).total, 0.0);
  f.rotation_total = 2 * M_PI - 0.7;  // 0.2 rad beyond it
  EXPECT_NEAR(evaluate_constraints(flip, f).total, 100000 + 5000 * 0.04, 1e-6);
  // The task file asks for 300 degrees of the turn in the air: a landed flip that turned
  // 0.1 rad less between take-off and touch-down pays 5000 (0.1)^2.
  f.rotation_total = 2 * M_PI;
  f.landed = true;
  f.rotation_flight = flip.constraints.find<RotationConstraint>()->min_flight;
  EXPECT_EQ(evaluate_constraints(flip, f).total, 0.0);
  f.rotation_flight = flip.constraints.find<RotationConstraint>()->min_flight - 0.1;
  EXPECT_NEAR(evaluate_constraints(flip, f).total, 5000 * 0.01, 1e-6);
  f.landed = false;
  EXPECT_GT(constraint_margin(flip, MotionSummary{}), -2);  // defined everywhere
}

// Where the feet come down counts as much as where they come to rest: touching down
// short of the box and hopping or sliding into it violates the landing constraint.
TEST(Constraints, LandingIsMeasuredAtTouchdownAndAtRest) {
  Task t = load_task(kTasks + "jump_forward.toml");
  MotionSummary m;
  m.took_off = m.landed = m.settled = true;
  m.touchdown_feet_x = 0.6;  // 25 cm short of the box at touch-down
  m.feet_x = 1.0;            // in its centre at rest
  ConstraintReport r = evaluate_constraints(t, m);
  EXPECT_NEAR(r.total, 5000 * 0.25 * 0.25, 1e-9);
  EXPECT_NEAR(constraint_margin(t, m), -0.25, 1e-12);
  m.touchdown_feet_x = 1.0;  // came down in the centre, slid 20 cm past the box
  m.feet_x = 1.35;
  EXPECT_NEAR(evaluate_constraints(t, m).total, 5000 * 0.2 * 0.2, 1e-9);

  // Jump onto: touching down on the box's face (below its top) is not standing on it.
  Task onto = load_task(kTasks + "jump_onto.toml");
  const SceneObject* box = onto.find_object("box");
  MotionSummary b;
  b.took_off = b.landed = b.settled = true;
  b.feet_x = b.touchdown_feet_x = 0.5 * (box->x_min + box->x_max);
  b.feet_z = box->height + 0.05;
  b.touchdown_feet_z = box->height - 0.1;
  EXPECT_NEAR(evaluate_constraints(onto, b).total, 5000 * 0.1 * 0.1, 1e-9);
  b.touchdown_feet_z = b.feet_z;
  EXPECT_EQ(evaluate_constraints(onto, b).total, 0.0);

  // Jump over: the length counts where the feet came down.
  Task over = load_task(kTasks + "jump_over.toml");
  MotionSummary o;
  o.took_off = o.landed = o.settled = true;
  o.min_clearance = 0.5;
  o.touchdown_feet_x = 0.9;
  o.feet_x = 1.2;
  EXPECT_NEAR(evaluate_constraints(over, o).total, 5000 * 0.1 * 0.1, 1e-9);
}

// A flip turns in the air: the root's rotation between take-off and the first touch-down
// (in the direction of the turns) short of min_flight by d costs K_c d^2, and counts in
// the margin at 0.2 m per rad. A motion that never landed has no flight to measure (its
// fall is the penalty).
TEST_F(TaskFileTest, MinimumRotationInTheAir) {
  const std::string flip = valid_text() + "rotation = { turns = 1.0, tolerance = 0.5, penalty = 100000.0, min_flight = 5.0 }\n";
  const Task t = load_task(write(flip));
  EXPECT_DOUBLE_EQ(t.constraints.find<RotationConstraint>()->min_flight, 5.0);
  MotionSummary m;
  m.took_off = m.landed = m.settled = true;
  m.feet_x = m.touchdown_feet_x = 1.0;
  m.rotation_total = 2 * M_PI;
  m.rotation_flight = 5.1;
  EXPECT_EQ(evaluate_constraints(t, m).total, 0.0);
  EXPECT_NEAR(constraint_margin(t, m), 0.2 * 0.1, 1e-12);
  m.rotation_flight = 4.7;  // 0.3 rad short, the whole turn still within its tolerance
  ConstraintReport r = evaluate_constraints(t, m);
  EXPECT_NEAR(r.total, 5000 * 0.3 * 0.3, 1e-9);
  EXPECT_EQ(r.terms.back().name, "flight_rotation");
  EXPECT_NEAR(r.terms.back().violation, 0.3, 1e-12);
  m.landed = false;
  r = evaluate_constraints(t, m);
  EXPECT_EQ(r.terms.back().penalty, 0.0);

  // A front flip (negative turns) turns the other way in the air.
  const Task front = load_task(write(replace(flip, "turns = 1.0", "turns = -1.0")));
  m.landed = true;
  m.rotation_total = -2 * M_PI;
  m.rotation_flight = -5.2;
  EXPECT_EQ(evaluate_constraints(front, m).total, 0.0);
  m.rotation_flight = 5.2;  // the wrong way round
  EXPECT_NEAR(evaluate_constraints(front, m).terms.back().penalty, 5000 * 10.2 * 10.2, 1e-6);

  // No more than the whole turn allows.
  EXPECT_EQ(error_of(replace(flip, "min_flight = 5.0", "min_flight = 7.0")),
            ": constraints.rotation.min_flight: expected a rotation in the air (rad) no larger than the "
            "whole turn allows, 2 pi |turns| + tolerance = 6.78319, got 7");
  EXPECT_EQ(error_of(replace(flip, "min_flight = 5.0", "min_flight = -1")),
            ": constraints.rotation.min_flight: expected a number in [0, 20], got -1");
}

// The peak height of a jump is measured from the floor (min) or from the centre of mass
// standing in the start pose (above_standing): then a body that stands taller has to rise
// as far as any other, rather than meeting the height by standing taller.
TEST_F(TaskFileTest, PeakHeightAboveTheStandingCom) {
  const Task absolute = load_task(write(valid_text() + "peak_height = { min = 1.2 }\n"));
  const Task relative = load_task(write(valid_text() + "peak_height = { above_standing = 0.3 }\n"));
  EXPECT_FALSE(absolute.constraints.find<PeakHeightConstraint>()->relative);
  EXPECT_TRUE(relative.constraints.find<PeakHeightConstraint>()->relative);
  MotionSummary m;
  m.took_off = m.landed = m.settled = true;
  m.feet_x = m.touchdown_feet_x = 1.0;
  m.standing_com_z = 0.95;
  m.peak_com_z = 1.21;
  EXPECT_EQ(evaluate_constraints(absolute, m).total, 0.0);
  EXPECT_NEAR(evaluate_constraints(relative, m).total, 5000 * 0.04 * 0.04, 1e-9);  // rose 0.26 m
  EXPECT_NEAR(constraint_margin(relative, m), -0.04, 1e-12);
  m.standing_com_z = 0.85;  // a shorter body: the same peak is a higher jump
  EXPECT_EQ(evaluate_constraints(relative, m).total, 0.0);
  EXPECT_NEAR(constraint_margin(relative, m), 0.06, 1e-12);
  EXPECT_EQ(error_of(valid_text() + "peak_height = { min = 1.2, above_standing = 0.3 }\n"),
            ": constraints.peak_height.min: expected either min (m above the floor) or above_standing (m above "
            "the standing COM), not both");
  EXPECT_EQ(error_of(valid_text() + "half_timestep = 1\n"),
            ": constraints.half_timestep: expected true or false");
  EXPECT_TRUE(load_task(write(valid_text() + "half_timestep = true\n")).constraints.half_timestep);
  EXPECT_FALSE(load_task(write(valid_text())).constraints.half_timestep);
}

// The half-timestep term: the fine rollout's C, plus K_c d^2 for landing spots more than
// kTimestepAgreement + d apart; its violation is 1 when the fine rollout misses the task.
TEST(Constraints, HalfTimestepTerm) {
  const Task t = load_task(kTasks + "jump_forward.toml");
  MotionSummary coarse, fine;
  coarse.took_off = coarse.landed = coarse.settled = true;
  coarse.feet_x = coarse.touchdown_feet_x = 1.0;
  fine = coarse;
  fine.touchdown_feet_x = 1.02;  // within 3 cm
  ConstraintTerm term = half_timestep_term(t, coarse, fine, 0.0);
  EXPECT_EQ(term.name, "half_timestep");
  EXPECT_EQ(term.penalty, 0.0);
  fine.feet_x = 1.08;  // 8 cm apart at rest: 5 cm too far
  term = half_timestep_term(t, coarse, fine, 0.0);
  EXPECT_NEAR(term.violation, 0.05, 1e-12);
  EXPECT_NEAR(term.penalty, 5000 * 0.05 * 0.05, 1e-9);
  fine.fell = true;  // a fall has no landing to compare; its C is the penalty
  term = half_timestep_term(t, coarse, fine, 100000.0);
  EXPECT_EQ(term.violation, 1.0);
  EXPECT_EQ(term.penalty, 100000.0);
}

// 3D landings are measured in the ground plane: within the disc's radius of its centre, at
// touch-down and at rest; the robot's forward pitch beyond its limit costs K_c d^2.
TEST(Constraints, LandingDiscAndPitchLimit) {
  Task t = load_task(kTasks + "robot_jump.toml");
  MotionSummary m;
  m.took_off = m.landed = m.settled = true;
  m.feet_x = m.touchdown_feet_x = 4.3;
  m.feet_y = m.touchdown_feet_y = 0.4;  // 0.5 m from the centre: inside the 0.75 m disc
  EXPECT_EQ(evaluate_constraints(t, m).total, 0.0);
  // The margin is the smallest slack: 0.25 m inside the disc, and 0.7 rad of pitch
  // counting 0.2 m per rad.
  EXPECT_NEAR(constraint_margin(t, m), 0.14, 1e-12);
  m.max_forward_pitch = 0.5;
  EXPECT_NEAR(constraint_margin(t, m), 0.04, 1e-12);
  m.max_forward_pitch = 0;
  m.touchdown_feet_y = 0.8;  // sideways at touch-down: sqrt(0.09 + 0.64) = 0.854 m
  EXPECT_NEAR(evaluate_constraints(t, m).total, 5000 * std::pow(std::hypot(0.3, 0.8) - 0.75, 2), 1e-9);
  m.touchdown_feet_y = 0.4;
  m.max_forward_pitch = 0.9;  // 0.2 rad past the limit
  const ConstraintReport r = evaluate_constraints(t, m);
  EXPECT_NEAR(r.total, 5000 * 0.2 * 0.2, 1e-9);
  EXPECT_EQ(r.terms.back().name, "pitch");
}

}  // namespace
}  // namespace diverse
