// MP4 videos: raw RGB frames piped to an ffmpeg child process.
//
// ffmpeg (Debian package `ffmpeg`) is run as
//   ffmpeg -f rawvideo -pix_fmt rgb24 -s WxH -r FPS -i - -vf pad=even -pix_fmt yuv420p
//          -c:v libx264 -crf CRF out.mp4
// with mpeg4 in place of libx264 when ffmpeg was built without it (`ffmpeg -encoders`).
// Frames go through a socket rather than a pipe, so a crashed ffmpeg shows up as an error
// from add_frame instead of a SIGPIPE that would kill the whole program; its exit status is
// checked on close and its last error line is reported.
//
// Side-by-side videos put several motions in one picture, one tile per motion, all seen
// through one camera fitted to every frame; they play in step and shorter motions hold their
// last frame until the longest one ends.
#pragma once

#include <mujoco/mujoco.h>

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "render/image.h"
#include "render/offscreen.h"

namespace diverse {

struct VideoOptions {
  double fps = 30.0;  // frames per second of the file
  int crf = 20;       // libx264 quality, 0 (lossless) .. 51 (worst); mpeg4 gets -q:v crf/6.5
};

// Path of the ffmpeg executable found on PATH, or empty if there is none.
std::string find_ffmpeg();
// The encoder videos are written with: "libx264" if ffmpeg has it, else "mpeg4". Throws
// UserError if ffmpeg is missing.
std::string video_encoder();

class VideoWriter {
 public:
  // Starts ffmpeg writing `path` (overwritten) from frames of width x height pixels. Throws
  // UserError if ffmpeg is not installed or cannot be started.
  VideoWriter(const std::string& path, int width, int height, VideoOptions options = {});
  // Closes the stream if close() was not called; errors are then ignored.
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  // Appends a frame of exactly width x height (else std::invalid_argument). Throws UserError
  // if ffmpeg has stopped reading.
  void add_frame(const Image& frame);
  // Ends the stream and waits for ffmpeg. Throws UserError (with ffmpeg's last message) if
  // it failed.
  void close();

  int frames() const { return frames_; }

 private:
  std::string path_;
  int width_ = 0;
  int height_ = 0;
  int frames_ = 0;
  int socket_ = -1;  // our end of the stream to ffmpeg's stdin
  int pid_ = -1;
  std::string log_path_;  // ffmpeg's stderr
};

// One motion of a side-by-side video.
struct VideoTrack {
  const mjModel* model = nullptr;
  std::string label;                        // drawn above the tile, e.g. "M3"
  std::vector<std::vector<double>> frames;  // qpos (size model->nq) sampled at the video fps
};

struct SideBySideOptions {
  int tile_width = 320;   // px
  int tile_height = 320;  // px
  int columns = 0;        // tiles per row; 0 puts all tracks in one row
  int gap = 4;            // px between tiles
  std::string title;      // optional line above the tiles
  bool show_time = true;  // time stamp in seconds in the title line
  std::vector<GroundStrip> ground_strips;
  SideCamera camera_direction;
  double camera_margin = 0.08;
  std::optional<SideCamera> camera;  // use this camera instead of fitting one
  RenderStyle style;
  VideoOptions video;
  Rgb background{255, 255, 255};
  Rgb text{34, 34, 34};
};

// Writes the tracks side by side into one MP4 whose length is that of the longest track.
// Throws std::invalid_argument if there are no tracks or a track has no model or no frames,
// UserError if ffmpeg fails.
void write_side_by_side_video(const std::string& path, std::span<const VideoTrack> tracks,
                              const SideBySideOptions& options = {});

}  // namespace diverse
