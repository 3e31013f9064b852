// Character files: the planar human loads from its file with what the paper says, and every
// way a character file or its MJCF can be wrong is a one-line error naming the file, the
// field and what was expected (and, from the command line, exit code 2).
#include "character/character.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "support/text_files.h"
#include "physics/model.h"
#include "support/cli.h"

namespace diverse {
namespace {

namespace fs = std::filesystem;
const std::string kCharacters = std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/";

using test_files::read_text;
using test_files::write_text;

// Replaces the first occurrence of `from` (which must occur) with `to`.
std::string edit(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// A copy of the planar human in a fresh directory, with edits to its character file and
// model; loads, compiles and binds it and returns the error message ("" if none).
class Edited {
 public:
  explicit Edited(const std::string& name) : dir_(fs::path(testing::TempDir()) / ("character_" + name)) {
    fs::create_directories(dir_);
    toml_ = read_text(kCharacters + "human2d.toml");
    xml_ = read_text(kCharacters + "human2d.xml");
  }
  Edited& toml(const std::string& from, const std::string& to) {
    toml_ = edit(toml_, from, to);
    return *this;
  }
  Edited& xml(const std::string& from, const std::string& to) {
    xml_ = edit(xml_, from, to);
    return *this;
  }
  std::string file() const { return (dir_ / "human2d.toml").string(); }
  std::string error() const {
    write_text(file(), toml_);
    write_text((dir_ / "human2d.xml").string(), xml_);
    try {
      auto spec = std::make_shared<const CharacterSpec>(load_character_file(file()));
      auto model = SharedModel::from_file(spec->model);
      bind_character(spec, model->get(), spec->model);
    } catch (const UserError& e) {
      return e.what();
    }
    return "";
  }

 private:
  fs::path dir_;
  std::string toml_, xml_;
};

TEST(Character, PlanarHumanLoadsFromItsFile) {
  auto spec = std::make_shared<const CharacterSpec>(load_character_file(kCharacters + "human2d.toml"));
  EXPECT_EQ(spec->name, "human2d");
  EXPECT_EQ(spec->root, RootKind::kPlanar);
  EXPECT_TRUE(spec->has_shape());
  EXPECT_EQ(spec->shape.size(), 10u);  // the paper's 10 shape parameters
  auto model = SharedModel::from_file(spec->model);
  const mjModel* m = model->get();
  const Character c = bind_character(spec, m, spec->model);
  EXPECT_EQ(c.links.size(), 17u);
  EXPECT_EQ(c.dof(), 16);
  EXPECT_EQ(c.groups.size(), 10u);
  EXPECT_NEAR(c.total_mass, 80.0, 1e-9);
  EXPECT_NEAR(c.height, 1.60, 1e-9);
  EXPECT_EQ(c.feet[0], mj_name2id(m, mjOBJ_BODY, "foot_l"));
  EXPECT_EQ(c.feet[1], mj_name2id(m, mjOBJ_BODY, "foot_r"));
  ASSERT_EQ(c.hands.size(), 2u);
  // Left and right of a pair: same group, left first.
  const JointGroup& hip = c.groups[static_cast<size_t>(c.find_group(JointRole::kHip))];
  ASSERT_EQ(hip.joints.size(), 2u);
  EXPECT_EQ(c.joints[static_cast<size_t>(hip.joints[0])].name, "hip_l");
  EXPECT_EQ(c.joints[static_cast<size_t>(hip.joints[0])].side, Side::kLeft);
  EXPECT_EQ(c.joints[static_cast<size_t>(hip.joints[1])].side, Side::kRight);
  // Torque limits come from the motors' force ranges.
  EXPECT_EQ(c.joints[static_cast<size_t>(hip.joints[0])].torque_limit, 300);
  // A link's world pitch is the root pitch plus the hinges along its chain.
  std::vector<double> q(static_cast<size_t>(m->nq), 0.0);
  q[static_cast<size_t>(c.root_pitch_qpos)] = 0.1;
  int ankle = -1, knee = -1;
  for (size_t i = 0; i < c.joints.size(); ++i) {
    if (c.joints[i].name == "ankle_l") ankle = static_cast<int>(i);
    if (c.joints[i].name == "knee_l") knee = static_cast<int>(i);
  }
  q[static_cast<size_t>(c.joints[static_cast<size_t>(knee)].qpos)] = -0.5;
  q[static_cast<size_t>(c.joints[static_cast<size_t>(ankle)].qpos)] = 0.2;
  EXPECT_NEAR(c.child_pitch(q.data(), ankle), 0.1 - 0.5 + 0.2, 1e-15);
  // Foot contact includes every geom of the foot bodies, nothing else.
  int foot = -1;
  EXPECT_TRUE(c.is_foot_geom(m, mj_name2id(m, mjOBJ_GEOM, "foot_r"), &foot));
  EXPECT_EQ(foot, 1);
  EXPECT_FALSE(c.is_foot_geom(m, mj_name2id(m, mjOBJ_GEOM, "hand_r")));
}

TEST(Character, AModelFileResolvesToTheCharacterFileBesideIt) {
  EXPECT_EQ(resolve_character_file(kCharacters + "human2d.xml"),
            fs::path(kCharacters + "human2d.toml").lexically_normal().string());
  const fs::path dir = fs::path(testing::TempDir()) / "character_lonely";
  fs::create_directories(dir);
  write_text((dir / "lonely.xml").string(), "<mujoco/>");
  try {
    resolve_character_file((dir / "lonely.xml").string());
    FAIL();
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()), (dir / "lonely.xml").string() + ": expected a character file beside the model (" +
                                         (dir / "lonely.toml").string() + "); docs/reference/character-file.md says how to write one");
  }
}

TEST(CharacterErrors, NamesAJointTheModelLacks) {
  Edited c("no_joint");
  c.toml("joints = [\"knee_l\", \"knee_r\"]", "joints = [\"knee_left\", \"knee_r\"]");
  EXPECT_EQ(c.error(), c.file() + ": groups[1].joints: expected a joint of the model " +
                           fs::path(c.file()).replace_extension(".xml").string() +
                           ", but it has no joint 'knee_left'");
}

TEST(CharacterErrors, NamesABodyTheModelLacks) {
  Edited c("no_body");
  c.toml("bodies = [\"foot_l\", \"foot_r\"]", "bodies = [\"foot_l\", \"paw_r\"]");
  EXPECT_EQ(c.error(), c.file() + ": feet.bodies: expected a body of the model " +
                           fs::path(c.file()).replace_extension(".xml").string() +
                           ", but it has no body 'paw_r'");
}

TEST(CharacterErrors, ActuatorOnARootJoint) {
  Edited c("root_actuator");
  c.xml("<motor name=\"tau_hip_l\"", "<motor name=\"push\" joint=\"rootx\" forcelimited=\"true\" forcerange=\"-9 9\"/>\n    <motor name=\"tau_hip_l\"");
  const std::string model = fs::path(c.file()).replace_extension(".xml").string();
  EXPECT_EQ(c.error(), model + ": actuator 'push': expected no actuator on the root joint 'rootx' (the root is "
                               "unactuated: all motion comes from joint torques)");
}

TEST(CharacterErrors, GearOtherThanOne) {
  Edited c("gear");
  c.xml("<motor name=\"tau_knee_l\" joint=\"knee_l\"", "<motor name=\"tau_knee_l\" joint=\"knee_l\" gear=\"50\"");
  const std::string model = fs::path(c.file()).replace_extension(".xml").string();
  EXPECT_EQ(c.error(), model + ": actuator 'tau_knee_l': expected gear=\"1\" (ctrl is the joint torque in Nm), got 50");
}

TEST(CharacterErrors, ActuatedJointWithoutTorqueLimit) {
  Edited c("no_limit");
  c.xml("joint=\"elbow_r\" forcelimited=\"true\"", "joint=\"elbow_r\" forcelimited=\"false\"");
  const std::string model = fs::path(c.file()).replace_extension(".xml").string();
  EXPECT_EQ(c.error(), model + ": actuator 'tau_elbow_r': expected a torque limit: forcelimited=\"true\" "
                               "forcerange=\"-L L\" with L > 0");
}

TEST(CharacterErrors, JointWithoutAnyActuator) {
  Edited c("no_motor");
  c.xml("    <motor name=\"tau_wrist_r\" joint=\"wrist_r\" forcelimited=\"true\" forcerange=\"-50 50\"/>\n", "");
  const std::string model = fs::path(c.file()).replace_extension(".xml").string();
  EXPECT_EQ(c.error(), model + ": joint 'wrist_r': expected a <motor> with forcelimited=\"true\" forcerange=\"-L L\" "
                               "driving it (its torque limit)");
}

TEST(CharacterErrors, LeftRightPairWithDifferentRanges) {
  Edited c("pair_range");
  c.xml("<joint name=\"knee_r\" range=\"-2.6 0\"", "<joint name=\"knee_r\" range=\"-2.4 0\"");
  EXPECT_EQ(c.error(), c.file() + ": groups[1].joints: expected the left/right pair 'knee_l', 'knee_r' to have the "
                                  "same range, got [-2.6, 0] and [-2.4, 0]");
}

TEST(CharacterErrors, LeftRightPairOfDifferentJointTypes) {
  Edited c("pair_type");
  c.xml("<joint name=\"ankle_r\" range=\"-0.9 0.7\"/>",
        "<joint name=\"ankle_r\" type=\"slide\" axis=\"0 0 1\" range=\"-0.9 0.7\"/>");
  EXPECT_EQ(c.error(), c.file() + ": groups[2].joints: expected 'ankle_r' to be a hinge joint");
}

TEST(CharacterErrors, LinkOfZeroMass) {
  Edited c("massless");
  c.xml("mass=\"0.48\"/>", "mass=\"1e-9\"/>");
  const std::string model = fs::path(c.file()).replace_extension(".xml").string();
  EXPECT_EQ(c.error(), model + ": body 'hand_l': expected a link with mass > 0 (it has 1e-09 kg)");
}

TEST(CharacterErrors, AModelMuJoCoRefuses) {
  Edited c("refused");
  c.xml("<geom name=\"shin_l\" fromto=", "<geom name=\"shin_l\" type=\"blob\" fromto=");
  const std::string message = c.error();
  const std::string model = fs::path(c.file()).replace_extension(".xml").string();
  EXPECT_EQ(message.rfind(model + ": ", 0), 0u) << message;
  EXPECT_NE(message.find("blob"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(CharacterErrors, JointInNoGroup) {
  Edited c("ungrouped");
  c.toml("joints = [\"head\"]", "joints = [\"neck_extra_that_is_not_there\"]");
  EXPECT_NE(c.error().find("it has no joint 'neck_extra_that_is_not_there'"), std::string::npos);
  Edited d("ungrouped2");
  d.toml("[[groups]]\nname = \"head\"\nrole = \"neck\"\nplane = \"sagittal\"\njoints = [\"head\"]\nwja = 0.0\nkp = 30.0\nkd = 3.0\n", "");
  EXPECT_EQ(d.error(), d.file() + ": groups: expected every joint of the model in a group, but 'head' is in none");
}

TEST(CharacterErrors, PlanarHingeNotAboutMinusY) {
  Edited c("axis");
  c.xml("<joint name=\"elbow_l\" range=\"0 2.6\"", "<joint name=\"elbow_l\" axis=\"1 0 0\" range=\"0 2.6\"");
  EXPECT_EQ(c.error(), c.file() + ": groups[6].joints: expected 'elbow_l' to turn about -y (axis 0 -1 0), as every "
                                  "hinge of a planar character does");
}

TEST(CharacterErrors, FileErrors) {
  Edited unknown("unknown_key");
  unknown.toml("name = \"human2d\"", "name = \"human2d\"\ncolour = \"red\"");
  EXPECT_EQ(unknown.error().rfind(unknown.file() + ": colour: expected no such key (unknown key; known keys: ", 0), 0u)
      << unknown.error();
  Edited role("role");
  role.toml("role = \"elbow\"", "role = \"funny_bone\"");
  EXPECT_EQ(role.error(), role.file() + ": groups[6].role: expected one of hip, knee, ankle, toe, shoulder, elbow, "
                                        "wrist, waist, neck, tail, other, got \"funny_bone\"");
  Edited wja("wja");
  wja.toml("wja = 1.0\nkp = 40.0", "wja = -1\nkp = 40.0");
  EXPECT_EQ(wja.error(), wja.file() + ": groups[6].wja: expected a number in [0, 100], got -1");
  Edited twice("twice");
  twice.toml("joints = [\"wrist_l\", \"wrist_r\"]", "joints = [\"wrist_l\", \"elbow_r\"]");
  EXPECT_EQ(twice.error(), twice.file() + ": groups[7].joints: expected each joint in one group only, got \"elbow_r\" again");
  Edited malformed("malformed");
  malformed.toml("[feet]", "[feet");
  EXPECT_NE(malformed.error().find(": expected valid TOML ("), std::string::npos) << malformed.error();
  Edited model("model");
  model.toml("model = \"human2d.xml\"", "model = \"nobody.xml\"");
  EXPECT_EQ(model.error().rfind(model.file() + ": model: expected an existing MJCF file", 0), 0u) << model.error();
  EXPECT_THROW(load_character_file("/nonexistent/character.toml"), UserError);
}

TEST(CharacterErrors, TheCommandLineSaysSoAndExitsWithTwo) {
  Edited c("cli");
  c.xml("<motor name=\"tau_knee_l\" joint=\"knee_l\"", "<motor name=\"tau_knee_l\" joint=\"knee_l\" gear=\"2\"");
  const std::string expected = c.error();
  ASSERT_FALSE(expected.empty());
  const fs::path task = fs::path(c.file()).parent_path() / "task.toml";
  std::string text = read_text(std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_high.toml");
  text = edit(text, "character = \"../assets/characters/human2d.toml\"", "character = \"human2d.toml\"");
  text = edit(text, "skill = \"../skills/", "skill = \"" + std::string(DIVERSE_SOURCE_DIR) + "/skills/");
  text = edit(text, "m0 = \"jump_high.m0.json\"", "m0 = \"" + std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_high.m0.json\"");
  text = edit(text, "base = \"jump_high_start.json\"", "base = \"" + std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_high_start.json\"");
  write_text(task.string(), text);
  const cli_test::CliResult r = cli_test::run_cli("simulate " + task.string() + " --out " +
                                                  (fs::path(c.file()).parent_path() / "out").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(expected), std::string::npos) << r.output;
}

TEST(CharacterCli, DescribesAValidCharacterAndRefusesABrokenOne) {
  const cli_test::CliResult human = cli_test::run_cli("character " + kCharacters + "human3d.toml");
  ASSERT_EQ(human.status, 0) << human.output;
  EXPECT_NE(human.output.find("root free in 'pelvis' (unactuated)"), std::string::npos) << human.output;
  EXPECT_NE(human.output.find("15 links, 80.000 kg, 1.800 m tall standing, 24 internal DOF"), std::string::npos)
      << human.output;
  EXPECT_NE(human.output.find("no shape parameters (control-only diversity)"), std::string::npos);
  const cli_test::CliResult planar = cli_test::run_cli("character " + kCharacters + "human2d.xml");
  ASSERT_EQ(planar.status, 0) << planar.output;
  EXPECT_NE(planar.output.find("17 links, 80.000 kg, 1.600 m tall standing, 16 internal DOF in 10 groups"),
            std::string::npos)
      << planar.output;
  EXPECT_NE(planar.output.find("shape.thigh"), std::string::npos);
  Edited c("cli_character");
  c.xml("<motor name=\"tau_knee_l\" joint=\"knee_l\"", "<motor name=\"tau_knee_l\" joint=\"knee_l\" gear=\"3\"");
  const std::string expected = c.error();
  const cli_test::CliResult broken = cli_test::run_cli("character " + c.file());
  EXPECT_EQ(broken.status, 2);
  EXPECT_EQ(broken.output, "diverse: error: " + expected + "\n");
}

}  // namespace
}  // namespace diverse
