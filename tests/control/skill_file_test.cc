// Skill files (control/skill_file.h): skills/jump2d.toml read and bound to the planar
// human, and every kind of bad file refused with one line naming the file, the line, the
// field and what was expected.
#include "control/skill_file.h"

#include <gtest/gtest.h>

#include <string>

#include "control/skill_controller.h"
#include "core/error.h"
#include "support/text_files.h"
#include "task/evaluate.h"
#include "tiny_biped.h"

namespace diverse {
namespace {

const std::string kRoot = DIVERSE_SOURCE_DIR;

std::string jump2d() { return test_files::read_text(kRoot + "/skills/jump2d.toml"); }

// jump2d.toml with `from` replaced by `to`, written as `name`.toml.
std::string variant(const std::string& name, const std::string& from, const std::string& to) {
  std::string text = jump2d();
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("jump2d.toml has no " + from);
  text.replace(at, from.size(), to);
  return tiny_biped::write_skill(name, text);
}

// The line (1-based) of the first occurrence of `text` in the file.
int line_of(const std::string& file, const std::string& text) {
  const std::string all = test_files::read_text(file);
  const auto at = all.find(text);
  if (at == std::string::npos) return -1;
  return 1 + static_cast<int>(std::count(all.begin(), all.begin() + static_cast<long>(at), '\n'));
}

// The message loading (and, with a character, binding) the file gives.
std::string message(const std::string& file, const TaskEvaluator* human = nullptr) {
  try {
    const SkillFile s = load_skill_file(file);
    if (human != nullptr) bind_skill(s, human->body(), human->model().get());
  } catch (const UserError& e) {
    return e.what();
  }
  return "no error";
}

TEST(SkillFile, Jump2dBindsToThePlanarHumanWithThePapersParameters) {
  const TaskEvaluator human(load_task(kRoot + "/tasks/jump_onto.toml"));
  const SkillFile s = load_skill_file(kRoot + "/skills/jump2d.toml");
  ASSERT_EQ(s.phases.size(), 6u);
  EXPECT_EQ(s.takeoff, "rise");
  EXPECT_EQ(s.film_strip, (std::vector<std::string>{"takeoff", "peak", "landing"}));
  const SkillBinding b = bind_skill(s, human.body(), human.model().get());
  // 6 phases x (8 posed groups + 6 gains), 3 durations, 3 module parameters.
  ASSERT_EQ(b.params.size(), 90u);
  EXPECT_EQ(b.params[0].name, "start.pelvis");
  EXPECT_EQ(b.params[2].name, "start.foot");
  EXPECT_EQ(b.params[4].name, "start.chest");
  EXPECT_EQ(b.params[8].name, "start.kp_hip");
  EXPECT_EQ(b.params[42].name, "rise.hip");
  EXPECT_EQ(b.params[84].name, "start.duration");
  EXPECT_EQ(b.params[87].name, "land.balance_offset");
  EXPECT_EQ(b.params[89].name, "landing.velocity_gain");
  EXPECT_EQ(b.params[89].unit, "s");
  // The knee's range is the joint's; the pelvis's the file's.
  EXPECT_EQ(b.params[1].lower, -2.6);
  EXPECT_EQ(b.params[0].lower, -1.4);
}

TEST(SkillFile, BadFilesNameTheFileLineFieldAndExpectation) {
  const TaskEvaluator human(load_task(kRoot + "/tasks/jump_onto.toml"));
  struct Bad {
    std::string name, from, to, marker, expected;
    bool bind;
  };
  const std::vector<Bad> cases = {
      {"unknown_key", "pairs = ", "colour = \"red\"\npairs = ", "colour",
       "colour: expected no such key (unknown key; known keys: name, description, kind, root, pairs, start, events, targets, "
       "gains, modules, phases)",
       false},
      {"no_group", "neck = 0.0\n", "neck = 0.0\ntail = 0.0\n", "tail",
       "targets.stance.tail: expected a joint group, role or ROLE.top of the character " + human.body().spec->file +
           ", got \"tail\" (it has none)",
       true},
      {"no_body", "{ to = \"fall\", on = \"peak\" }", "{ to = \"fall\", on = \"contact_lost\", body = \"wing\" }", "wing",
       "phases.rise.next.body: expected a body of the character " + human.body().spec->file +
           ", got \"wing\" (no such body)",
       true},
      {"no_phase", "{ to = \"fall\", on = \"peak\" }", "{ to = \"flight\", on = \"peak\" }", "to = \"flight\"",
       "phases[3].next[1].to: expected the name of a phase, got \"flight\" (no such phase)", false},
      {"never_left", "modules = [\"balance\"]\nnext = [{ to = \"extend\", on = \"duration\" }]",
       "modules = [\"balance\"]", "[[phases]]\nname = \"crouch\"",
       "phases[1].next: expected at least one transition: phase \"crouch\" can never be left (only the last phase may "
       "end the skill)",
       false},
      {"empty_range", "range = [0.05, 0.6]", "range = [0.6, 0.05]", "range = [0.6",
       "phases[0].duration.range: expected a range that is not empty (LOWER < UPPER), got [0.6, 0.05]", false},
      {"missing_setting", "kp = 1500.0\n", "", "[[modules]]",
       "modules[0].kp: expected a setting of the \"balance\" module (missing)", false},
      {"unknown_kind", "kind = \"foot_placement\"", "kind = \"foot_planting\"", "foot_planting",
       "modules[1].kind: expected one of \"balance\", \"foot_placement\", \"spotting\", \"stance\", \"simbicon\", "
       "\"gravity_compensation\", \"stance_support\", \"stance_hip\", \"stance3d\", \"aim_legs\", \"root_damping\", "
       "\"linear_feedback\", got \"foot_planting\"",
       false},
      {"unknown_condition", "on = \"peak\"", "on = \"apex\"", "apex",
       "phases[3].next[1].on: expected one of \"duration\", \"time\", \"contact\", \"touchdown\", \"liftoff\", "
       "\"contact_made\", \"contact_lost\", \"peak\", \"turned\", \"spotted\", \"feature\", got \"apex\"",
       false},
      {"condition_setting", "{ to = \"land\", on = \"time\", after = 0.8, gave_up = true }",
       "{ to = \"land\", on = \"time\", gave_up = true }", "gave_up = true }",
       "phases[2].next[1].after: expected a setting for the \"time\" condition (missing)", false},
      {"feedback_feature", "[[phases]]",
       "[[modules]]\nname = \"fb\"\nkind = \"linear_feedback\"\nfeature = \"com_vy\"\ntarget = \"hip\"\ngain = 0.1\n\n[[phases]]",
       "com_vy",
       "modules[2].feature: expected one of \"com_x\", \"com_z\", \"com_vx\", \"com_vz\", \"pitch\", \"pitch_rate\", got \"com_vy\"",
       false},
      {"feedback_no_target", "[[phases]]",
       "[[modules]]\nname = \"fb\"\nkind = \"linear_feedback\"\nfeature = \"com_vx\"\ngain = 0.1\n\n[[phases]]",
       "[[modules]]\nname = \"fb\"", "modules[2].target: expected a setting of the \"linear_feedback\" module (missing)", false},
      {"feedback_target", "[[phases]]",
       "[[modules]]\nname = \"fb\"\nkind = \"linear_feedback\"\nfeature = \"com_vx\"\ntarget = \"tail\"\ngain = 0.1\n\n[[phases]]",
       "[[modules]]\nname = \"fb\"",
       "modules.fb.target: expected a joint group, role or ROLE.plane of the character " + human.body().spec->file +
           ", got \"tail\" (it selects no group)",
       true},
      {"feedback_limit", "[[phases]]",
       "[[modules]]\nname = \"fb\"\nkind = \"linear_feedback\"\nfeature = \"com_vx\"\ntarget = \"hip\"\ngain = 0.1\nlimit = 0.0\n\n[[phases]]",
       "limit = 0.0", "modules[2].limit: expected a number in [1e-06, 1e+09], got 0", false},
      {"unknown_module", "modules = [\"landing\"]", "modules = [\"landing_aim\"]", "landing_aim",
       "phases[4].modules: expected modules the file declares in [[modules]], got \"landing_aim\"", false},
  };
  for (const Bad& c : cases) {
    const std::string file = variant(c.name, c.from, c.to);
    const int line = c.marker.empty() ? 1 : line_of(file, c.marker);
    EXPECT_EQ(message(file, c.bind ? &human : nullptr), file + ": line " + std::to_string(line) + ": " + c.expected)
        << c.name;
  }
}

// A task's [controller] table naming a skill: the file must exist, and the other keys name
// the skill's modules, whose number settings they override.
TEST(SkillFile, TaskControllerTablesNameAnExistingSkillAndItsModules) {
  const std::string skill = test_files::read_text(kRoot + "/skills/jump2d.toml");
  auto refused = [&](const std::string& extra, const std::string& expected) {
    try {
      tiny_biped::task("controller_table", skill, extra);
      ADD_FAILURE() << "accepted " << extra;
    } catch (const UserError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(expected), std::string::npos) << m;
    }
  };
  refused("bounce = 2", "controller.bounce: expected no such key (unknown key; known keys: type, skill, landing_height, "
                        "balance, landing, the last the skill's modules as tables)");
  refused("balance = { lean = \"far\" }", "controller.balance.lean: expected a number");
  refused("balance = { colour = 1 }", "controller.balance.colour: expected a setting of the \"balance\" module balance");
  refused("landing = { offset = 0.1 }",
          "controller.landing.offset: expected a number setting (the skill makes landing.offset the parameter "
          "\"landing.offset\")");
  const Task ok = tiny_biped::task("controller_table", skill, "balance = { kp = 4000.0 }");
  const auto& modules = dynamic_cast<const SkillConfig&>(*ok.controller_config).skill->modules;
  EXPECT_EQ(modules[0].settings.at("kp").number, 4000.0);
  EXPECT_EQ(modules[0].settings.at("kd").number, 300.0);
  try {
    const std::string task_file = (tiny_biped::dir() / "missing_skill.toml").string();
    test_files::write_text(task_file, "name = \"m\"\ncharacter = \"tiny_biped.toml\"\nmetric = \"md\"\nvariations = 1\n"
                                      "m0 = \"none.json\"\n[controller]\nskill = \"nowhere.toml\"\n[constraints]\n"
                                      "weight = 1.0\nfall_penalty = 1.0\n");
    load_task(task_file);
    ADD_FAILURE() << "a missing skill file was accepted";
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()), (tiny_biped::dir() / "missing_skill.toml").string() +
                                         ": controller.skill: expected an existing skill file (relative to the task "
                                         "file), but " +
                                         (tiny_biped::dir() / "nowhere.toml").string() + " does not exist");
  }
}

}  // namespace
}  // namespace diverse
