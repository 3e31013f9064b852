// Constraints as listed terms (task/term.h): the list form [[constraints]] gives the same
// C, margins and rollouts as the table form, bit for bit; rotation about roll and the
// vertical; bodies allowed to touch; and every message of a bad entry.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <toml++/toml.h>
#include <vector>

#include "core/error.h"
#include "physics/model.h"
#include "support/cli.h"
#include "support/task_variant.h"
#include "support/text_files.h"
#include "task/constraints.h"
#include "task/evaluate.h"
#include "task/jump_eval.h"
#include "task/rollout_terms.h"
#include "task/task.h"
#include "task/term_fall.h"
#include "task/term_rotation.h"

namespace diverse {
namespace {

namespace fs = std::filesystem;

// The table form's constraints in the order their terms add to C (task.cc).
const std::vector<std::string> kTableKinds = {"landing", "on_box", "clearance", "min_length",
                                              "peak_height", "rotation", "pitch", "foot_slip"};

// A committed task with its [constraints] table rewritten as the list form: one
// [[constraints]] entry per constraint in the table form's order, each with the table's
// weight, then the fall rules, the half-timestep check and `extra_entries` (TOML text of
// [[constraints]] entries).
fs::path as_list_form(const std::string& task, const std::string& extra_entries = "") {
  const fs::path variant = test_files::task_variant(task, task + "_table", {}, {});
  toml::table root = toml::parse_file(variant.string());
  const toml::table table = *root["constraints"].as_table();
  toml::array list;
  for (const std::string& kind : kTableKinds) {
    const toml::table* keys = table[kind].as_table();
    if (keys == nullptr) continue;
    toml::table entry = *keys;
    entry.insert("kind", kind);
    entry.insert("weight", *table["weight"].value<double>());
    list.push_back(entry);
  }
  list.push_back(toml::table{{"kind", "fall"}, {"penalty", *table["fall_penalty"].value<double>()}});
  if (table["half_timestep"].value_or(false)) list.push_back(toml::table{{"kind", "half_timestep"}});
  if (!extra_entries.empty()) {
    const toml::table extra = toml::parse(extra_entries);
    for (const toml::node& entry : *extra["constraints"].as_array()) list.push_back(*entry.as_table());
  }
  root.insert_or_assign("constraints", list);
  std::ostringstream text;
  text << root << "\n";
  const fs::path file = variant.parent_path() / (task + "_list.toml");
  test_files::write_text(file.string(), text.str());
  return file;
}

Evaluation evaluate_m0(const TaskEvaluator& ev) {
  const auto worker = ev.make_worker();
  return ev.evaluate(ev.load_parameters(ev.task().m0).values(), *worker);
}

std::string error_of(const std::string& file) {
  try {
    load_task(file);
  } catch (const UserError& e) {
    const std::string what = e.what();
    return what.substr(what.find(": ") + 1);  // without the file
  }
  return "(no error)";
}

// A list-form task of `task` with `entries` in place of its constraints.
std::string with_entries(const std::string& task, const std::string& name, const std::string& entries) {
  const fs::path variant = test_files::task_variant(task, name, {}, {});
  std::string text = test_files::read_text(variant.string());
  const auto begin = text.find("\n[constraints]\n");
  const auto end = text.find("\n[", begin + 1);
  text.erase(begin + 1, end == std::string::npos ? std::string::npos : end - begin);
  text += "\n" + entries;
  const fs::path file = variant.parent_path() / (name + ".toml");
  test_files::write_text(file.string(), text);
  return file.string();
}

// Every committed task's input motion: the list form gives the same constraint value,
// terms, margin, summary and steps as the table form, to the last bit.
TEST(ConstraintTerms, ListFormMatchesTableFormOnEveryCommittedTask) {
  for (const std::string task : {"jump_high", "jump_forward", "jump_onto", "jump_over", "backflip", "hop", "split_leap",
                                 "tailwalker_tuck_jump", "jump_backwards", "robot_jump", "silly_walk",
                                 "robot_silly_walk"}) {
    SCOPED_TRACE(task);
    const TaskEvaluator table(load_task(test_files::task_variant(task, task + "_table", {}, {}).string()));
    const TaskEvaluator list(load_task(as_list_form(task).string()));
    ASSERT_EQ(table.task().constraints.terms.size(), list.task().constraints.terms.size());
    EXPECT_EQ(table.task().constraints.half_timestep, list.task().constraints.half_timestep);
    EXPECT_EQ(table.task().constraints.fall_penalty, list.task().constraints.fall_penalty);
    const Evaluation a = evaluate_m0(table), b = evaluate_m0(list);
    EXPECT_EQ(a.constraint, b.constraint);
    EXPECT_EQ(a.stats.steps, b.stats.steps);
    ASSERT_EQ(a.report.terms.size(), b.report.terms.size());
    for (size_t k = 0; k < a.report.terms.size(); ++k) {
      EXPECT_EQ(a.report.terms[k].name, b.report.terms[k].name);
      EXPECT_EQ(a.report.terms[k].penalty, b.report.terms[k].penalty);
    }
    EXPECT_EQ(constraint_margin(table.task(), a.summary), constraint_margin(list.task(), b.summary));
    EXPECT_EQ(a.summary.feet_x, b.summary.feet_x);
    EXPECT_EQ(a.summary.peak_com_z, b.summary.peak_com_z);
    EXPECT_EQ(a.summary.foot_slip, b.summary.foot_slip);
    EXPECT_EQ(a.summary.min_clearance, b.summary.min_clearance);
    EXPECT_EQ(a.summary.walk.steps.size(), b.summary.walk.steps.size());
    ASSERT_EQ(a.poses.size(), b.poses.size());
    if (!a.poses.empty()) {
      EXPECT_EQ(a.poses.back().link_com, b.poses.back().link_com);
    }
  }
}

// The committed list-form task file: the same input motion's rollout as tasks/
// jump_backwards.toml's, bit for bit, under the half-timestep check too.
TEST(ConstraintTerms, CommittedListFormTaskMatchesItsTable) {
  const TaskEvaluator table(load_task(std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_backwards.toml"));
  const TaskEvaluator list(load_task(std::string(DIVERSE_SOURCE_DIR) + "/tests/task/data/jump_backwards_list.toml"));
  EXPECT_TRUE(list.task().constraints.half_timestep);
  EvaluationOptions checked;
  checked.half_timestep_check = true;
  const auto table_worker = table.make_worker(), list_worker = list.make_worker();
  const std::vector<double> m0 = table.load_parameters(table.task().m0).values();
  const Evaluation a = table.evaluate(m0, *table_worker, checked), b = list.evaluate(m0, *list_worker, checked);
  EXPECT_EQ(a.constraint, 0.0);
  EXPECT_EQ(a.constraint, b.constraint);
  EXPECT_EQ(a.check_steps, b.check_steps);
  EXPECT_EQ(a.report.terms.size(), b.report.terms.size());
  EXPECT_EQ(a.summary.feet_x, b.summary.feet_x);
  EXPECT_EQ(a.summary.feet_y, b.summary.feet_y);
  EXPECT_EQ(constraint_margin(table.task(), a.summary), constraint_margin(list.task(), b.summary));
}

// The turn about each world axis, integrated from the angular velocity: a body spinning
// about the vertical at pi rad/s for 1 s has turned half a turn about it and none about
// the others; spinning about x, a quarter turn about roll.
TEST(ConstraintTerms, RootTurnIntegratesTheWorldAngularVelocity) {
  const char* xml = R"(<mujoco>
    <option timestep="0.001" gravity="0 0 0"/>
    <worldbody><body name="ball"><freejoint/><geom type="sphere" size="0.1"/></body></worldbody>
  </mujoco>)";
  const auto model = SharedModel::from_xml(xml, "ball");
  for (const int axis : {0, 2}) {
    SimWorker worker(model);
    mjData* d = worker.data();
    const mjModel* m = worker.model();
    d->qvel[3 + axis] = axis == 2 ? M_PI : 0.5 * M_PI;  // body frame = world frame at the start
    mj_forward(m, d);
    RootTurn turn;
    for (int k = 0; k < 1000; ++k) {
      mj_step(worker.model(), d);
      turn.add_step(d->xmat + 9, d->qvel + 3, m->opt.timestep);
    }
    EXPECT_NEAR(axis == 2 ? turn.vertical : turn.roll, axis == 2 ? M_PI : 0.5 * M_PI, 1e-9);
    EXPECT_NEAR(axis == 2 ? turn.roll : turn.vertical, 0.0, 1e-9);
    EXPECT_NEAR(turn.pitch, 0.0, 1e-9);
  }
}

// A half turn about the vertical scores as turned, and a jump that does not turn pays
// the miss; roll likewise. The flight turns are what the rollout measured.
TEST(ConstraintTerms, RotationAboutRollAndTheVertical) {
  const std::string entries = R"(
[[constraints]]
kind = "rotation"
axis = "vertical"
turns = 0.5
tolerance = 0.4
penalty = 1000.0

[[constraints]]
kind = "rotation"
axis = "roll"
turns = 0.0
tolerance = 0.3
penalty = 1000.0
)";
  const Task task = load_task(as_list_form("jump_backwards", entries).string());
  const RotationConstraint* vertical = find_rotation(task.constraints, RotationAxis::kVertical);
  ASSERT_NE(vertical, nullptr);
  EXPECT_EQ(vertical->turns, 0.5);
  MotionSummary s;
  s.took_off = s.landed = s.settled = true;
  s.feet_x = s.touchdown_feet_x = -0.8;
  s.vertical_flight = M_PI - 0.3;  // half a turn, 0.3 rad short: within the tolerance
  s.roll_flight = 0.1;
  EXPECT_EQ(evaluate_constraints(task, s).total, 0.0);
  EXPECT_NEAR(constraint_margin(task, s), 0.2 * (0.4 - 0.3), 1e-12);  // the vertical's slack, 0.1 rad
  s.vertical_flight = 0.0;  // no turn: pi - 0.4 rad beyond the tolerance
  ConstraintReport r = evaluate_constraints(task, s);
  const double d = M_PI - 0.4;
  EXPECT_NEAR(r.total, 1000 + 5000 * d * d, 1e-6);
  EXPECT_EQ(r.terms[r.terms.size() - 2].name, "rotation_vertical");
  s.vertical_flight = M_PI;
  s.roll_flight = -0.5;  // rolled 0.2 rad beyond the tolerance
  r = evaluate_constraints(task, s);
  EXPECT_NEAR(r.total, 1000 + 5000 * 0.04, 1e-6);
  EXPECT_EQ(r.terms.back().name, "rotation_roll");
  s.landed = false;  // no flight: the fall term covers it
  EXPECT_EQ(evaluate_constraints(task, s).terms.back().penalty, 0.0);

  // The input motion jumps backwards turning little (0.35 rad about the vertical, its
  // arms' swing): what the rollout measured scores.
  const TaskEvaluator ev(task);
  const Evaluation e = evaluate_m0(ev);
  ASSERT_TRUE(e.summary.landed);
  EXPECT_LT(std::fabs(e.summary.vertical_flight), 0.5);
  EXPECT_LT(std::fabs(e.summary.roll_flight), 0.5);
  for (const ConstraintTerm& t : e.report.terms) {
    if (t.name == "rotation_vertical") {
      EXPECT_NEAR(t.violation, std::fabs(e.summary.vertical_flight - M_PI) - 0.4, 1e-12);
    }
    if (t.name == "rotation_roll") {
      EXPECT_EQ(t.violation, 0.0);
    }
  }
}

// The planar human turns only about pitch: asking it for roll or the vertical is refused
// in one line, by the loader and by the tool (exit code 2).
TEST(ConstraintTerms, PlanarCharacterRefusesRollAndVertical) {
  const std::string roll = with_entries("jump_high", "planar_roll",
                                        "[[constraints]]\nkind = \"rotation\"\naxis = \"roll\"\nturns = 1.0\n"
                                        "tolerance = 0.5\npenalty = 1000.0\n");
  const std::string message =
      " constraints[0].axis: expected \"pitch\": the planar character \"human2d\" turns only about its lateral "
      "axis, got \"roll\"";
  EXPECT_EQ(error_of(roll), message);
  const cli_test::CliResult r =
      cli_test::run_cli("simulate " + roll + " --no-film --out " + (fs::path(roll).parent_path() / "planar_roll_out").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find(roll + ":" + message), std::string::npos) << r.output;
  const std::string vertical = with_entries("jump_high", "planar_vertical",
                                            "[constraints]\nweight = 5000.0\nfall_penalty = 100000.0\n"
                                            "rotation = { axis = \"vertical\", turns = 0.5, tolerance = 0.5, penalty = 1.0 }\n");
  EXPECT_EQ(error_of(vertical), " constraints.rotation.axis: expected \"pitch\": the planar character \"human2d\" turns "
                                "only about its lateral axis, got \"vertical\"");
}

// Every bad entry of the list form, and of the new keys, in one line naming the field.
TEST(ConstraintTerms, BadEntriesAreRefused) {
  auto bad = [](const std::string& name, const std::string& entries) {
    return error_of(with_entries("jump_backwards", name, entries));
  };
  EXPECT_EQ(bad("no_kind", "[[constraints]]\ncenter = 1.0\n"), " constraints[0].kind: expected a string (missing)");
  EXPECT_EQ(bad("unknown_kind", "[[constraints]]\nkind = \"height\"\n"),
            " constraints[0].kind: expected one of \"landing\", \"on_box\", \"clearance\", \"min_length\", "
            "\"peak_height\", \"rotation\", \"pitch\", \"foot_slip\", \"fall\", \"half_timestep\", got \"height\"");
  EXPECT_EQ(bad("unknown_key", "[[constraints]]\nkind = \"landing\"\ncenter = 1.0\nhalf_width = 0.1\nwidth = 2\n"),
            " constraints[0].width: expected no such key (unknown key; known keys: center, half_width, lateral, radius, "
            "weight)");
  EXPECT_EQ(bad("twice", "[[constraints]]\nkind = \"pitch\"\nmax = 0.5\n[[constraints]]\nkind = \"pitch\"\nmax = 0.6\n"),
            " constraints[1].kind: expected each kind once, \"pitch\" is listed twice");
  const std::string turn = "[[constraints]]\nkind = \"rotation\"\naxis = \"vertical\"\nturns = 0.5\ntolerance = 0.4\npenalty = 1.0\n";
  EXPECT_EQ(bad("axis_twice", turn + turn), " constraints[1].axis: expected one rotation constraint per axis, \"vertical\" repeats");
  EXPECT_EQ(bad("bad_axis", "[[constraints]]\nkind = \"rotation\"\naxis = \"yaw\"\n"),
            " constraints[0].axis: expected \"pitch\", \"roll\" or \"vertical\", got \"yaw\"");
  EXPECT_EQ(bad("flight_twist", turn + "min_flight = 1.0\n"),
            " constraints[0].min_flight: expected min_flight only with axis = \"pitch\" (a roll or vertical turn is "
            "measured in the air)");
  EXPECT_EQ(bad("weight", "[[constraints]]\nkind = \"pitch\"\nmax = 0.5\nweight = -1\n"),
            " constraints[0].weight: expected a number in [1e-06, 1e+09], got -1");
  EXPECT_EQ(bad("half_keys", "[[constraints]]\nkind = \"half_timestep\"\nfactor = 0.5\n"),
            " constraints[0].factor: expected no key: the half-timestep check has no settings");
  EXPECT_EQ(bad("allow_type", "[[constraints]]\nkind = \"fall\"\nallow_contact = \"hands\"\n"),
            " constraints[0].allow_contact: expected an array of strings");
  EXPECT_EQ(bad("fall_penalty", "[[constraints]]\nkind = \"fall\"\npenalty = 0\n"),
            " constraints[0].penalty: expected a number in [1e-06, 1e+12], got 0");
  // A walk meets only what a walk can: its steps, the foot slip, the fall rules.
  EXPECT_EQ(error_of(with_entries("silly_walk", "walk_landing", "[[constraints]]\nkind = \"landing\"\ncenter = 1.0\nhalf_width = 0.2\n")),
            " constraints[0]: expected a constraint a walk can meet (foot_slip, fall, half_timestep), got \"landing\"");
  // Bodies allowed to touch are bodies of the character, checked with its model.
  auto refused_by_scene = [](const std::string& task, const std::string& name, const std::string& entries) {
    try {
      TaskEvaluator ev(load_task(with_entries(task, name, entries)));
    } catch (const UserError& e) {
      const std::string what = e.what();
      return what.substr(what.find(": ") + 1);
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(refused_by_scene("jump_backwards", "allow_paw", "[[constraints]]\nkind = \"fall\"\nallow_contact = [\"paw\"]\n"),
            " constraints[0].allow_contact: expected \"hands\" or the name of a body of the character, got \"paw\"");
  EXPECT_EQ(refused_by_scene("robot_jump", "allow_robot_hands",
                             "[[constraints]]\nkind = \"landing\"\ncenter = 4.0\nradius = 0.75\n"
                             "[[constraints]]\nkind = \"fall\"\nallow_contact = [\"hands\"]\n"),
            " constraints[1].allow_contact: expected body names: the character \"robot3d\" has no hands");
}

// A hand on the ground is a fall unless the task lists it (the hands, or the hand's body);
// any other body that is not a foot still is.
TEST(ConstraintTerms, AHandOnTheGroundIsAFallUnlessListed) {
  const std::string file = test_files::task_variant("jump_high", "hands_fall", {}, {}).string();
  const std::string hands = test_files::task_variant("jump_high", "hands_allowed", {}, {{"constraints", "allow_contact = [\"hands\"]"}}).string();
  const std::string left = test_files::task_variant("jump_high", "left_hand_allowed", {}, {{"constraints", "allow_contact = [\"hand_l\"]"}}).string();
  const TaskEvaluator plain(load_task(file)), allowed(load_task(hands)), only_left(load_task(left));
  EXPECT_EQ(allowed.task().constraints.allow_contact, std::vector<std::string>{"hands"});
  const mjModel* m = plain.model().get();
  const auto worker = plain.make_worker();
  mjData* d = worker->data();
  mj_forward(m, d);
  // One contact of a body with the floor, as MuJoCo reports it.
  auto touching = [&](const char* geom) {
    d->ncon = 1;
    d->contact[0] = mjContact{};
    d->contact[0].geom1 = mj_name2id(m, mjOBJ_GEOM, "floor");
    d->contact[0].geom2 = mj_name2id(m, mjOBJ_GEOM, geom);
    ASSERT_GE(d->contact[0].geom2, 0) << geom;
  };
  RolloutTerms none(plain.task(), m, plain.body()), both(allowed.task(), m, allowed.body()),
      one(only_left.task(), m, only_left.body());
  touching("hand_l");
  EXPECT_TRUE(scan_contacts(m, d, plain.body()).non_foot);
  EXPECT_TRUE(none.contact_is_fall(m, d));
  EXPECT_FALSE(both.contact_is_fall(m, d));
  EXPECT_FALSE(one.contact_is_fall(m, d));
  touching("hand_r");
  EXPECT_FALSE(both.contact_is_fall(m, d));
  EXPECT_TRUE(one.contact_is_fall(m, d));
  touching("head");
  EXPECT_TRUE(both.contact_is_fall(m, d));
  touching("foot_l");
  EXPECT_FALSE(touches_outside(m, d, plain.body(), {}));
  d->ncon = 0;

  // The input motion never touches with anything but its feet: the same rollout either way.
  const Evaluation a = evaluate_m0(plain), b = evaluate_m0(allowed);
  EXPECT_EQ(a.constraint, b.constraint);
  EXPECT_EQ(a.stats.steps, b.stats.steps);
}

}  // namespace
}  // namespace diverse
