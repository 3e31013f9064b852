// Every kind of bad input the tool reads, through the built `diverse`: each must end in
// one line "diverse: error: ..." naming the option or file, the field and what was
// expected, with exit code 2 (never an internal error, a crash or a hang). One test per
// class of input: options of every subcommand, task files, character files and their
// models, parameter files, motion files, run directories and checkpoints.
// docs/reference/reliability.md counts these cases.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <vector>

#include "io/files.h"
#include "support/cli.h"
#include "support/scratch.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

const std::string kSource = DIVERSE_SOURCE_DIR;
const std::string kTask = kSource + "/tasks/jump_high.toml";

struct Case {
  std::string args;      // arguments of `diverse`
  std::string expected;  // text the error line must contain
};

fs::path scratch(const std::string& name) {
  const fs::path dir = test_files::scratch_dir("bad_input_" + name);
  fs::create_directories(dir);
  return dir;
}

void expect_user_error(const Case& c) {
  SCOPED_TRACE("diverse " + c.args);
  // Under a time limit: a hang fails the case (exit 124) instead of stalling the suite.
  // glibc fills freed memory with a pattern (MALLOC_PERTURB_), so a message that reads what
  // an error path already freed comes out wrong instead of by luck right.
  const cli_test::CliResult r = cli_test::run_cli(c.args + " </dev/null", "MALLOC_PERTURB_=165 timeout 120");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_EQ(r.output.rfind("diverse: error: ", 0), 0u) << r.output;
  EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << "expected one line: " << r.output;
  EXPECT_NE(r.output.find(c.expected), std::string::npos) << r.output;
}

std::string read(const fs::path& p) { return read_file(p); }

void write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

// jump_high.toml (or another task) with its relative paths made absolute, `replace`
// pairs applied (each must match) and `append` added at the end; an `append` that opens
// with a table the task already has ("\n[simulation]\n...") adds its keys to that table.
std::string task_text(const std::string& task, const std::vector<std::pair<std::string, std::string>>& replace,
                      const std::string& append = "") {
  std::string t = read(kSource + "/tasks/" + task + ".toml");
  t = std::regex_replace(t, std::regex("\"\\.\\./assets/"), "\"" + kSource + "/assets/");
  t = std::regex_replace(t, std::regex("\"\\.\\./skills/"), "\"" + kSource + "/skills/");
  t = std::regex_replace(t, std::regex("m0 = \""), "m0 = \"" + kSource + "/tasks/");
  t = std::regex_replace(t, std::regex("base = \""), "base = \"" + kSource + "/tasks/");
  for (const auto& [from, to] : replace) {
    const auto at = t.find(from);
    EXPECT_NE(at, std::string::npos) << "no '" << from << "' in " << task;
    if (at != std::string::npos) t.replace(at, from.size(), to);
  }
  if (append.starts_with("\n[")) {
    const std::string header = append.substr(0, append.find('\n', 1) + 1);
    const auto at = t.find(header);
    if (at != std::string::npos) return t.insert(at + header.size(), append.substr(header.size()));
  }
  return t + append;
}

TEST(BadInput, OptionsOfEverySubcommand) {
  const fs::path dir = scratch("options");
  const std::string out = " --out " + (dir / "out").string();
  const std::string run = "run " + kTask + out + " ";
  const Case cases[] = {
      // The cases users reported: an out-of-memory, a hang, a zero step, an N of 0.
      {run + "--n 100000", "--n: expected an integer in [1, 100], got '100000'"},
      {run + "--threads 100000", "--threads: expected an integer in [0, 256], got '100000'"},
      {run + "--sigma0 0", "--sigma0: expected a number in (0, 1], got '0'"},
      {run + "--n 0", "--n: expected an integer in [1, 100], got '0'"},
      {run + "--n 2.5", "--n: expected an integer in [1, 100], got '2.5'"},
      {run + "--n 99999999999999999999", "--n: expected an integer in [1, 100]"},
      {run + "--threads -1", "--threads: expected an integer in [0, 256], got '-1'"},
      {run + "--sigma0 nan", "--sigma0: expected a number in (0, 1], got 'nan'"},
      {run + "--sigma0 1.5", "--sigma0: expected a number in (0, 1], got '1.5'"},
      {run + "--k inf", "--k: expected a number in [0, 1000000000], got 'inf'"},
      {run + "--k -1", "--k: expected a number in [0, 1000000000], got '-1'"},
      {run + "--generations 0", "--generations: expected an integer in [1, 1000000], got '0'"},
      {run + "--popsize 1", "--popsize: expected an integer in [2, 1000], got '1'"},
      {run + "--popsize 1000000", "--popsize: expected an integer in [2, 1000], got '1000000'"},
      {run + "--seed -1", "--seed: expected an integer in [0, 18446744073709551615], got '-1'"},
      {run + "--seed 1e3", "--seed: expected an integer in [0, 18446744073709551615], got '1e3'"},
      {run + "--seed 18446744073709551616", "--seed: expected an integer in [0, 18446744073709551615]"},
      {run + "--window -5", "--window: expected an integer in [0, 1000000], got '-5'"},
      {run + "--epsilon nan", "--epsilon: expected a number in [0, 1000000000000], got 'nan'"},
      {run + "--checkpoint-seconds -1", "--checkpoint-seconds: expected a number in [0, 86400], got '-1'"},
      {run + "--rank-timeout 1", "--rank-timeout: expected a number in [2, 86400], got '1'"},
      {run + "--shape-weight 0 --vary shape --metric md+shape", "--shape-weight: expected a number in (0, 1000000000], got '0'"},
      {run + "--metric euclid", "--metric: unknown metric 'euclid'"},
      {run + "--vary colour", "--vary: expected control or shape, got 'colour'"},
      {run + "--metric shape", "--metric: the shape metric needs the shape parameters (--vary shape)"},
      {run + "--strategy sideways", "sideways"},
      {run + "--strength 0", "--strength: expected a number in [0.1, 10], got '0'"},
      {run + "--strength 11", "--strength: expected a number in [0.1, 10], got '11'"},
      {run + "--strength two", "--strength: expected a number in [0.1, 10], got 'two'"},
      {run + "--effort-bound 0.5", "--effort-bound: expected a number in [1, 1000000], got '0.5'"},
      {run + "--effort-bound inf", "--effort-bound: expected a number in [1, 1000000], got 'inf'"},
      {run + "--max-distance 0", "--max-distance: expected a number in (0, 1000000000000], got '0'"},
      {run + "--max-distance -3", "--max-distance: expected a number in (0, 1000000000000], got '-3'"},
      {run + "--max-distance nan", "--max-distance: expected a number in (0, 1000000000000], got 'nan'"},
      {"run no_such_task" + out, "no_such_task: expected a task file or the name of one in tasks/"},
      {"run " + dir.string() + out, ": expected a task file or the name of one in tasks/"},
      {"run " + kTask + " --out /proc/diverse_cannot_be_here", "/proc/diverse_cannot_be_here: cannot create output directory"},
      {"run " + kTask + " --no-such-flag" + out, "--no-such-flag"},
      {"resume " + (dir / "nowhere").string(), "nowhere: not a directory"},
      {"resume " + dir.string() + " --threads 1000", "--threads: expected an integer in [0, 256], got '1000'"},
      {"resume " + dir.string() + " --checkpoint-seconds nan", "--checkpoint-seconds: expected a number in [0, 86400], got 'nan'"},
      {"resume " + dir.string() + " --rank-timeout x", "--rank-timeout: expected a number in [2, 86400], got 'x'"},
      {"simulate jump_high --params " + dir.string() + out, dir.string() + ": cannot read the parameter file (it is a directory)"},
      {"simulate jump_high --params /dev/zero" + out, "/dev/zero: cannot read the parameter file (not a regular file)"},
      {"simulate jump_high --params " + (dir / "none.json").string() + out, "none.json: cannot read the parameter file (No such file or directory)"},
      {"simulate jump_high", "--out is required"},
      {"replay " + dir.string(), dir.string() + ": cannot read (it is a directory)"},
      {"seed-motion jump_high --threads 0", "--threads: expected an integer in [1, 256], got '0'"},
      {"seed-motion jump_high --sigma nan", "--sigma: expected a number in [1e-06, 1], got 'nan'"},
      {"seed-motion jump_high --check-sigmas 0.02 inf", "--check-sigmas: expected a number in [1e-06, 1], got 'inf'"},
      // --robust is a flag, and goes with the other options in their ranges only.
      {"seed-motion jump_high --robust=maybe", "--robust = maybe"},
      {"seed-motion jump_high --robust --perturbations -1", "--perturbations: expected an integer in [0, 1000], got '-1'"},
      {"seed-motion jump_high --perturbations 4 --selection-samples -1", "--selection-samples: expected an integer in [0, 1000], got '-1'"},
      {"seed-motion jump_high --perturbations 4 --objective median", "--objective: expected mean or share, got 'median'"},
      {"seed-motion jump_high --pushes -2", "--pushes: expected an integer in [0, 1000], got '-2'"},
      {"seed-motion jump_high --pushes 4 --push-speed 0", "--push-speed: expected a number in [1e-06, 10], got '0'"},
      {"seed-motion jump_high --pushes 4 --push-speed nan", "--push-speed: expected a number in [1e-06, 10], got 'nan'"},
      {"seed-motion jump_high --robust --generations 0", "--generations: expected an integer in [1, 100000], got '0'"},
      {"seed-motion jump_high --robust --robustness-check --check-samples 0",
       "--check-samples: expected an integer in [1, 100000], got '0'"},
      {"seed-motion jump_high --robust --robustness-check --start /nonexistent/m0.json",
       "/nonexistent/m0.json: cannot read the parameter file"},
      {"seed-motion jump_high --convergence", "--convergence: only with --robustness-check"},
      {"seed-motion silly_walk --robustness-check --convergence",
       "silly_walk.toml is a walk"},
      {"bench --seconds 0", "--seconds: expected a number in (0, 3600], got '0'"},
      {"bench --threads 100000", "--threads: expected an integer in [0, 256], got '100000'"},
      {"bench --rounds 0", "--rounds: expected an integer in [1, 1000], got '0'"},
      {"bench --batch 0", "--batch: expected an integer in [1, 100000], got '0'"},
      {"character " + dir.string(), dir.string() + ": cannot read the character file (it is a directory)"},
      {"render " + (dir / "nowhere").string(), "nowhere: no such directory"},
      {"render " + dir.string() + " --fps 45", "--fps: expected 30 or 60, got 45"},
      {"gallery " + dir.string() + " --threads -2", "--threads: expected an integer in [0, 256], got '-2'"},
      {"export " + dir.string(), "export: choose a format: --bvh"},
      {"export " + dir.string() + " --bvh --fps 24", "--fps: expected 30 or 60, got 24"},
      {"blend " + (dir / "nowhere").string(), "nowhere: no such directory"},
      {"blend " + dir.string() + " --samples 0", "--samples: expected an integer in [1, 100000], got '0'"},
      {"blend " + dir.string() + " --path-points nan", "--path-points: expected an integer in [0, 10000], got 'nan'"},
      {"report " + dir.string(), "not a finished run (no summary.json)"},
      {"cmaes --function sphere --dim 0", "--dim: expected an integer from 1 to 1000, got '0'"},
      {"toy --n 0" + out, "--n: expected an integer in [1, 100], got '0'"},
      {"toy --threads 100000" + out, "--threads: expected an integer in [1, 256], got '100000'"},
      {"toy --k nan" + out, "--k: expected a number in [0, 1000000000], got 'nan'"},
      {"no-such-command", "no-such-command: expected a subcommand ("},
  };
  for (const Case& c : cases) expect_user_error(c);
}

TEST(BadInput, TaskFileFields) {
  const fs::path dir = scratch("task");
  int index = 0;
  auto task_case = [&](const std::string& text, const std::string& expected) {
    const fs::path file = dir / ("t" + std::to_string(index++) + ".toml");
    write(file, text);
    return Case{"simulate " + file.string() + " --no-film --out " + (dir / "out").string(), file.string() + ": " + expected};
  };
  const std::string box = "\n[[objects]]\nname = \"crate\"\nkind = \"box\"\nx_min = 0.55\nx_max = 1.35\nheight = 0.5\n";
  const Case cases[] = {
      // A name that would inject MJCF attributes.
      task_case(task_text("jump_onto", {{"name = \"box\"", "name = \"box\\\" pos=\\\"0 0 9\""},
                                        {"object = \"box\"", "object = \"box\\\" pos=\\\"0 0 9\""}}),
                "objects[0].name: expected 1 to 64 letters, digits, '_', '-' or '.', got \"box\" pos=\"0 0 9\""),
      task_case(task_text("jump_high", {{"timestep = 0.004", "timestep = 1e-300"}}),
                "simulation.timestep: expected 0 (the model's) or a number in [1e-05, 0.01], got 1e-300"),
      task_case(task_text("jump_high", {{"timestep = 0.004", "timestep = 0.5"}}),
                "simulation.timestep: expected a number in [0, 0.01], got 0.5"),
      // A box-top margin wider than half the box: nowhere to stand.
      task_case(task_text("jump_onto", {{"margin = 0.1", "margin = 0.45"}}),
                "constraints.on_box.margin: expected less than half the width of \"box\" (0.8 m wide), got 0.45 m"),
      // An object where the character stands.
      task_case(task_text("jump_onto", {{"x_min = 0.55", "x_min = -0.3"}}),
                "objects[0]: expected an object clear of the character's start pose, but \"box\" overlaps its"),
      // Constraints that exclude one another.
      task_case(task_text("jump_high", {{"peak_height = { above_standing = 0.293 }", "peak_height = { above_standing = 0.293 }\nmin_length = { length = 2.0 }"}}),
                "constraints.landing, constraints.min_length: expected landing constraints that some x satisfies"),
      task_case(task_text("jump_over", {{"min_clearance = 0.02", "min_clearance = 0.5"}}),
                "constraints.clearance.min_clearance: expected less than simulation.clearance_range (0.3 m"),
      task_case(task_text("jump_high", {}, "\n[simulation]\nmax_time = 1.0\nsettle_time = 1.0\n"),
                "simulation.max_time: expected more than simulation.settle_time (1 s)"),
      task_case(task_text("jump_high", {}, "\n[simulation]\nrest_hold = 7\n"),
                "simulation.rest_hold: expected a number in [0, 5], got 7"),
      task_case(task_text("jump_high", {}, "\n[simulation]\nbalanced_rest = 1\n"),
                "simulation.balanced_rest: expected true or false"),
      task_case(task_text("jump_high", {{"variations = 4", "variations = 0"}}),
                "variations: expected an integer in [1, 100], got 0"),
      task_case(task_text("jump_high", {{"variations = 4", "variations = 100000"}}),
                "variations: expected an integer in [1, 100], got 100000"),
      task_case(task_text("jump_high", {{"metric = \"md\"", "metric = \"euclid\""}}),
                "metric: expected \"hf\", \"md\" or \"wja\", got \"euclid\""),
      task_case(task_text("jump_high", {{"name = \"jump_high\"", "name = 3"}}), "name: expected a string"),
      task_case(task_text("jump_high", {{"name = \"jump_high\"", ""}}), "name: expected a string (missing)"),
      task_case(task_text("jump_high", {{"name = \"jump_high\"", "name = \"jump_high\"\ncolour = \"red\""}}),
                "colour: expected no such key (unknown key; known keys: name, description, "),
      task_case(task_text("jump_high", {{"above_standing = 0.293", "above_standing = nan"}}),
                "constraints.peak_height.above_standing: expected a number in [0, 5], got nan"),
      task_case(task_text("jump_high", {{"skill = \"", "type = \"jump9d\"\nskill = \""}}), "controller.type"),
      task_case(task_text("jump_high", {{"skill = \"", "balance = { kp = -1.0 }\nskill = \""}}),
                "controller.balance.kp: expected"),
      // The old controller's toggles are no keys of a skill's task: the skill file says it.
      task_case(task_text("jump_backwards", {{"skill = \"", "asymmetric = true\nskill = \""}}),
                "controller.asymmetric: expected no such key (unknown key; known keys: type, skill, landing_height, crouch, push, land, landing"),
      task_case(task_text("jump_high", {{"character = \"" + kSource + "/assets/characters/human2d.toml\"",
                                         "character = \"" + dir.string() + "\""}}),
                "character: expected an existing file (relative to the task file)"),
      task_case(task_text("jump_high", {}, box + box),
                "objects[1].name: expected a unique name, \"crate\" repeats"),
      task_case("name = \"x\"\n[[[", "line 2: expected valid TOML"),
      task_case(std::string("name = \"\xff\xfe\"\n"), "line 1: expected valid TOML (Encountered invalid utf-8 sequence)"),
      task_case("", "name: expected a string (missing)"),
  };
  for (const Case& c : cases) expect_user_error(c);
}

// A copy of the planar human whose MJCF is changed by `edit`; returns a task file on it.
fs::path character_variant(const fs::path& dir, const std::string& name,
                           const std::vector<std::pair<std::string, std::string>>& xml_edits,
                           const std::vector<std::pair<std::string, std::string>>& toml_edits = {}) {
  const fs::path cdir = dir / name;
  fs::create_directories(cdir);
  std::string xml = read(kSource + "/assets/characters/human2d.xml");
  for (const auto& [from, to] : xml_edits) {
    const auto at = xml.find(from);
    EXPECT_NE(at, std::string::npos) << "no '" << from << "' in human2d.xml";
    if (at != std::string::npos) xml.replace(at, from.size(), to);
  }
  write(cdir / "human2d.xml", xml);
  std::string toml = read(kSource + "/assets/characters/human2d.toml");
  for (const auto& [from, to] : toml_edits) {
    const auto at = toml.find(from);
    EXPECT_NE(at, std::string::npos) << "no '" << from << "' in human2d.toml";
    if (at != std::string::npos) toml.replace(at, from.size(), to);
  }
  write(cdir / "human2d.toml", toml);
  const fs::path task = cdir / "task.toml";
  // At the model's own timestep, so that the model's option.timestep is the one used.
  write(task, task_text("jump_high", {{kSource + "/assets/characters/human2d.toml", (cdir / "human2d.toml").string()},
                                      {"timestep = 0.004\n", ""}}));
  return task;
}

TEST(BadInput, CharacterFilesAndModels) {
  const fs::path dir = scratch("character");
  const std::string out = " --no-film --out " + (dir / "out").string();
  auto sim = [&](const fs::path& task) { return "simulate " + task.string() + out; };
  const std::string xml = read(kSource + "/assets/characters/human2d.xml");
  ASSERT_NE(xml.find("<option"), std::string::npos);
  const Case cases[] = {
      // Zero and upward gravity: the controllers divide by g.
      {sim(character_variant(dir, "zero_g", {{"gravity=\"0 0 -9.81\"", "gravity=\"0 0 0\""}})),
       "human2d.xml: option.gravity: expected gravity pointing down, \"0 0 -g\" with g in [0.1, 100] m/s^2, got \"0 0 0\""},
      {sim(character_variant(dir, "up_g", {{"gravity=\"0 0 -9.81\"", "gravity=\"0 0 9.81\""}})),
       "option.gravity: expected gravity pointing down"},
      {sim(character_variant(dir, "tiny_dt", {{"timestep=\"0.002\"", "timestep=\"1e-9\""}})),
       "human2d.xml: option.timestep: expected a timestep in [1e-05, 0.01] s, got 1e-09"},
      {sim(character_variant(dir, "no_model", {}, {{"model = \"human2d.xml\"", "model = \"missing.xml\""}})),
       "model"},
      {sim(character_variant(dir, "bad_root", {}, {{"[root]", "[root]\ncolour = 1"}})), "root.colour: expected no such key"},
      {sim(character_variant(dir, "broken_xml", {{"</worldbody>", "</worldbod>"}})), "human2d.xml"},
      {"character " + (dir / "nowhere.toml").string(), "nowhere.toml"},
  };
  for (const Case& c : cases) expect_user_error(c);
}

// An extra body (a prop) whose name begins like a hand's or a foot's is just another
// link: the character file says which bodies are the hands and feet.
TEST(BadInput, ExtraBodiesNamedLikeHandsAndFeetAreNotSpecial) {
  const fs::path dir = scratch("props");
  const std::string xml = read(kSource + "/assets/characters/human2d.xml");
  const auto torso = xml.find("<body name=\"chest\"");
  ASSERT_NE(torso, std::string::npos) << "human2d.xml has no body named chest";
  const auto open_end = xml.find('>', torso);
  const std::string props =
      "\n<body name=\"hand_prop\" pos=\"0 0 0.05\"><geom name=\"hand_prop_g\" type=\"sphere\" size=\"0.02\" mass=\"0.1\" contype=\"0\" conaffinity=\"0\"/></body>"
      "\n<body name=\"foot_prop\" pos=\"0 0 0.08\"><geom name=\"foot_prop_g\" type=\"sphere\" size=\"0.02\" mass=\"0.1\" contype=\"0\" conaffinity=\"0\"/></body>\n";
  const fs::path task = character_variant(dir, "props", {{xml.substr(torso, open_end + 1 - torso), xml.substr(torso, open_end + 1 - torso) + props}});
  const cli_test::CliResult c = cli_test::run_cli("character " + (task.parent_path() / "human2d.toml").string());
  EXPECT_EQ(c.status, 0) << c.output;
  const cli_test::CliResult s = cli_test::run_cli("simulate " + task.string() + " --no-film --out " + (dir / "out").string());
  EXPECT_EQ(s.status, 0) << s.output;
  EXPECT_EQ(s.output.find("internal error"), std::string::npos) << s.output;
}

TEST(BadInput, ParameterFiles) {
  const fs::path dir = scratch("params");
  const nlohmann::json m0 = read_json(kSource + "/tasks/jump_high.m0.json");
  const nlohmann::json params = m0.contains("parameters") ? m0["parameters"] : m0;
  ASSERT_TRUE(params.is_object());
  const std::string first = params.begin().key();
  int index = 0;
  auto param_case = [&](const std::string& text, const std::string& expected) {
    const fs::path file = dir / ("p" + std::to_string(index++) + ".json");
    write(file, text);
    return Case{"simulate jump_high --no-film --params " + file.string() + " --out " + (dir / "out").string(),
                file.string() + ": " + expected};
  };
  nlohmann::json missing = params, extra = params, wrong = params, out_of_range = params;
  missing.erase(first);
  extra["no.such.parameter"] = 1.0;
  wrong[first] = "high";
  out_of_range[first] = 1e300;
  const Case cases[] = {
      param_case("{\"parameters\": ", "expected valid JSON"),
      param_case("", "expected valid JSON"),
      param_case("[1, 2, 3]", ""),
      param_case(missing.dump(), "parameters." + first + ": expected a number in"),
      param_case(extra.dump(), "parameters.no.such.parameter: expected a known parameter name"),
      param_case(wrong.dump(), "parameters." + first + ": expected a number in"),
      param_case(out_of_range.dump(), "parameters." + first + ": expected a number in"),
      param_case("{\"parameters\": {\"shape.leg\": 1e999}}", "expected valid JSON"),
  };
  for (const Case& c : cases) expect_user_error(c);
}

TEST(BadInput, MotionFilesRunDirectoriesAndCheckpoints) {
  const fs::path dir = scratch("runs");
  const fs::path good = dir / "good";
  const cli_test::CliResult made = cli_test::run_cli(
      "run " + kTask + " --n 1 --popsize 2 --generations 1 --threads 1 --quiet --no-render --out " + good.string());
  ASSERT_EQ(made.status, 0) << made.output;
  int index = 0;
  // A copy of the good run with `file` replaced by `text`.
  auto broken = [&](const std::string& file, const std::string& text) {
    const fs::path copy = dir / ("r" + std::to_string(index++));
    fs::copy(good, copy, fs::copy_options::recursive);
    write(copy / file, text);
    return copy;
  };
  const nlohmann::json motion = read_json(good / "motions/m1.json");
  const nlohmann::json checkpoint = read_json(good / "checkpoint.json");
  const nlohmann::json run = read_json(good / "run.json");
  auto motion_with = [&](const std::string& pointer, const nlohmann::json& value) {
    nlohmann::json m = motion;
    m[nlohmann::json::json_pointer(pointer)] = value;
    return m.dump();
  };
  auto checkpoint_with = [&](const std::string& pointer, const nlohmann::json& value) {
    nlohmann::json c = checkpoint;
    c[nlohmann::json::json_pointer(pointer)] = value;
    return c.dump();
  };
  auto run_with = [&](const std::string& pointer, const nlohmann::json& value) {
    nlohmann::json r = run;
    r[nlohmann::json::json_pointer(pointer)] = value;
    return r.dump();
  };
  const std::size_t nv = motion["replay"]["qvel0"].size();
  nlohmann::json past_the_dofs = motion;
  past_the_dofs["replay"]["damped_dofs"] = nlohmann::json::array({nv + 3});
  past_the_dofs["replay"]["damping"] = nlohmann::json::array();
  auto replay = [&](const std::string& text, const std::string& expected) {
    const fs::path copy = broken("motions/m1.json", text);
    return Case{"replay " + (copy / "motions/m1.json").string(), expected};
  };
  auto resume = [&](const std::string& file, const std::string& text, const std::string& expected) {
    const fs::path copy = broken(file, text);
    fs::remove(copy / "summary.json");
    return Case{"resume --quiet --no-render " + copy.string(), expected};
  };
  const Case cases[] = {
      replay("{", "m1.json: not valid JSON"),
      replay(motion_with("/replay/nq", "many"), "replay.nq: missing or malformed"),
      replay(motion_with("/replay/nq", 1e30), "replay.nq: missing or malformed"),
      replay(motion_with("/format", 5), "format: expected \"diverse.motion\""),
      replay(motion_with("/replay/nq", 100000000), "replay"),
      replay(motion_with("/replay/timestep", -1), "replay.timestep"),
      replay(motion_with("/replay/ctrl", nlohmann::json::array({nlohmann::json::array({1.0})})), "replay.ctrl: missing or malformed"),
      replay(motion_with("/replay/qpos", nlohmann::json::array()), "as many qpos rows as ctrl rows"),
      replay(motion_with("/replay/qpos/0", nlohmann::json::array({1.0})), "replay.qpos: missing or malformed"),
      replay(motion_with("/replay/model", "../model/none.xml"), "none.xml"),
      replay(motion_with("/replay/model", 7), "replay.model"),
      replay(motion_with("/replay/damping", nlohmann::json::array({nlohmann::json{{"step", -5}, {"values", nlohmann::json::array()}}})), "replay.damping"),
      replay(motion_with("/replay/damped_dofs", nlohmann::json::array({100000})), "replay.damping: missing or malformed"),
      replay(motion_with("/replay/damped_dofs", nlohmann::json::array({-1})), "replay.damped_dofs: missing or malformed"),
      // A dof index past the model's: the message names the model's nv, read before the
      // model's copy is freed.
      replay(past_the_dofs.dump(), "replay.damped_dofs: expected dof indices below the model's nv (" +
                                       std::to_string(nv) + "), got " + std::to_string(nv + 3)),
      resume("run.json", "[]", "run.json: format: expected \"diverse.run\""),
      resume("run.json", run_with("/format", 5), "run.json: format: expected \"diverse.run\""),
      resume("run.json", run_with("/options/variations", 100000), "run.json: options: diversity options: variations must be in [1, 1000]"),
      resume("run.json", run_with("/options/variations", 1e30), "run.json: options.variations: expected an integer in"),
      resume("run.json", run_with("/options/strategy", "sideways"), "run.json: options.strategy"),
      resume("run.json", run_with("/task_file", 12), "run.json: expected the settings `diverse run` writes"),
      resume("run.json", run_with("/strength", 0), "run.json: strength: expected a number in [0.1, 10]"),
      resume("run.json", run_with("/strength", "strong"), "run.json: strength: expected a number in [0.1, 10]"),
      resume("run.json", run_with("/bounds/effort", 0.5), "run.json: bounds.effort: expected a number in [1, 1e6]"),
      resume("run.json", run_with("/bounds/distance", -1), "run.json: bounds.distance: expected a number in (0, 1e12]"),
      resume("run.json", run_with("/bounds/energy", 2), "run.json: bounds.energy: expected only the keys effort, distance and robust"),
      resume("run.json", run_with("/bounds", 3), "run.json: bounds: expected an object"),
      resume("run.json", run_with("/task_file", "/nonexistent/task.toml"), "run.json: task_file: /nonexistent/task.toml no longer exists"),
      resume("checkpoint.json", "", "checkpoint.json: not valid JSON"),
      resume("checkpoint.json", checkpoint_with("/format", 5), "checkpoint.json: format: expected a checkpoint written by `diverse run`"),
      resume("checkpoint.json", checkpoint_with("/wall_seconds", "long"), "checkpoint.json: wall_seconds: expected a number >= 0"),
      resume("checkpoint.json", checkpoint_with("/optimizer/options/popsize", 1e12), "checkpoint.json: "),
      resume("checkpoint.json", checkpoint_with("/optimizer/generation", -4), "checkpoint.json: "),
      resume("checkpoint.json", checkpoint_with("/optimizer/cma", nlohmann::json::array()), "checkpoint.json: checkpoint: expected state for 1 variations"),
      resume("checkpoint.json", checkpoint_with("/optimizer/points", nlohmann::json::array()), "checkpoint.json: "),
      resume("checkpoint.json", checkpoint_with("/optimizer/cma/0/sigma", "0x1p+4000"), "checkpoint.json: "),
      resume("checkpoint.json", checkpoint_with("/optimizer/current_D", 12345.0), "checkpoint.json: does not reproduce"),
      {"resume " + (dir / "nowhere").string(), "not a directory"},
  };
  for (const Case& c : cases) expect_user_error(c);
}

// `diverse robustness`: every option out of its range, a file that is neither a motion nor
// a run, a motion of another task than --task. All are refused before any rollout.
TEST(BadInput, RobustnessOptionsAndInputs) {
  const fs::path dir = scratch("robustness");
  const cli_test::CliResult made = cli_test::run_cli("simulate jump_high --no-film --out " + (dir / "sim").string());
  ASSERT_EQ(made.status, 0) << made.output;
  const std::string motion = (dir / "sim/motion.json").string();
  const std::string rob = "robustness " + motion + " ";
  write(dir / "notes.txt", "not json");
  write(dir / "other.json", R"({"format": "diverse.run"})");
  fs::create_directories(dir / "empty");
  const Case cases[] = {
      {rob + "--sigma 0", "--sigma: expected a number in (0, 0.5], got '0'"},
      {rob + "--sigma 0.7", "--sigma: expected a number in (0, 0.5], got '0.7'"},
      {rob + "--sigma nan", "--sigma: expected a number in (0, 0.5]"},
      {rob + "--samples 0", "--samples: expected an integer in [1, 1000], got '0'"},
      {rob + "--samples 5000", "--samples: expected an integer in [1, 1000], got '5000'"},
      {rob + "--push -0.1", "--push: expected a number in [0, 10], got '-0.1'"},
      {rob + "--push 11", "--push: expected a number in [0, 10], got '11'"},
      {rob + "--seed -1", "--seed: expected"},
      {rob + "--threads 1000", "--threads: expected an integer in [0, 256], got '1000'"},
      {"robustness", "expected a motion file, a run directory or --task FILE"},
      {"robustness " + (dir / "empty").string(), "empty: run.json: expected a run directory"},
      {"robustness " + (dir / "notes.txt").string(), "notes.txt: not valid JSON"},
      {"robustness " + (dir / "none.json").string(), "none.json: cannot read"},
      {"robustness " + (dir / "other.json").string(), "other.json: format: expected \"diverse.motion\""},
      {"robustness " + kTask, "jump_high.toml: not valid JSON"},
      // A motion of the high jump against the backflip, the walk or the 3D backwards jump.
      {rob + "--task backflip", "motion.json: task: expected a motion of task 'backflip' (--task backflip), got 'jump_high'"},
      {rob + "--task silly_walk", "motion.json: task: expected a motion of task 'silly_walk'"},
      {rob + "--task jump_backwards", "motion.json: task: expected a motion of task 'jump_backwards'"},
      // A parameter file needs its task; one of another task names the parameter.
      {"robustness " + kSource + "/tasks/jump_high.m0.json", "jump_high.m0.json: format: expected a motion file"},
      {"robustness " + kSource + "/tasks/jump_high.m0.json --task silly_walk", "jump_high.m0.json: parameters."},
      {rob + "--out " + (dir / "notes.txt/x.json").string(), "notes.txt"},
  };
  for (const Case& c : cases) expect_user_error(c);
}

// A task file that still names the planar jump controller "jump2d", which became the skill
// file skills/jump2d.toml: one line naming the file and the field, with the line to write
// instead (the path relative to the task file), for every command that reads a task.
TEST(BadInput, TheRetiredJumpControllerNamesItsSkillFile) {
  const fs::path dir = scratch("retired_jump2d");
  const fs::path file = dir / "tasks" / "old_jump.toml";
  write(file, task_text("jump_high", {{"skill = \"" + kSource + "/skills/jump_high.toml\"",
                                       "type = \"jump2d\"\nlanding_control = true\nlevel_feet = true"}}));
  const std::string relative = (fs::path(kSource) / "skills/jump2d.toml")
                                   .lexically_normal()
                                   .lexically_relative(fs::absolute(file).lexically_normal().parent_path())
                                   .string();
  const std::string expected = file.string() + ": controller.type: expected skill = \"" + relative +
                               "\" in place of type = \"jump2d\" (that controller is this skill file now";
  for (const std::string& command : {"simulate " + file.string() + " --no-film --out " + (dir / "out").string(),
                                     "run " + file.string() + " --generations 1 --out " + (dir / "run").string(),
                                     "seed-motion " + file.string() + " --generations 1"}) {
    expect_user_error({command, expected});
  }
}

// `diverse replay MOTION --task FILE` with a task of another controller or character than
// the motion's: refused before anything is replayed (it once replayed a jump "against" a
// walk and exited 0). The motion's own task is accepted.
TEST(BadInput, ReplayAgainstATaskOfAnotherSkill) {
  const fs::path dir = scratch("replay_task");
  const cli_test::CliResult made = cli_test::run_cli("simulate jump_high --no-film --out " + (dir / "sim").string());
  ASSERT_EQ(made.status, 0) << made.output;
  const std::string motion = (dir / "sim/motion.json").string();
  const Case cases[] = {
      {"replay " + motion + " --task silly_walk",
       "motion.json: parameters: expected the parameters of skill 'walk3d' for character 'human3d'"},
      {"replay " + motion + " --task robot_silly_walk", "motion.json: parameters: expected the parameters of skill 'robot_walk3d'"},
      // A task that names a skill file is named by its skill.
      {"replay " + motion + " --task jump_backwards",
       "motion.json: parameters: expected the parameters of skill 'jump3d' for character 'human3d'"},
      {"replay " + motion + " --task robot_jump", "motion.json: parameters: expected the parameters of skill 'robot_jump'"},
      {"replay " + motion + " --task " + kSource + "/examples/own-character/leap.toml", "motion.json: "},
      // The same character under the paper's jump (skills/jump2d.toml), with its foot
      // targets: 90 parameters, where the high jump's level feet leave 87.
      {"replay " + motion + " --task " + kSource + "/tests/task/data/jump_high_paper_feet.toml",
       "motion.json: parameters: expected the parameters of skill 'jump2d' for character 'human2d' (task " +
           kSource + "/tests/task/data/jump_high_paper_feet.toml): 90 of them, got 87 of a motion of task 'jump_high'"},
  };
  for (const Case& c : cases) expect_user_error(c);
  // Its own task replays as before.
  const cli_test::CliResult ok = cli_test::run_cli("replay " + motion + " --task jump_high");
  EXPECT_EQ(ok.status, 0) << ok.output;
}

}  // namespace
}  // namespace diverse
