// A small finished run of the planar high jump, laid out as `diverse run` leaves one and
// written with the run's own writers, for the tests that read runs back
// (finished/run_view.h) and draw them (render/run_media.h, render/gallery.h).
#pragma once

#include <filesystem>
#include <string>

namespace diverse::test_support {

// tasks/jump_high.toml in the source tree.
std::string jump_high_task_file();

// A run directory at `dir` (made, or emptied first) of two simulated jumps: M0 is the
// task's input motion, M1 the same controller with every parameter moved by 0.06 of its
// range, and M1's path goes M0 -> half-way -> M1 (paths/m1.json). run.json names the task
// file with its text; summary.json gives both motions dmin 1.5 and an MD distance of 1.5.
void write_jump_run(const std::filesystem::path& dir);

}  // namespace diverse::test_support
