// Subcommand registry of the `diverse` tool.
//
// Every subcommand lives in its own cmd_<name>.cc and registers an installer at
// static-initialization time:
//
//   static const bool registered = diverse::cli::register_command(10, add_cmaes);
//
// The installer adds a CLI11 subcommand and its callback. Callbacks report bad user
// input by throwing diverse::UserError (one line); main() prints it and exits 2.
#pragma once

namespace CLI {
class App;
}

namespace diverse::cli {

using Installer = void (*)(CLI::App& app);

// `order` sorts subcommands in --help (lower first).
bool register_command(int order, Installer installer);

}  // namespace diverse::cli
