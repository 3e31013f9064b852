// The `diverse` command-line tool: finds many different ways a simulated character
// can perform a skill. Subcommands register themselves (see command.h).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <utility>
#include <vector>

#include "command.h"
#include "core/error.h"

namespace diverse::cli {
namespace {

std::vector<std::pair<int, Installer>>& registry() {
  static std::vector<std::pair<int, Installer>> commands;
  return commands;
}

}  // namespace

bool register_command(int order, Installer installer) {
  registry().emplace_back(order, installer);
  return true;
}

}  // namespace diverse::cli

int main(int argc, char** argv) {
  CLI::App app{"diverse: diverse motions and character shapes for simulated skills"};
  app.set_version_flag("--version", std::string(DIVERSE_VERSION));
  app.require_subcommand(1);
  // A flag given twice takes its last value, as in most command-line tools.
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  auto commands = diverse::cli::registry();
  std::stable_sort(commands.begin(), commands.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [order, install] : commands) install(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "diverse: error: %s\n", e.what());
    return 2;
  } catch (const diverse::UserError& e) {
    std::fprintf(stderr, "diverse: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "diverse: internal error: %s\n", e.what());
    return 3;
  }
  return 0;
}
