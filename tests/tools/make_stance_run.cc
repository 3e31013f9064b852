// Writes a run directory of 3D motions for the browser tests (tests/e2e/), see
// tests/support/stance_run.h:
//   make_stance_run DIR CHARACTER SECONDS VX,VY [VX,VY ...]   stance control, one motion per
//                                                            push (m/s), M0 first
//   make_stance_run DIR CHARACTER walk STEPS PARAMS [...]     SIMBICON walks, one per
//                                                            tasks/PARAMS file, M0 first
#include <cstdio>
#include <string>
#include <vector>

#include "support/stance_run.h"

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr,
                 "usage: make_stance_run DIR CHARACTER SECONDS VX,VY [VX,VY ...]\n"
                 "       make_stance_run DIR CHARACTER walk STEPS PARAMS [PARAMS ...]\n");
    return 2;
  }
  if (std::string(argv[3]) == "walk") {
    if (argc < 6) {
      std::fprintf(stderr, "make_stance_run: walk: expected STEPS and at least one PARAMS file\n");
      return 2;
    }
    std::vector<std::string> parameters(argv + 5, argv + argc);
    diverse::test_support::write_walk_run(argv[1], argv[2], parameters, std::stoi(argv[4]));
    std::printf("%s\n", argv[1]);
    return 0;
  }
  std::vector<std::array<double, 3>> pushes;
  for (int i = 4; i < argc; ++i) {
    double vx = 0, vy = 0;
    if (std::sscanf(argv[i], "%lf,%lf", &vx, &vy) != 2) {
      std::fprintf(stderr, "make_stance_run: %s: expected VX,VY\n", argv[i]);
      return 2;
    }
    pushes.push_back({vx, vy, 0.0});
  }
  diverse::test_support::write_stance_run(argv[1], argv[2], pushes, std::stod(argv[3]));
  std::printf("%s\n", argv[1]);
  return 0;
}
