// Writes a run directory of 3D stance motions for the browser tests (tests/e2e/):
//   make_stance_run DIR CHARACTER SECONDS VX,VY [VX,VY ...]
// one motion per push (the root's initial velocity in m/s), M0 first; see
// tests/support/stance_run.h.
#include <cstdio>
#include <string>
#include <vector>

#include "support/stance_run.h"

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: make_stance_run DIR CHARACTER SECONDS VX,VY [VX,VY ...]\n");
    return 2;
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
