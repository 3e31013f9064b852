// `diverse skill check FILE [--character C]`: reads a skill file (docs/reference/skills.md) and binds
// it to a character, as a task naming it would; any problem is one line naming the file, the
// line, the field and what was expected (exit code 2).
// `diverse skill show FILE [--character C]`: prints its phases with their targets, gains,
// durations, modules and transitions, its modules, and the parameters the optimizer varies
// for that character.
//
// Without --character, the planar human (a planar skill) or the 3D human (a free one), from
// the assets/characters/ folder beside the skill's folder.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "character/character.h"
#include "command.h"
#include "control/skill_file.h"
#include "core/error.h"
#include "physics/model.h"

namespace diverse::cli {
namespace {

struct SkillArgs {
  std::string file, character;
};

// The character the skill is checked against.
std::string character_for(const SkillFile& skill, const std::string& given) {
  if (!given.empty()) return resolve_character_file(given);
  const std::string name = skill.root == RootKind::kPlanar ? "human2d.toml" : "human3d.toml";
  const auto path = std::filesystem::path(skill.file).parent_path() / ".." / "assets" / "characters" / name;
  if (!std::filesystem::is_regular_file(path)) {
    throw UserError("--character: expected a character file (none given, and no " + path.lexically_normal().string() +
                    " beside the skill's folder)");
  }
  return path.lexically_normal().string();
}

struct Bound {
  SkillFile skill;
  std::shared_ptr<const CharacterSpec> spec;
  SkillBinding binding;
};

Bound bind(const SkillArgs& a) {
  Bound b;
  b.skill = load_skill_file(a.file);
  b.spec = std::make_shared<const CharacterSpec>(load_character_file(character_for(b.skill, a.character)));
  const auto model = SharedModel::from_file(b.spec->model);
  const Character body = bind_character(b.spec, model->get(), b.spec->model);
  b.binding = bind_skill(b.skill, body, model->get());
  return b;
}

std::string value_text(const SkillValue& v) {
  char text[96];
  switch (v.kind) {
    case SkillValue::Kind::kParam:
      if (!v.has_range) return "parameter " + v.param;
      std::snprintf(text, sizeof text, " in [%g, %g]", v.lower, v.upper);
      return "parameter " + v.param + text;
    case SkillValue::Kind::kCurve:
      return "curve of " + std::to_string(v.curve.size()) + " knots";
    default:
      std::snprintf(text, sizeof text, "%g", v.number);
      return text;
  }
}

std::string condition_text(const SkillCondition& c) {
  char text[128];
  if (c.kind == "time") std::snprintf(text, sizeof text, "time %g s", c.after);
  else if (c.kind == "liftoff") std::snprintf(text, sizeof text, "liftoff (%g s without contact, COM rising)", c.airborne);
  else if (c.kind == "turned") std::snprintf(text, sizeof text, "turned %g rad", c.angle);
  else if (c.kind == "contact_made" || c.kind == "contact_lost") std::snprintf(text, sizeof text, "%s %s", c.kind.c_str(), c.body.empty() ? ("of the " + c.foot + " foot").c_str() : c.body.c_str());
  else if (c.kind == "feature") std::snprintf(text, sizeof text, "%s %s %g", c.feature.c_str(), c.above ? ">=" : "<=", c.threshold);
  else return c.kind;
  return text;
}

void show(const Bound& b) {
  const SkillFile& s = b.skill;
  std::printf("skill %s: %s\n", s.name.c_str(), s.file.c_str());
  if (!s.description.empty()) std::printf("  %s\n", s.description.c_str());
  std::printf("  root %s; leg pairs:", to_string(s.root));
  for (const auto& p : s.pairs) std::printf(" %s", p.c_str());
  std::printf("\n  events: push %s, takeoff %s, peak %s, landing %s\n", s.push.empty() ? "-" : s.push.c_str(),
              s.takeoff.empty() ? "-" : s.takeoff.c_str(), s.peak.empty() ? "-" : s.peak.c_str(),
              s.landing.empty() ? "-" : s.landing.c_str());
  for (const SkillModuleSpec& m : s.modules) {
    std::printf("  module %s (%s):", m.name.c_str(), m.kind.c_str());
    for (const auto& [name, word] : m.words) std::printf(" %s = %s;", name.c_str(), word.c_str());
    for (const auto& [name, value] : m.settings) std::printf(" %s = %s;", name.c_str(), value_text(value).c_str());
    std::printf("\n");
  }
  for (const SkillPhase& p : s.phases) {
    std::printf("  phase %s: %s%stargets %s, gains %s, ", p.name.c_str(), p.swing < 0 ? "" : p.swing == 0 ? "the left leg swings, " : "the right leg swings, ",
                p.parameters.empty() ? "" : ("parameters " + p.parameters + ".*, ").c_str(), p.targets.c_str(),
                p.gains.empty() ? "the character's" : p.gains.c_str());
    if (p.duration.kind == SkillDuration::Kind::kValue) std::printf("duration %s", value_text(p.duration.value).c_str());
    else if (p.duration.kind == SkillDuration::Kind::kPredict) std::printf("duration predicted (%s)", p.duration.predict.c_str());
    else std::printf("no duration");
    if (!p.interpolate || p.duration.kind == SkillDuration::Kind::kNone) std::printf(", targets at once");
    for (const auto& m : p.modules) std::printf(", %s", m.c_str());
    std::printf("\n");
    for (const SkillTransition& t : p.next) {
      std::string on;
      for (const auto& c : t.on) on += (on.empty() ? "" : " and ") + condition_text(c);
      std::string passes;
      for (const auto& p2 : t.passes) passes += (passes.empty() ? ", passing " : ", ") + p2;
      std::printf("    -> %s on %s%s%s\n", t.to.c_str(), on.c_str(), passes.c_str(), t.gave_up ? " (gave up)" : "");
    }
  }
  std::printf("  %zu parameters for %s:\n", b.binding.params.size(), b.spec->file.c_str());
  for (const ParamSpec& p : b.binding.params) {
    std::printf("    %-24s [%g, %g] %s\n", p.name.c_str(), p.lower, p.upper, p.unit.c_str());
  }
}

void install_skill(CLI::App& app) {
  auto args = std::make_shared<SkillArgs>();
  CLI::App* cmd = app.add_subcommand("skill", "Check a skill file against a character, or show its phases and parameters");
  cmd->require_subcommand(1);
  cmd->footer("Examples:\n"
              "  diverse skill check skills/backflip.toml\n"
              "  diverse skill show skills/jump2d.toml --character examples/own-character/tailwalker.toml");
  CLI::App* check = cmd->add_subcommand("check", "Read a skill file and bind it to a character; report any problem");
  CLI::App* show_cmd = cmd->add_subcommand("show", "Print a skill's phases, transitions, modules and parameters");
  for (CLI::App* sub : {check, show_cmd}) {
    sub->add_option("file", args->file, "Skill file (.toml, docs/reference/skills.md)")->required();
    sub->add_option("--character", args->character,
                    "Character file (default: the planar or the 3D human, by the skill's root)");
  }
  check->callback([args] {
    const Bound b = bind(*args);
    std::printf("%s: skill %s binds to %s: %zu phases, %zu modules, %zu parameters\n", args->file.c_str(),
                b.skill.name.c_str(), b.spec->file.c_str(), b.skill.phases.size(), b.skill.modules.size(),
                b.binding.params.size());
  });
  show_cmd->callback([args] { show(bind(*args)); });
}

const bool registered = register_command(76, install_skill);

}  // namespace
}  // namespace diverse::cli
