// Writes the checkpoint target's seed input to the path given: the checkpoint of a toy
// run (N = 2, popsize 4) after 3 generations, in the form `diverse run` writes it.
#include <cstdio>

#include "core/thread_pool.h"
#include "io/files.h"
#include "optimize/diversity.h"
#include "toy/toy.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: checkpoint_seed OUT.json\n");
    return 2;
  }
  const diverse::ToyProblem problem;
  diverse::ThreadPool pool(1);
  diverse::DiversityOptions options;
  options.variations = 2;
  options.popsize = 4;
  options.max_generations = 10;
  diverse::DiversityOptimizer optimizer(problem, options, pool);
  for (int g = 0; g < 3; ++g) optimizer.step();
  nlohmann::json checkpoint = {{"format", "diverse.run_checkpoint"},
                               {"wall_seconds", 1.5},
                               {"vary", {"control"}},
                               {"optimizer", optimizer.checkpoint()}};
  diverse::write_json_atomic(argv[1], checkpoint);
  return 0;
}
