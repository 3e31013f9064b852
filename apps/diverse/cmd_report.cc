// `diverse report RUN...`: one Markdown table row per finished run, read from the runs'
// summary.json files. Used by the reproduction scripts in scripts/.
//
//   diverse report runs/repro/*
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "command.h"
#include "options.h"
#include "core/error.h"
#include "io/files.h"

namespace diverse::cli {
namespace {

std::string format(const char* fmt, double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, fmt, v);
  return buffer;
}

void install_report(CLI::App& app) {
  auto runs = std::make_shared<std::vector<std::string>>();
  CLI::App* cmd = app.add_subcommand("report", "A Markdown table of finished runs");
  cmd->add_option("runs", *runs, "Run directories")->required();
  cmd->callback([runs] {
    // Every directory is checked before the table starts, so an error is the only output.
    for (const std::string& dir : *runs) {
      if (!std::filesystem::exists(std::filesystem::path(dir) / "summary.json"))
        throw UserError(dir + ": not a finished run (no summary.json)");
    }
    std::printf(
        "| run | task | metric | strategy | seed | generations | minutes | D | C of M1..MN | "
        "min d among M0..MN | mean d among M1..MN | d(M0, nudged M0) |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (const std::string& dir : *runs) {
      const std::filesystem::path summary_path = std::filesystem::path(dir) / "summary.json";
      if (!std::filesystem::exists(summary_path))
        throw UserError(dir + ": not a finished run (no summary.json)");
      const nlohmann::json s = read_json(summary_path);
      try {
        const std::string metric = s.at("metric").get<std::string>();
        const auto d = s.at("distances").at(metric).get<std::vector<std::vector<double>>>();
        const std::size_t n = d.size();
        double min_all = std::numeric_limits<double>::infinity(), mean_var = 0;
        int pairs = 0;
        for (std::size_t i = 0; i < n; ++i)
          for (std::size_t j = i + 1; j < n; ++j) {
            min_all = std::min(min_all, d[i][j]);
            if (i >= 1) {
              mean_var += d[i][j];
              ++pairs;
            }
          }
        if (pairs > 0) mean_var /= pairs;
        std::string constraints;
        for (const auto& m : s.at("motions"))
          if (m.at("index").get<int>() > 0)
            constraints += (constraints.empty() ? "" : " ") + format("%.3g", m.at("constraint").get<double>());
        std::printf("| %s | %s | %s | %s | %llu | %lld | %s | %s | %s | %s | %s | %s |\n",
                    std::filesystem::path(dir).filename().string().c_str(),
                    s.at("task").get<std::string>().c_str(), metric.c_str(),
                    s.at("strategy").get<std::string>().c_str(),
                    static_cast<unsigned long long>(s.at("seed").get<std::uint64_t>()),
                    s.at("generations").get<long long>(),
                    format("%.1f", s.at("timing").at("wall_seconds").get<double>() / 60).c_str(),
                    format("%.4g", s.at("D").get<double>()).c_str(), constraints.c_str(),
                    format("%.4g", min_all).c_str(), format("%.4g", mean_var).c_str(),
                    format("%.3g", s.value("nudged_m0_distance", 0.0)).c_str());
      } catch (const nlohmann::json::exception& e) {
        throw UserError(summary_path.string() + ": expected a summary written by `diverse run` (" +
                        e.what() + ")");
      }
    }
  });
}

const bool registered = register_command(45, install_report);

}  // namespace
}  // namespace diverse::cli
