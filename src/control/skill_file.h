// Skill files (skills/NAME.toml): a skill as data, run by the skill engine
// (control/skill_controller.h). docs/reference/skills.md describes every field.
//
//   SkillFile skill = load_skill_file("skills/jump2d.toml");   // the file alone
//   SkillBinding b = bind_skill(skill, body, model);          // against one character
//
// A skill is a list of phases. Each phase names a set of joint targets (a number, a named
// optimized parameter with its range, or a curve over the phase; a joint angle or the
// world pitch of the link above or below the joint; left and right alike or each its own),
// a set of PD gains, a duration (a number, a parameter, or predicted from the flight), the
// feedback modules it switches on, and its transitions: the next phase and the event that
// leads there (the duration elapsed, a time, contact made or lost, lift-off, touch-down,
// the COM's peak, a feature crossing a threshold, a turn completed, the landing spotted).
// The [events] table names the phases that mark the motion's events (push, take-off,
// peak, landing) and the events the film strip shows.
//
// Parameters. The optimizer varies the named parameters, each normalized to [0, 1] over
// its range (params/parameters.h), in this order: phase by phase, the targets in the
// character's group order and then the gains (kp, kd) in the same order; then the phase
// durations, phase by phase; then the modules' parameters, module by module, settings in
// alphabetical order. A name used twice is one parameter (its ranges must agree).
//
// load_skill_file() checks what the file alone can tell: unknown keys, wrong types, a
// transition to a phase that does not exist, a phase that can never be left, an empty
// range, a module's missing setting. bind_skill() checks it against a character: a group,
// role or body the character does not have, the root kind, the leg pairs. Every error is
// one UserError line "FILE: line N: FIELD: expected ...".
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <map>
#include <string>
#include <vector>

#include "character/character.h"
#include "control/skill_feature.h"
#include "params/parameters.h"

namespace diverse {

// A number, a named parameter (with its range) or a piecewise-linear curve over the
// phase's normalized time s in [0, 1].
struct SkillValue {
  // kStanding: the joint's angle in the model's standing pose (qpos0), written "standing".
  enum class Kind { kNumber, kParam, kCurve, kStanding };
  Kind kind = Kind::kNumber;
  double number = 0;
  std::string param;           // as written: may hold "{group}"; phases prefix "PHASE."
  bool has_range = false;      // a parameter without a range takes its joint's
  double lower = 0, upper = 0;
  std::string unit;
  bool sides = false;          // a parameter: NAME_left and NAME_right for a left/right pair
  std::vector<std::array<double, 2>> curve;  // knots (s, value), s increasing from 0 to 1
  int world = -1;       // a side's own `world` (a SkillTarget::World), -1: the entry's
  bool mirror = false;  // negated while the right leg swings (a centre link's roll)
  int line = 0;
};

// One entry of a target set. `selector`: a group name, a role ("hip"), the topmost group
// of a role ("waist.top"), the groups of a role in a plane ("hip.sagittal"), "other" (every
// group no other entry names), or "root" (the free root's pitch and roll in the heading
// frame, control/heading_frame.h).
struct SkillTarget {
  std::string selector;
  // A joint angle; the world pitch of the link above or below the joint (planar
  // characters); the link below the joint in the heading frame, all its hinges together
  // (free roots; angles relative to standing); or, for a free root, a world pitch a
  // "stance3d" module holds through the stance legs: the root's (kRoot), the torso's
  // (kTorso), each sole's (kSole).
  enum class World { kJoint, kParent, kChild, kHeading, kRoot, kTorso, kSole };
  World world = World::kJoint;
  bool from_standing = false;  // relative = "standing": added to qpos0, kept in the joint's range
  bool sided = false;  // left and right given apart (or, with by_role, swing and stance)
  bool by_role = false;  // left holds the swing leg's side, right the stance leg's
  SkillValue both, left, right;
  SkillValue pitch, roll;  // "root"
  int line = 0;
};

struct SkillGain {
  std::string selector;
  SkillValue kp, kd;  // Nm/rad, Nm s/rad
  int line = 0;
};

// One condition of a transition (all of a transition's conditions must hold).
struct SkillCondition {
  // duration, time, contact, touchdown, liftoff, contact_made, contact_lost, peak,
  // turned, spotted, feature
  std::string kind;
  double after = 0;        // time: s since the phase began
  double airborne = 0.01;  // liftoff: s without contact, the COM rising
  double angle = 0;        // turned: rad of root pitch since take-off
  std::string body;        // contact_made, contact_lost: an MJCF body of the character
  std::string foot;        // contact_made, contact_lost: instead of a body, "swing", "stance", "left", "right"
  std::string feature;     // feature: com_x, com_z, com_vx, com_vz, pitch, pitch_rate
  bool above = true;       // feature: crosses above (true) or below `threshold`
  // `kind` and `feature` as the engine tries them every step (set with them when the file
  // is read: no string is compared in a step).
  enum class Type { kDuration, kTime, kContact, kLiftoff, kContactMade, kContactLost, kPeak, kTurned, kSpotted, kFeature };
  Type type = Type::kDuration;
  using Feature = SkillFeature;
  Feature which = Feature::kComX;
  double threshold = 0;
};

struct SkillTransition {
  std::string to;
  std::vector<SkillCondition> on;
  std::vector<std::string> passes;  // phases that count as begun at the same moment
  bool gave_up = false;             // the motion gave up (a push that never took off)
  int line = 0;
};

struct SkillDuration {
  enum class Kind { kNone, kValue, kPredict };
  Kind kind = Kind::kNone;
  SkillValue value;       // kValue (s)
  std::string predict;    // kPredict: "rise" (v_z / g), "fall" (from the peak), "touchdown" (from here)
  double at_most = 0;     // s; > 0 caps the prediction
  int line = 0;
};

struct SkillPhase {
  std::string name;
  std::string parameters;      // the prefix of its parameters' names ("" : the name)
  int swing = -1;              // the leg that swings (0 left, 1 right), -1 none
  std::string targets, gains;  // set names; gains "" keeps the character's
  bool interpolate = true;     // false: targets at once
  // Where its targets start: those last commanded (kTargets), the previous phase's goals
  // (kGoals), the pose it begins in (kPose), or its own goals (kGoals of this phase: kNone).
  enum class From { kTargets, kGoals, kPose, kNone };
  From from = From::kTargets;
  SkillDuration duration;
  std::vector<std::string> modules;
  std::vector<SkillTransition> next;
  int line = 0;
};

struct SkillModuleSpec {
  std::string name, kind;
  std::map<std::string, SkillValue> settings;  // numbers, booleans as 0/1, or parameters
  std::map<std::string, std::string> words;    // settings that take a word (a plane)
  int line = 0;
};

struct SkillFile {
  std::string file;
  std::string name, description;
  RootKind root = RootKind::kPlanar;
  std::vector<std::string> pairs;  // roles that must be left/right pairs
  int root_line = 1, pairs_line = 1;  // where they are written (1 when defaulted)
  bool walk = false;        // kind = "walk": the task counts steps (task/walk_task.h), not a jump's events
  bool start_pose = false;  // start = "first_phase": the rollout starts in the first phase's pose
  std::string push, takeoff, peak, landing;  // phase names; "" when none
  std::vector<std::string> film_strip;       // events shown
  std::map<std::string, std::vector<SkillTarget>> target_sets;
  std::map<std::string, std::vector<SkillGain>> gain_sets;
  std::vector<SkillModuleSpec> modules;
  std::vector<SkillPhase> phases;
  int phase_index(const std::string& name) const;   // -1 if none
  int module_index(const std::string& name) const;  // -1 if none
};

// The module kinds the engine knows, with their settings: {kind, required, optional}.
struct SkillModuleKind {
  const char* kind;
  std::vector<const char*> required, optional;
  const char* what;  // one line, for `diverse skill show` and messages
  // Settings that take one of a few words: {setting, {word, ...}} (required).
  std::vector<std::pair<const char*, std::vector<const char*>>> words = {};
  // Settings that name joint groups, as a target set's selectors (required).
  std::vector<const char*> selectors = {};
};
const std::vector<SkillModuleKind>& skill_module_kinds();
// The kind called `kind`, or null.
const SkillModuleKind* find_module_kind(const std::string& kind);

// Parses and checks a skill file. Throws UserError.
SkillFile load_skill_file(const std::string& path);
// `overrides` (a task's [controller] table): number settings of the skill's modules,
// { MODULE = { SETTING = NUMBER } }. Throws UserError naming `r`'s file.
class TomlReader;
void override_skill_settings(SkillFile& skill, const TomlReader& r, const std::vector<std::string>& own_keys);

// The skill resolved against one character: every parameter, and per phase every joint's
// target and gains. Throws UserError "SKILLFILE: line N: FIELD: expected ..." when the
// character lacks a group, role or body the skill names.
struct SkillJointTarget {
  SkillTarget::World world = SkillTarget::World::kJoint;
  const SkillValue* value = nullptr;  // into the SkillFile
  int param = -1;                     // index into params when a parameter
  double sign = 1;                    // -1: a mirrored value while the right leg swings
  bool from_standing = false;         // the value added to qpos0, within the joint's range
};
struct SkillJointGain {
  int kp_param = -1, kd_param = -1;   // parameters, or -1
  double kp = 0, kd = 0;              // when not parameters (the character's, or numbers)
};
struct SkillPhaseBinding {
  std::vector<SkillJointTarget> targets;  // per Character::joints entry
  std::vector<SkillJointGain> gains;      // per Character::joints entry
  int duration_param = -1;
  std::vector<int> modules;               // indices into SkillFile::modules
  int swing = -1;                         // the swinging leg (0 left, 1 right), -1 none
  bool swing_lands = false;               // a transition on the swing foot's contact made
  bool root = false;                      // root pitch and roll targets given
  SkillJointTarget root_pitch, root_roll;  // world = kHeading
};
struct SkillBinding {
  std::vector<ParamSpec> params;
  std::vector<SkillPhaseBinding> phases;
  // Per module: setting name -> parameter index (-1 when a number).
  std::vector<std::map<std::string, int>> module_params;
};
// `m` is the character's model (for body names); may be null to skip body checks.
SkillBinding bind_skill(const SkillFile& skill, const Character& body, const mjModel* m);

// The groups a selector names in `body` (empty if none).
std::vector<int> select_groups(const std::string& selector, const Character& body);

}  // namespace diverse
