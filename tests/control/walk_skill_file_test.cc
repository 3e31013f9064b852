// The SIMBICON walk's skill file (skills/walk3d.toml) read and bound to the 3D human: its
// parameters by name, range and order as the "walk3d" controller named them, and the bad
// files of what the walk added to skill files (swing legs, targets by role, heading-frame
// targets, a foot's contact, a module's word setting) refused with one line naming the
// file, the line, the field and what was expected.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "control/skill_file.h"
#include "core/error.h"
#include "support/text_files.h"
#include "task/evaluate.h"
#include "tiny_biped.h"

namespace diverse {
namespace {

const std::string kRoot = DIVERSE_SOURCE_DIR;

// skills/`skill`.toml with `from` replaced by `to`, written as `name`.toml.
std::string variant(const std::string& skill, const std::string& name, const std::string& from, const std::string& to) {
  std::string text = test_files::read_text(kRoot + "/skills/" + skill + ".toml");
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error(skill + ".toml has no " + from);
  text.replace(at, from.size(), to);
  return tiny_biped::write_skill(name, text);
}

int line_of(const std::string& file, const std::string& text) {
  const std::string all = test_files::read_text(file);
  const auto at = all.find(text);
  if (at == std::string::npos) return -1;
  return 1 + static_cast<int>(std::count(all.begin(), all.begin() + static_cast<long>(at), '\n'));
}

std::string message(const std::string& file, const TaskEvaluator* character) {
  try {
    const SkillFile s = load_skill_file(file);
    if (character != nullptr) bind_skill(s, character->body(), character->model().get());
  } catch (const UserError& e) {
    return e.what();
  }
  return "no error";
}

TEST(WalkSkillFile, BindsToTheHumanWithTheWalksParameters) {
  const TaskEvaluator human(load_task(kRoot + "/tasks/silly_walk.toml"));
  const SkillFile s = load_skill_file(kRoot + "/skills/walk3d.toml");
  EXPECT_TRUE(s.walk);
  EXPECT_TRUE(s.start_pose);
  ASSERT_EQ(s.phases.size(), 4u);
  EXPECT_EQ(s.phases[0].swing, 0);
  EXPECT_EQ(s.phases[2].swing, 1);
  EXPECT_EQ(s.phases[2].parameters, "lift");
  const SkillBinding b = bind_skill(s, human.body(), human.model().get());
  // 2 x 22 targets, lift.duration and the four feedback gains.
  ASSERT_EQ(b.params.size(), 49u);
  EXPECT_EQ(b.params[0].name, "lift.pelvis.pitch");
  EXPECT_EQ(b.params[2].name, "lift.swing.hip");
  EXPECT_EQ(b.params[4].name, "lift.swing.knee");
  EXPECT_EQ(b.params[5].name, "lift.stance.knee");
  EXPECT_EQ(b.params[22].name, "strike.pelvis.pitch");
  EXPECT_EQ(b.params[44].name, "lift.duration");
  EXPECT_EQ(b.params[45].name, "sagittal.cd");
  EXPECT_EQ(b.params[48].name, "coronal.cv");
  // A heading-frame range within what the joint allows from standing: the hip's
  // [-0.5, 0.8] (limits -0.5 .. 1.2 rad at standing 0) is cut by the file's 1.2 only above.
  EXPECT_EQ(b.params[2].upper, 1.2);
  // The right leg's phases: the same parameters, the sides swapped, the rolls of the
  // pelvis and the torso mirrored.
  const int hip = human.body().find_group("hip");
  const auto& joints = human.body().groups[static_cast<size_t>(hip)].joints;
  EXPECT_EQ(b.phases[0].targets[static_cast<size_t>(joints[0])].param, 2);
  EXPECT_EQ(b.phases[2].targets[static_cast<size_t>(joints[1])].param, 2);
  EXPECT_EQ(b.phases[0].targets[static_cast<size_t>(joints[1])].world, SkillTarget::World::kHeading);
  EXPECT_EQ(b.phases[0].targets[static_cast<size_t>(joints[1])].param, -1);  // the stance hip
  EXPECT_EQ(b.phases[0].root_roll.sign, 1.0);
  EXPECT_EQ(b.phases[2].root_roll.sign, -1.0);
  EXPECT_EQ(b.phases[2].root_pitch.sign, 1.0);
  EXPECT_FALSE(b.phases[0].swing_lands);
  EXPECT_TRUE(b.phases[1].swing_lands);
}

TEST(WalkSkillFile, BadFilesNameTheFileLineFieldAndExpectation) {
  const TaskEvaluator human(load_task(kRoot + "/tasks/silly_walk.toml"));
  const TaskEvaluator planar(load_task(kRoot + "/tasks/jump_onto.toml"));
  struct Bad {
    std::string skill, name, from, to, marker, expected;
    const TaskEvaluator* character;
  };
  const std::string human_file = human.body().spec->file, planar_file = planar.body().spec->file;
  const std::vector<Bad> cases = {
      {"walk3d", "bad_swing", "swing = \"left\"", "swing = \"both\"", "swing = \"both\"",
       "phases[0].swing: expected \"left\" or \"right\", got \"both\"", nullptr},
      {"walk3d", "planar_swing", "root = \"free\"\npairs = [\"hip\", \"knee\", \"ankle\"]\n# The rollout starts static in the first phase's pose, the stance sole on the floor.\nstart = \"first_phase\"",
       "root = \"planar\"\npairs = [\"hip\", \"knee\", \"ankle\"]", "swing = \"left\"",
       "phases[0].swing: expected no swing leg: a phase with a swing leg needs root = \"free\"", nullptr},
      {"jump2d", "planar_start", "pairs = ", "start = \"first_phase\"\npairs = ", "start =",
       "start: expected \"standing\": a start in the first phase's pose needs root = \"free\"", nullptr},
      {"walk3d", "bad_start", "start = \"first_phase\"", "start = \"lying\"", "start =",
       "start: expected \"standing\" or \"first_phase\", got \"lying\"", nullptr},
      {"walk3d", "bad_kind", "kind = \"walk\"", "kind = \"swim\"", "kind = \"swim\"",
       "kind: expected \"jump\" or \"walk\", got \"swim\"", nullptr},
      {"walk3d", "no_swing", "parameters = \"strike\"\nswing = \"left\"\n", "parameters = \"strike\"\n", "hip = { swing",
       "targets.walk.hip: expected a phase with a swing leg (swing = \"left\" or \"right\") for swing and stance targets, but phase "
       "\"left_strike\" has none",
       &human},
      {"walk3d", "lr_and_roles", "knee = { swing", "knee = { left = 0.0, swing", "knee = {",
       "targets.walk.knee.swing: expected either left and right or swing and stance, not both", nullptr},
      {"walk3d", "half_role", "knee = { swing = { param = \"swing.{group}\" }, stance = { param = \"stance.{group}\" } }",
       "knee = { swing = { param = \"swing.{group}\" } }", "knee = {",
       "targets.walk.knee.stance: expected both swing and stance (missing)", nullptr},
      {"walk3d", "bad_world", "world = \"heading\", range = [-0.6, 0.6] }", "world = \"sky\", range = [-0.6, 0.6] }",
       "world = \"sky\"", "targets.walk.waist.world: expected \"joint\", \"parent\", \"child\", \"heading\", \"root\", \"torso\" or \"sole\", got \"sky\"", nullptr},
      {"walk3d", "root_without_roll", ", roll = { param = \"pelvis.roll\", range = [-0.4, 0.4], mirror = true } }", " }",
       "root = {", "targets.walk.root.roll: expected a number, \"standing\", { param = \"NAME\", range = [LOWER, UPPER] } or { curve = [[s, value], ...] } (missing)",
       nullptr},
      {"walk3d", "bad_foot", "foot = \"swing\" }, { to = \"right_lift\"", "foot = \"hand\" }, { to = \"right_lift\"",
       "foot = \"hand\"", "phases[1].next[0].foot: expected \"swing\", \"stance\", \"left\" or \"right\", got \"hand\"", nullptr},
      {"walk3d", "foot_and_body", "foot = \"swing\" }, { to = \"right_lift\"", "foot = \"swing\", body = \"torso\" }, { to = \"right_lift\"",
       "body = \"torso\"", "phases[1].next[0].body: expected exactly one of body = \"NAME\" or foot = \"swing\", \"stance\", \"left\" or \"right\"",
       nullptr},
      {"walk3d", "bad_plane", "plane = \"coronal\"", "plane = \"transverse\"", "plane = \"transverse\"",
       "modules[1].plane: expected one of \"sagittal\", \"coronal\", got \"transverse\"", nullptr},
      {"walk3d", "no_plane", "plane = \"coronal\"\n", "", "[[modules]]\nname = \"coronal\"",
       "modules[1].plane: expected a setting of the \"simbicon\" module (missing)", nullptr},
      {"walk3d", "on_the_planar_human", "root = \"free\"", "root = \"free\"", "root = \"free\"",
       "root: expected a character with a free root, but the character " + planar_file + " has a planar root", &planar},
  };
  for (const Bad& c : cases) {
    const std::string file = variant(c.skill, c.name, c.from, c.to);
    const int line = c.marker.empty() ? 1 : line_of(file, c.marker);
    EXPECT_EQ(message(file, c.character), file + ": line " + std::to_string(line) + ": " + c.expected) << c.name;
  }
  // The committed walks load and bind.
  EXPECT_EQ(message(kRoot + "/skills/walk3d.toml", &human), "no error");
}

}  // namespace
}  // namespace diverse
