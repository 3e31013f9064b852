// Ranges of command-line options.
//
// Every numeric option of every subcommand has a documented range (docs/reference/reliability.md);
// these CLI11 validators enforce it on the text the user typed, before conversion, so
// that a value out of range, a non-number, NaN, infinity or a number too large for its
// type is one line "OPTION: expected ..., got 'TEXT'" and exit code 2, never a silent
// default, a wrapped integer or an internal error:
//
//   cmd->add_option("--n", args->n, "...")->check(integer_in(1, kMaxVariations));
//   cmd->add_option("--sigma0", args->sigma0, "...")->check(number_in(0, 1, Bound::kOpen));
#pragma once

#include <CLI/CLI.hpp>

namespace diverse::cli {

// Upper limits shared by several subcommands.
constexpr long long kMaxThreads = 256;        // --threads (0 = one per core)
constexpr long long kMaxVariations = 100;     // --n, as a task file's `variations`
constexpr long long kMaxGenerations = 1000000;
constexpr long long kMaxPopsize = 1000;

enum class Bound { kClosed, kOpen };

// A decimal integer in [lo, hi].
CLI::Validator integer_in(long long lo, long long hi);
// A decimal unsigned integer (a seed): 0 to 2^64 - 1, no sign.
CLI::Validator unsigned_integer();
// A finite number in [lo, hi], or (lo, hi] when `low` is kOpen.
CLI::Validator number_in(double lo, double hi, Bound low = Bound::kClosed);

}  // namespace diverse::cli
