#include "control/controller.h"

#include <map>

#include "core/error.h"

namespace diverse {

// Defined in control/builtin_controllers.cc: every controller type this build knows.
std::vector<std::unique_ptr<ControllerType>> builtin_controllers();

namespace {

const std::vector<std::unique_ptr<ControllerType>>& registry() {
  static const std::vector<std::unique_ptr<ControllerType>> types = builtin_controllers();
  return types;
}

}  // namespace

ContactState scan_contacts(const mjModel* m, const mjData* d, const Character& body) {
  ContactState c;
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& con = d->contact[i];
    if (con.exclude != 0) continue;  // in the margin gap: near, not touching
    for (int g : {con.geom1, con.geom2}) {
      const int b = m->geom_bodyid[g];
      if (b == 0 || m->body_rootid[b] != body.root_body) continue;
      c.any = true;
      int foot = -1;
      if (body.is_foot_geom(m, g, &foot)) {
        c.foot[static_cast<size_t>(foot)] = true;
      } else {
        c.non_foot = true;
      }
    }
  }
  return c;
}

const ControllerType& find_controller(const std::string& name, const std::string& where) {
  for (const auto& type : registry()) {
    if (name == type->name()) return *type;
  }
  std::string known;
  for (const auto& type : registry()) known += std::string(known.empty() ? "\"" : ", \"") + type->name() + "\"";
  throw UserError(where + ": expected one of " + known + ", got \"" + name + "\"");
}

std::vector<std::string> controller_names() {
  std::vector<std::string> names;
  for (const auto& type : registry()) names.emplace_back(type->name());
  return names;
}

JointDrive make_drive(const Character& body, SaturatedDrive saturated, Damping damping) {
  std::vector<DrivenJoint> joints;
  joints.reserve(body.joints.size());
  for (const CharacterJoint& j : body.joints) joints.push_back({j.actuator, j.dof, j.torque_limit});
  return JointDrive(std::move(joints), saturated, damping);
}

}  // namespace diverse
