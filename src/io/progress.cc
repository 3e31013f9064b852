#include "io/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace diverse {

ProgressReporter::ProgressReporter(std::FILE* out, long long total_generations, int every)
    : out_(out),
      total_(total_generations),
      every_(std::max(1, every)),
      live_(::isatty(::fileno(out)) != 0),
      start_(std::chrono::steady_clock::now()) {}

std::string ProgressReporter::format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long long s = std::llround(seconds);
  char buffer[32];
  if (s >= 3600)
    std::snprintf(buffer, sizeof buffer, "%lldh%02lldm", s / 3600, (s % 3600) / 60);
  else if (s >= 60)
    std::snprintf(buffer, sizeof buffer, "%lldm%02llds", s / 60, s % 60);
  else
    std::snprintf(buffer, sizeof buffer, "%llds", s);
  return buffer;
}

std::string ProgressReporter::format_line(const DiversityRecord& record,
                                          long long total_generations,
                                          double evaluations_per_second, double seconds_left) {
  char buffer[96];
  std::snprintf(buffer, sizeof buffer, "gen %lld/%lld  D %.4g  best %.4g", record.generation,
                total_generations, record.D, record.best_D);
  std::string line = buffer;
  // C and dmin of the variations (M_0 is fixed and left out).
  line += "  C [";
  for (Eigen::Index i = 1; i < record.constraint.size(); ++i) {
    std::snprintf(buffer, sizeof buffer, "%s%.3g", i > 1 ? " " : "", record.constraint[i]);
    line += buffer;
  }
  line += "]  dmin [";
  for (Eigen::Index i = 1; i < record.dmin.size(); ++i) {
    std::snprintf(buffer, sizeof buffer, "%s%.3g", i > 1 ? " " : "", record.dmin[i]);
    line += buffer;
  }
  std::snprintf(buffer, sizeof buffer, "]  %.0f eval/s", evaluations_per_second);
  line += buffer;
  if (record.simulation_steps > 0) {
    std::snprintf(buffer, sizeof buffer, "  %.1fM steps", 1e-6 * static_cast<double>(record.simulation_steps));
    line += buffer;
  }
  std::snprintf(buffer, sizeof buffer, "  left %s", format_duration(seconds_left).c_str());
  line += buffer;
  return line;
}

void ProgressReporter::on_record(const DiversityRecord& record, int variations) {
  // A generation ends with the last variation's step (joint: its only step).
  if (record.variation != 0 && record.variation != variations) return;
  const auto now = std::chrono::steady_clock::now();
  if (start_evaluations_ < 0) {
    // The first report measures from here, so a resumed run's rate is its own.
    start_ = now;
    start_evaluations_ = record.evaluations;
    start_generation_ = record.generation;
  }
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const long long done_generations = record.generation - start_generation_;
  const double rate = elapsed > 0 ? (record.evaluations - start_evaluations_) / elapsed : 0.0;
  const double left = done_generations > 0
                          ? elapsed / done_generations * static_cast<double>(total_ - record.generation)
                          : -1.0;
  const std::string line = format_line(record, total_, rate, left);
  if (live_) {
    std::fprintf(out_, "\r\033[K%s", line.c_str());
    line_open_ = true;
  } else if (record.generation % every_ == 0 || record.generation == total_) {
    std::fprintf(out_, "%s\n", line.c_str());
  }
  std::fflush(out_);
}

void ProgressReporter::finish(const std::string& message) {
  if (line_open_) std::fprintf(out_, "\n");
  line_open_ = false;
  if (!message.empty()) std::fprintf(out_, "%s\n", message.c_str());
  std::fflush(out_);
}

}  // namespace diverse
