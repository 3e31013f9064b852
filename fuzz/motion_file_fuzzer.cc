// libFuzzer target: the motion-file reader (`diverse replay FILE`, and what render,
// gallery and export read of a run's motions).
//
// One input is one motion file, placed in motions/ of a scratch run directory whose
// model/m1.xml is jump_high's scene (the corpus's "../model/m1.xml" resolves to it). It
// is read and replayed (replay_motion_file). Every bad file must end in UserError.
#include <cstdint>
#include <fstream>

#include "core/error.h"
#include "fuzz_support.h"
#include "io/motion_record.h"
#include "task/task.h"

namespace {

struct MotionScratch {
  diverse::fuzz::Scratch scratch{"run/motions", ""};
  MotionScratch() {
    const diverse::Task task =
        diverse::load_task(std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_high.toml");
    std::filesystem::create_directories(scratch.dir() / ".." / "model");
    std::ofstream(scratch.dir() / ".." / "model" / "m1.xml") << diverse::scene_xml(task);
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const MotionScratch run;
  const std::string path = run.scratch.write("m1.json", data, size);
  try {
    diverse::replay_motion_file(path);
  } catch (const diverse::UserError&) {
  }
  return 0;
}
