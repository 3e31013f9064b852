// libFuzzer target: the parameter-file reader (`diverse simulate TASK --params FILE`,
// a task's m0 and seed base).
//
// One input is one parameter file for jump_high's controller, read as plain
// parameters and as parameters with shape scales (load_parameters,
// load_shaped_parameters). Every bad file must end in UserError.
#include <cstdint>
#include <memory>

#include "core/error.h"
#include "fuzz_support.h"
#include "task/evaluate.h"
#include "task/task.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const diverse::fuzz::Scratch scratch("params", "");
  static const auto evaluator = std::make_unique<diverse::TaskEvaluator>(
      diverse::load_task(std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_high.toml"));
  const std::string path = scratch.write("fuzz.json", data, size);
  try {
    evaluator->load_parameters(path);
  } catch (const diverse::UserError&) {
  }
  try {
    evaluator->load_shaped_parameters(path);
  } catch (const diverse::UserError&) {
  }
  return 0;
}
