// Pictures and videos of a finished run (`diverse render RUN`).
//
// Everything here is drawn from the recorded states of the run as read back
// (finished/run_view.h): nothing is simulated again, so pictures show exactly the motions
// the run found, each on its own model (rows and tiles may differ in body shape).
//
//   filmstrip.png     the paper's figure 5: one row per motion (M0 on top), one column
//                     per phase event of the jump (A crouch, B extend, C take-off, ...;
//                     render/film_columns.h, jump_film_columns), one shared side camera, scene
//                     objects drawn and the landing region marked on the floor
//   videos/m<i>.mp4   each motion alone, labelled with its constraint value
//   videos/all.mp4    all motions side by side in step, through one shared camera;
//                     shorter motions hold their last frame
//
// Videos sample the recorded states at the video's frame rate (the state nearest in time
// to each frame), in real time or at half speed; the time stamp is the motion's time.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "finished/run_view.h"
#include "render/offscreen.h"

namespace diverse {

// A video's header line holds a title on the left and the time stamp on the right: the
// first of `titles` that leaves `stamp` room (FontSize::kMedium, margins of `gap` pixels)
// in `width` pixels, else the last. Longest first: "robot_silly_walk M1, real time", then
// "M1, real time", then "M1".
std::string fitting_title(const std::vector<std::string>& titles, const std::string& stamp, int width, int gap);

// The task's landing region, drawn on the floor (render/film_columns.h,
// task_ground_strips); none when the run's task file could not be read (run.task_note).
std::vector<GroundStrip> run_ground_strips(const RunView& run);

// The film strip of the run (layout above) written as a PNG.
void write_run_film_strip(const RunView& run, const std::filesystem::path& png);

struct RunVideoOptions {
  double fps = 30.0;    // frames per second of the files
  double speed = 1.0;   // 1 = real time, 0.5 = half speed
  int tile_width = 384;   // px, one motion's picture
  int tile_height = 384;  // px
  int columns = 5;        // at most this many motions per row of all.mp4
};

// Writes videos/m<i>.mp4 for every motion and videos/all.mp4 (layout above); returns the
// paths written. Each motion's frames are rendered once and go to both files. Throws
// UserError if ffmpeg is missing or fails.
std::vector<std::filesystem::path> write_run_videos(const RunView& run,
                                                    const RunVideoOptions& options = {});

}  // namespace diverse
