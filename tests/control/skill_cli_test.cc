// `diverse skill check` and `diverse skill show` (apps/diverse/cmd_skill.cc): a good skill
// binds and is described; a bad one is refused with its one-line message and exit code 2.
#include <gtest/gtest.h>

#include <string>

#include "support/cli.h"
#include "support/text_files.h"
#include "tiny_biped.h"

namespace diverse {
namespace {

const std::string kRoot = DIVERSE_SOURCE_DIR;

TEST(SkillCli, CheckBindsAGoodSkillToTheDefaultOrAGivenCharacter) {
  const cli_test::CliResult r = cli_test::run_cli("skill check " + kRoot + "/skills/backflip.toml");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output, kRoot + "/skills/backflip.toml: skill backflip binds to " + kRoot +
                          "/assets/characters/human2d.toml: 6 phases, 3 modules, 90 parameters\n");
  const cli_test::CliResult t = cli_test::run_cli("skill check " + kRoot + "/skills/jump2d.toml --character " + kRoot +
                                                  "/examples/own-character/tailwalker.toml");
  EXPECT_EQ(t.status, 0) << t.output;
  EXPECT_NE(t.output.find("tailwalker.toml: 6 phases, 2 modules, 84 parameters"), std::string::npos) << t.output;
}

TEST(SkillCli, ShowPrintsPhasesTransitionsModulesAndParameters) {
  const cli_test::CliResult r = cli_test::run_cli("skill show " + kRoot + "/skills/backflip.toml");
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* line : {"  phase rise: targets flight, gains legs, duration predicted (rise), spotting\n",
                           "    -> land on contact, passing fall\n", "    -> fall on peak and spotted\n",
                           "  module spotting (spotting): open_time = 0.1; turn = 5.1;\n",
                           "  90 parameters for ", "    landing.velocity_gain    [-0.4, 0.4] s\n"}) {
    EXPECT_NE(r.output.find(line), std::string::npos) << line << "\n" << r.output;
  }
}

TEST(SkillCli, ABadSkillIsOneLineAndExitCode2) {
  std::string text = test_files::read_text(kRoot + "/skills/jump2d.toml");
  text.replace(text.find("{ to = \"fall\", on = \"peak\" }"), 29, "{ to = \"flight\", on = \"peak\" }");
  const std::string file = tiny_biped::write_skill("cli_no_phase", text);
  const cli_test::CliResult r = cli_test::run_cli("skill check " + file);
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output, "diverse: error: " + file +
                          ": line 97: phases[3].next[1].to: expected the name of a phase, got \"flight\" (no such "
                          "phase)\n");
  const cli_test::CliResult c = cli_test::run_cli("skill check " + kRoot + "/skills/jump2d.toml --character " + kRoot +
                                                  "/assets/characters/human3d.toml");
  EXPECT_EQ(c.status, 2);
  EXPECT_NE(c.output.find("jump2d.toml: line 6: root: expected a character with a planar root, but the character "),
            std::string::npos)
      << c.output;
}

}  // namespace
}  // namespace diverse
