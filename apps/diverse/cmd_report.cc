// `diverse report RUN...`: one Markdown table row per finished run, read from the runs'
// summary.json files. Used by the reproduction scripts in scripts/. Runs whose
// robustness was measured (RUN/robustness.json, `diverse robustness RUN`) add a second
// table after it: per motion, the share of perturbed rollouts of each kind that meet
// the task (robust/robustness.h). Runs whose summary has each motion's foot slip
// (task/foot_slip.h) add a table of it: per motion and side, the stances and how far the
// planted feet slid per stance (mean and largest) and at most how fast.
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
#include "robust/robustness.h"

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
  cmd->footer("Example:\n"
              "  diverse report runs/jump_high runs/backflip");
  cmd->add_option("runs", *runs, "Run directories")->required();
  cmd->callback([runs] {
    // Every directory is checked before the table starts, so an error is the only output.
    // The robustness of a run's motions (RUN/robustness.json, `diverse robustness RUN`) is
    // read now too, and tabled after the runs: per motion, the share of each kind of
    // perturbed rollouts that meet the task.
    std::vector<std::string> robustness_rows, slip_rows;
    for (const std::string& dir : *runs) {
      if (!std::filesystem::exists(std::filesystem::path(dir) / "summary.json"))
        throw UserError(dir + ": not a finished run (no summary.json)");
      const std::filesystem::path file = std::filesystem::path(dir) / "robustness.json";
      if (!std::filesystem::exists(file)) continue;
      const nlohmann::json r = read_json(file);
      if (!r.is_object() || r.value("format", std::string()) != "diverse.robustness")
        throw_field_error(file.string(), "format", "expected \"diverse.robustness\" (written by `diverse robustness`)");
      if (!r.contains("motions") || !r["motions"].is_array())
        throw_field_error(file.string(), "motions", "expected a list of motions");
      for (const nlohmann::json& m : r["motions"]) {
        if (!m.is_object() || !m.contains("label") || !m["label"].is_string())
          throw_field_error(file.string(), "motions[].label", "expected a motion's label");
        robustness_rows.push_back("| " + std::filesystem::path(dir).filename().string() + " | " +
                                  m["label"].get<std::string>() + " | " +
                                  robustness_shares(m, file.string()) + " |");
      }
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
        for (const auto& m : s.at("motions")) {
          if (!m.contains("foot_slip")) continue;
          const nlohmann::json& f = m.at("foot_slip");
          std::string row = "| " + std::filesystem::path(dir).filename().string() + " | " +
                            m.at("label").get<std::string>() + " |";
          for (const char* side : {"left", "right"}) {
            const nlohmann::json& fs = f.at(side);
            row += " " + std::to_string(fs.at("stances").get<int>()) + " | " +
                   format("%.2f", 100 * fs.at("mean_per_stance").get<double>()) + " | " +
                   format("%.2f", 100 * fs.at("largest_per_stance").get<double>()) + " |";
          }
          slip_rows.push_back(row + " " + format("%.2f", f.at("max_speed").get<double>()) + " |");
        }
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
    if (!robustness_rows.empty()) {
      std::printf("\n| run | motion | robustness (perturbed rollouts that meet the task) |\n|---|---|---|\n");
      for (const std::string& row : robustness_rows) std::printf("%s\n", row.c_str());
    }
    if (!slip_rows.empty()) {
      std::printf("\n| run | motion | left stances | left cm per stance | left largest cm | right stances | "
                  "right cm per stance | right largest cm | fastest slide m/s |\n|---|---|---|---|---|---|---|---|---|\n");
      for (const std::string& row : slip_rows) std::printf("%s\n", row.c_str());
    }
  });
}

const bool registered = register_command(45, install_report);

}  // namespace
}  // namespace diverse::cli
