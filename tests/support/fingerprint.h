// A fingerprint of a trajectory, bit for bit: FNV-1a over the bytes of every double, for
// tests that pin a rollout's qpos and ctrl at every step (skill_replay_test,
// skill_replay3d_test).
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

namespace diverse::test_files {

inline uint64_t fingerprint(const std::vector<double>& values) {
  uint64_t h = 1469598103934665603ull;
  for (double v : values) {
    unsigned char b[sizeof v];
    std::memcpy(b, &v, sizeof v);
    for (unsigned char c : b) h = (h ^ c) * 1099511628211ull;
  }
  return h;
}

}  // namespace diverse::test_files
