// `diverse character FILE`: loads and validates a character (its character file, or the MJCF
// with its character file beside it) and prints what the controllers, constraints and
// metrics will see: root, links, mass, standing height, internal DOF, joint groups with their
// roles, joints, ranges and torque limits, feet, hands and shape parameters. Any problem is
// the one-line error of docs/guide/own-character.md (exit code 2).
//
//   diverse character assets/characters/human3d.toml
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "character/character.h"
#include "command.h"
#include "options.h"
#include "physics/model.h"

namespace diverse::cli {
namespace {

std::string range_text(const CharacterJoint& j) {
  if (!std::isfinite(j.lower) || !std::isfinite(j.upper)) return "unlimited";
  char text[64];
  std::snprintf(text, sizeof text, "[%.3g, %.3g] rad", j.lower, j.upper);
  return text;
}

void install_character(CLI::App& app) {
  auto file = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("character", "Load and validate a character, and describe it");
  cmd->footer("Examples:\n"
              "  diverse character assets/characters/robot3d.toml\n"
              "  diverse character examples/own-character/tailwalker.toml");
  cmd->add_option("file", *file, "Character file (.toml), or an MJCF with its character file beside it")
      ->required();
  cmd->callback([file] {
    const auto spec = std::make_shared<const CharacterSpec>(load_character_file(resolve_character_file(*file)));
    const auto model = SharedModel::from_file(spec->model);
    const mjModel* m = model->get();
    const Character c = bind_character(spec, m, spec->model);
    auto body_name = [&](int b) { return std::string(mj_id2name(m, mjOBJ_BODY, b)); };
    std::printf("character %s: %s\n", spec->name.c_str(), spec->file.c_str());
    if (!spec->description.empty()) std::printf("  %s\n", spec->description.c_str());
    std::printf("  model %s, timestep %g s\n", spec->model.c_str(), m->opt.timestep);
    std::printf("  root %s in '%s' (unactuated)\n", to_string(c.root), spec->root_body.c_str());
    std::printf("  %zu links, %.3f kg, %.3f m tall standing, %d internal DOF in %zu groups\n", c.links.size(),
                c.total_mass, c.height, c.dof(), c.groups.size());
    for (const JointGroup& g : c.groups) {
      std::printf("  group %-12s %-8s %-10s wja %-4g kp %-6g kd %-6g\n", g.name.c_str(), to_string(g.role),
                  to_string(g.plane), g.wja, g.kp, g.kd);
      for (int k : g.joints) {
        const CharacterJoint& j = c.joints[static_cast<size_t>(k)];
        const char* side = j.side == Side::kLeft ? "left" : j.side == Side::kRight ? "right" : "centre";
        std::printf("    %-16s %-6s %-22s limit %g Nm\n", j.name.c_str(), side, range_text(j).c_str(),
                    j.torque_limit);
      }
    }
    std::printf("  feet %s, %s\n", body_name(c.feet[0]).c_str(), body_name(c.feet[1]).c_str());
    if (c.hands.empty()) {
      std::printf("  no hands\n");
    } else {
      std::printf("  hands %s, %s\n", body_name(c.hands[0]).c_str(), body_name(c.hands[1]).c_str());
    }
    if (!spec->has_shape()) {
      std::printf("  no shape parameters (control-only diversity)\n");
      return;
    }
    for (const ShapeGroupSpec& s : spec->shape) {
      std::string links;
      for (const std::string& l : s.links) links += (links.empty() ? "" : ", ") + l;
      std::printf("  shape.%-10s scale in [%g, %g]: %s\n", s.name.c_str(), s.min, s.max, links.c_str());
    }
  });
}

const bool registered = register_command(75, install_character);

}  // namespace
}  // namespace diverse::cli
