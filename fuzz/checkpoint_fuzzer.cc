// libFuzzer target: the checkpoint reader (`diverse resume DIR`).
//
// One input is one checkpoint.json. It is read as `diverse resume` reads it
// (read_run_checkpoint) and the optimizer restored from it (restore_optimizer), on the
// paper's 2-D toy problem instead of a task, so that the re-evaluation of the stored
// sets costs microseconds rather than rollouts; everything the reader checks of the
// optimizer's state (options, CMA-ES states, points, counters, log, paths) is the same.
// Every bad file must end in UserError.
#include <cstdint>

#include "core/error.h"
#include "core/thread_pool.h"
#include "fuzz_support.h"
#include "run/checkpoint.h"
#include "toy/toy.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const diverse::fuzz::Scratch scratch("run", "");
  static const diverse::ToyProblem problem;
  static diverse::ThreadPool pool(1);
  const std::string path = scratch.write("checkpoint.json", data, size);
  try {
    double wall = 0;
    const nlohmann::json state = diverse::read_run_checkpoint(path, false, &wall);
    diverse::restore_optimizer(problem, state, pool, path);
  } catch (const diverse::UserError&) {
  }
  return 0;
}
