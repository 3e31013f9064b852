// A run meets faults: SIGKILL while a checkpoint is being written and right at a
// generation boundary, a stop before the first checkpoint, and a disk that fills up
// while checkpointing (a preloaded write() that runs out of space: ENOSPC, as a full
// file system gives it). Each must end with the uninterrupted run's summary after
// `diverse resume`, or with one clear error and the last good checkpoint intact and
// resumable. scripts/kill-resume.sh is the 20-point experiment (docs/reference/reliability.md).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "io/files.h"
#include "run/run.h"
#include "support/cli.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

const std::string kTask = std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_high.toml";
// 2 variations, 8 samples each per generation, 4 generations, a checkpoint every one.
const std::string kArgs = kTask +
                          " --n 2 --popsize 8 --sigma0 0.03 --generations 4 --seed 3 --threads 1 "
                          "--checkpoint-seconds 0 --quiet --no-render";

// One directory per process and name: CTest runs each test of this file as its own
// process, several at once, and every one of them builds the reference run first.
fs::path scratch(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("diverse_faults_test_" + std::to_string(getpid()) + "_" + name);
  fs::remove_all(dir);
  return dir;
}

long long checkpoint_generation(const fs::path& dir) {
  try {
    return read_json(dir / "checkpoint.json")["optimizer"]["generation"].get<long long>();
  } catch (...) {
    return -1;
  }
}

bool temporary_exists(const fs::path& dir) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path().filename().string().rfind("checkpoint.json.tmp.", 0) == 0) return true;
  return false;
}

// Starts `diverse run ARGS --out DIR` and kills it with SIGKILL once `when(dir)` holds
// (or the run ended). Returns true if the kill came before the run ended by itself.
template <class When>
bool run_and_kill_when(const fs::path& dir, When when, const std::string& env = "") {
  const pid_t pid = fork();
  if (pid == 0) {
    const std::string command = (env.empty() ? "" : "env " + env + " ") + std::string(DIVERSE_BINARY) +
                                " run " + kArgs + " --out " + dir.string();
    execl("/bin/sh", "sh", "-c", ("exec " + command).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  bool killed = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(3);
  while (std::chrono::steady_clock::now() < deadline) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return false;
    if (when(dir)) {
      kill(pid, SIGKILL);
      killed = true;
      break;
    }
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return killed && WIFSIGNALED(status);
}

class Faults : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    reference_ = new fs::path(scratch("reference"));
    const cli_test::CliResult r = cli_test::run_cli("run " + kArgs + " --out " + reference_->string());
    ASSERT_EQ(r.status, 0) << r.output;
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*reference_, ec);
    delete reference_;
  }
  static nlohmann::json reference_summary() { return without_timing(read_json(*reference_ / "summary.json")); }

  static void expect_resumes_to_reference(const fs::path& dir) {
    ASSERT_FALSE(fs::exists(dir / "summary.json")) << "the run ended before it was stopped";
    const cli_test::CliResult r = cli_test::run_cli("resume " + dir.string() + " --threads 2 --quiet --no-render");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(without_timing(read_json(dir / "summary.json")), reference_summary());
    EXPECT_FALSE(temporary_exists(dir));
  }

  static fs::path* reference_;
};
fs::path* Faults::reference_ = nullptr;

// The full-disk preload in front of the tool. Under the sanitizer build (scripts/sanitize.sh)
// AddressSanitizer wants its runtime first in the library list, so its link-order check is
// turned off, added to the options the suite runs with rather than replacing them (those
// send reports to files and set the leak and stack checks).
std::string preload_env() {
  const char* asan = std::getenv("ASAN_OPTIONS");
  const std::string options = (asan != nullptr && asan[0] != '\0' ? std::string(asan) + ":" : std::string()) +
                              "verify_asan_link_order=0";
  return "'ASAN_OPTIONS=" + options + "' LD_PRELOAD=" + std::string(DIVERSE_FULL_DISK_PRELOAD);
}

TEST_F(Faults, KillWhileACheckpointIsBeingWritten) {
  const fs::path dir = scratch("mid_write");
  fs::create_directories(dir);
  // The writer freezes inside a write once run.json and about one and a half checkpoints'
  // worth of bytes are written (the preload's stall mode), so the kill lands mid-checkpoint
  // whatever the machine's speed.
  const auto budget = static_cast<long long>(fs::file_size(*reference_ / "run.json") +
                                             fs::file_size(*reference_ / "checkpoint.json") * 3 / 2);
  const std::string env = preload_env() + " DIVERSE_FULL_DISK_STALL=1 DIVERSE_FULL_DISK_DIR=" +
                          fs::canonical(dir).string() + " DIVERSE_FULL_DISK_BYTES=" + std::to_string(budget);
  ASSERT_TRUE(run_and_kill_when(dir, [](const fs::path& d) { return temporary_exists(d); }, env));
  // Whatever checkpoint is in place is whole (or, killed in the first one, there is none
  // and the resume starts again from run.json).
  if (fs::exists(dir / "checkpoint.json")) {
    EXPECT_GE(checkpoint_generation(dir), 0) << "a torn checkpoint";
  }
  expect_resumes_to_reference(dir);
}

TEST_F(Faults, KillAtAGenerationBoundary) {
  const fs::path dir = scratch("boundary");
  ASSERT_TRUE(run_and_kill_when(dir, [](const fs::path& d) { return checkpoint_generation(d) >= 2; }));
  EXPECT_EQ(checkpoint_generation(dir), 2);
  expect_resumes_to_reference(dir);
}

TEST_F(Faults, StopBeforeTheFirstCheckpointStartsAgainFromRunJson) {
  const fs::path dir = scratch("no_checkpoint");
  fs::copy(*reference_, dir, fs::copy_options::recursive);
  for (const char* name : {"checkpoint.json", "summary.json", "log.jsonl", "motions", "model", "paths"})
    fs::remove_all(dir / name);
  expect_resumes_to_reference(dir);
}

TEST_F(Faults, DiskFullWhileCheckpointingKeepsTheLastCheckpoint) {
  const fs::path dir = scratch("full_disk");
  fs::create_directories(dir);
  // Room for run.json and one checkpoint of the finished run's size (they grow with the log):
  // the disk fills while a checkpoint of a middle generation is written.
  const auto run_bytes = static_cast<long long>(fs::file_size(*reference_ / "run.json"));
  const auto checkpoint_bytes = static_cast<long long>(fs::file_size(*reference_ / "checkpoint.json"));
  const long long budget = run_bytes + checkpoint_bytes;
  const std::string env = preload_env() + " DIVERSE_FULL_DISK_DIR=" +
                          fs::canonical(dir).string() + " DIVERSE_FULL_DISK_BYTES=" + std::to_string(budget);
  const cli_test::CliResult r = cli_test::run_cli("run " + kArgs + " --out " + dir.string(), env);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << "expected one line: " << r.output;
  EXPECT_NE(r.output.find("checkpoint.json: cannot write (No space left on device); the last checkpoint "
                          "(generation "),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find(") is intact: `diverse resume " + dir.string() + "` continues from it"),
            std::string::npos)
      << r.output;
  // The checkpoint in place is whole and no temporary is left behind.
  const long long at = checkpoint_generation(dir);
  EXPECT_GE(at, 0);
  EXPECT_LT(at, 4);
  EXPECT_FALSE(temporary_exists(dir));
  // Once there is room again, the run continues to the uninterrupted run's result.
  expect_resumes_to_reference(dir);
}

}  // namespace
}  // namespace diverse
