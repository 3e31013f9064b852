// The `diverse` command-line tool: finds many different ways a simulated character
// can perform a skill. Subcommands register themselves (see command.h).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
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

// Errors are one line: a line break or other control character that came from a file
// (a TOML string, a JSON key) is printed escaped.
std::string one_line(const char* message) {
  std::string out;
  for (const char* c = message; *c != '\0'; ++c) {
    const auto u = static_cast<unsigned char>(*c);
    if (u == '\n') {
      out += "\\n";
    } else if (u < 0x20 || u == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", u);
      out += hex;
    } else {
      out += *c;
    }
  }
  return out;
}

// Under mpirun every rank parses the same command line: only rank 0 reports its errors.
bool reports_errors() {
  const char* rank = std::getenv("OMPI_COMM_WORLD_RANK");
  return rank == nullptr || std::string(rank) == "0";
}

}  // namespace diverse::cli

int main(int argc, char** argv) {
  CLI::App app{"diverse: diverse motions and character shapes for simulated skills"};
  app.set_version_flag("--version", std::string(DIVERSE_VERSION));
  app.footer("Examples:\n"
             "  diverse run                          # 4 diverse high jumps into runs/jump_high/\n"
             "  diverse run --help                   # a subcommand's options and an example");
  app.require_subcommand(1);
  // A flag given twice takes its last value, as in most command-line tools.
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  auto commands = diverse::cli::registry();
  std::stable_sort(commands.begin(), commands.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [order, install] : commands) install(app);

  // A first argument that is neither an option nor a subcommand is named in the error
  // (CLI11 would only say that a subcommand is required).
  if (argc > 1 && argv[1][0] != '-') {
    bool known = false;
    std::string names;
    const CLI::App& top = app;
    for (const CLI::App* sub : top.get_subcommands([](const CLI::App*) { return true; })) {
      known = known || sub->check_name(argv[1]);
      names += (names.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known) {
      std::fprintf(stderr, "diverse: error: %s: expected a subcommand (%s)\n",
                   diverse::cli::one_line(argv[1]).c_str(), names.c_str());
      return 2;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    if (diverse::cli::reports_errors())
      std::fprintf(stderr, "diverse: error: %s\n", diverse::cli::one_line(e.what()).c_str());
    return 2;
  } catch (const diverse::UserError& e) {
    if (diverse::cli::reports_errors())
      std::fprintf(stderr, "diverse: error: %s\n", diverse::cli::one_line(e.what()).c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "diverse: internal error: %s\n", diverse::cli::one_line(e.what()).c_str());
    return 3;
  }
  return 0;
}
