// Progress reporting for long optimizations.
//
// On a terminal: one live line, rewritten in place (generation, D, each variation's C
// and dmin, evaluations per second, estimated time left). Otherwise (a pipe, a log
// file, CI): quiet, line-oriented output, one line every `every` generations and at
// the end, so logs stay readable and greppable.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>

#include "optimize/diversity.h"

namespace diverse {

class ProgressReporter {
 public:
  // `out` is usually stderr; `live` forces the terminal style on or off (default:
  // isatty(out)). `total_generations` is the generation limit, for the time estimate.
  ProgressReporter(std::FILE* out, long long total_generations, int every = 10);
  void set_live(bool live) { live_ = live; }

  // Call after every step; reports at the end of a generation (the last variation's step).
  void on_record(const DiversityRecord& record, int variations);
  // Ends the live line and prints a final summary line.
  void finish(const std::string& message);

  // "1h02m", "4m12s", "9s".
  static std::string format_duration(double seconds);
  // The text of one report line (no newline), exposed for tests.
  static std::string format_line(const DiversityRecord& record, long long total_generations,
                                 double evaluations_per_second, double seconds_left);

 private:
  std::FILE* out_;
  long long total_;
  int every_;
  bool live_;
  bool line_open_ = false;
  std::chrono::steady_clock::time_point start_;
  long long start_evaluations_ = -1;
  long long start_generation_ = 0;
};

}  // namespace diverse
