// libFuzzer target: the task-file reader and the scene it builds.
//
// One input is one task file, placed in a copy of tasks/ (so the corpus's relative paths
// to characters and seed motions resolve). It is parsed (load_task) and, if it parses,
// turned into a TaskEvaluator: the scene MJCF with the task's objects is compiled, the
// character bound to it, the controller configured and the scene checked. Every bad
// file must end in UserError.
#include <cstdint>

#include "core/error.h"
#include "fuzz_support.h"
#include "task/evaluate.h"
#include "task/task.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const diverse::fuzz::Scratch scratch("tasks", "tasks");
  const std::string path = scratch.write("fuzz.toml", data, size);
  try {
    diverse::TaskEvaluator evaluator(diverse::load_task(path));
  } catch (const diverse::UserError&) {
  }
  return 0;
}
