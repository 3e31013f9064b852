// Running the built `diverse` tool from end-to-end tests.
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

namespace diverse::cli_test {

struct CliResult {
  int status = -1;     // exit code, -1 if it did not exit normally
  std::string output;  // stdout and stderr together
};

// Runs `command` in a shell and returns what it printed to stdout.
inline std::string shell_output(const std::string& command) {
  std::string out;
  if (FILE* pipe = popen(command.c_str(), "r")) {
    char buffer[4096];
    std::size_t n = 0;
    while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) out.append(buffer, n);
    pclose(pipe);
  }
  return out;
}

// Runs `diverse ARGS` (with `env` variable assignments in front, if any).
inline CliResult run_cli(const std::string& args, const std::string& env = "") {
  const std::string command = (env.empty() ? "" : "env " + env + " ") +
                              std::string(DIVERSE_BINARY) + " " + args + " 2>&1";
  CliResult r;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return r;
  char buffer[4096];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) r.output.append(buffer, n);
  const int status = pclose(pipe);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// Starts `diverse run ARGS --out DIR` in the background and kills it with SIGKILL once its
// checkpoint has reached `generation` (or after three minutes). Returns the generation the
// last checkpoint read showed, so the caller can assert that the kill came mid-run.
inline long long run_then_kill(const std::string& args, const std::filesystem::path& dir,
                               long long generation) {
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    const std::string command =
        std::string(DIVERSE_BINARY) + " run " + args + " --out " + dir.string() + " >/dev/null 2>&1";
    execl("/bin/sh", "sh", "-c", ("exec " + command).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  long long reached = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(3);
  while (reached < generation && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    std::ifstream in(dir / "checkpoint.json");
    if (!in) continue;  // not written yet, or a read racing the atomic rename
    try {
      reached = nlohmann::json::parse(in)["optimizer"]["generation"].get<long long>();
    } catch (...) {
      // Never torn (atomic rename); keep polling.
    }
  }
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  return reached;
}

}  // namespace diverse::cli_test
