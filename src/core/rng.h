// Deterministic, portable random numbers.
//
// xoshiro256** (Blackman and Vigna, 2018) seeded through splitmix64. Unlike the
// standard library's distributions, uniform() and normal() here produce the same
// sequence on every platform and compiler, so a seed means the same run everywhere.
// The whole state is four 64-bit words plus the cached Box-Muller deviate, so it
// serializes exactly for checkpoints.
//
// Streams: never share one Rng between threads. Derive an independent stream per
// piece of work with derive_seed(run_seed, a, b, ...), e.g. (seed, generation,
// variation, sample); results then never depend on thread count or scheduling.
#pragma once

#include <array>
#include <cstdint>
#include <initializer_list>

namespace diverse {

// Mixes a base seed with any number of integers into a new 64-bit seed (splitmix64).
std::uint64_t derive_seed(std::uint64_t seed, std::initializer_list<std::uint64_t> keys);

class Rng {
 public:
  struct State {
    std::array<std::uint64_t, 4> s{};
    bool has_spare = false;
    double spare = 0.0;
    bool operator==(const State&) const = default;
  };

  explicit Rng(std::uint64_t seed = 0);

  std::uint64_t next_u64();
  // Uniform in [0, 1) with 53 random bits.
  double uniform();
  // Standard normal deviate (polar Box-Muller; the second deviate is cached).
  double normal();

  const State& state() const { return state_; }
  void set_state(const State& state) { state_ = state; }

 private:
  State state_;
};

}  // namespace diverse
