// The controller types this build knows, by the name a task file's [controller] type
// gives. Every skill is a file run by the skill engine ("skill"); a controller that cannot
// be written as a skill file adds its line here and lives in its own files under control/.
#include <memory>
#include <vector>

#include "control/controller.h"
#include "control/skill_controller.h"

namespace diverse {

std::vector<std::unique_ptr<ControllerType>> builtin_controllers() {
  std::vector<std::unique_ptr<ControllerType>> types;
  types.push_back(std::make_unique<SkillControllerType>());
  return types;
}

}  // namespace diverse
