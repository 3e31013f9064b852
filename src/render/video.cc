#include "render/video.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "core/error.h"

extern char** environ;

namespace diverse {
namespace {

std::string missing_ffmpeg_message() {
  return "ffmpeg: not found on PATH; install it (Debian: apt-get install ffmpeg) to write "
         "videos";
}

// Runs argv with stdin from `stdin_fd` (or /dev/null), stdout to `stdout_fd` (or
// /dev/null) and stderr to `stderr_fd`. Returns the child's pid; throws UserError if it
// cannot be started.
pid_t spawn(const std::vector<std::string>& args, int stdin_fd, int stdout_fd, int stderr_fd) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (stdin_fd >= 0) {
    posix_spawn_file_actions_adddup2(&actions, stdin_fd, 0);
  } else {
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  }
  if (stdout_fd >= 0) {
    posix_spawn_file_actions_adddup2(&actions, stdout_fd, 1);
  } else {
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  }
  posix_spawn_file_actions_adddup2(&actions, stderr_fd, 2);
  std::vector<char*> argv;
  for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int error = posix_spawn(&pid, args[0].c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0) {
    throw UserError(args[0] + ": cannot start: " + std::strerror(error));
  }
  return pid;
}

// Waits for the child; returns its exit status, or 128 + signal if it was killed.
int wait_for(pid_t pid) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return -1;
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

// A temporary file for a child's output, opened close-on-exec; removed by the caller.
int make_temp_file(std::string& path) {
  std::string pattern = (std::filesystem::temp_directory_path() / "diverse-ffmpeg-XXXXXX").string();
  const int fd = mkostemp(pattern.data(), O_CLOEXEC);
  if (fd < 0) throw UserError(pattern + ": cannot create temporary file: " + std::strerror(errno));
  path = pattern;
  return fd;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string last_line(const std::string& text) {
  std::string line;
  std::istringstream lines(text);
  for (std::string l; std::getline(lines, l);) {
    if (l.find_first_not_of(" \t\r") != std::string::npos) line = l;
  }
  return line;
}

}  // namespace

std::string find_ffmpeg() {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return {};
  std::istringstream dirs(path);
  for (std::string dir; std::getline(dirs, dir, ':');) {
    // An empty entry means the current directory.
    const std::string candidate = (dir.empty() ? std::string(".") : dir) + "/ffmpeg";
    struct stat info {};
    if (stat(candidate.c_str(), &info) == 0 && S_ISREG(info.st_mode) &&
        access(candidate.c_str(), X_OK) == 0) {
      return candidate;
    }
  }
  return {};
}

std::string video_encoder() {
  static std::mutex mutex;
  static std::string encoder;  // found once per process
  const std::lock_guard<std::mutex> lock(mutex);
  if (!encoder.empty()) return encoder;
  const std::string ffmpeg = find_ffmpeg();
  if (ffmpeg.empty()) throw UserError(missing_ffmpeg_message());
  std::string list_path;
  const int list_fd = make_temp_file(list_path);
  int status = -1;
  try {
    status = wait_for(spawn({ffmpeg, "-hide_banner", "-encoders"}, -1, list_fd, list_fd));
  } catch (...) {
    ::close(list_fd);
    std::remove(list_path.c_str());
    throw;
  }
  ::close(list_fd);
  const std::string list = read_file(list_path);
  std::remove(list_path.c_str());
  if (status != 0) throw UserError(ffmpeg + ": cannot list encoders: " + last_line(list));
  encoder = list.find(" libx264 ") != std::string::npos ? "libx264" : "mpeg4";
  return encoder;
}

VideoWriter::VideoWriter(const std::string& path, int width, int height, VideoOptions options)
    : path_(path), width_(width), height_(height) {
  if (width <= 0 || height <= 0 || !(options.fps > 0.0)) {
    throw std::invalid_argument("VideoWriter: bad size " + std::to_string(width) + "x" +
                                std::to_string(height) + " or fps " +
                                std::to_string(options.fps));
  }
  const std::string ffmpeg = find_ffmpeg();
  if (ffmpeg.empty()) throw UserError(missing_ffmpeg_message());
  const std::string encoder = video_encoder();

  char fps[32];
  std::snprintf(fps, sizeof fps, "%.6g", options.fps);
  std::vector<std::string> args = {
      ffmpeg, "-hide_banner", "-loglevel", "error", "-y",
      "-f", "rawvideo", "-pix_fmt", "rgb24",
      "-s", std::to_string(width) + "x" + std::to_string(height),
      "-r", fps, "-i", "pipe:0",
      // yuv420p (what players expect) needs even sizes.
      "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p", "-c:v", encoder};
  if (encoder == "libx264") {
    args.insert(args.end(), {"-crf", std::to_string(std::clamp(options.crf, 0, 51)), "-preset",
                             "medium", "-movflags", "+faststart"});
  } else {
    // mpeg4's quantizer scale 1..31; CRF 20 maps to 3, a good quality.
    args.insert(args.end(),
                {"-q:v", std::to_string(std::clamp(
                             static_cast<int>(std::lround(options.crf / 6.5)), 1, 31))});
  }
  args.push_back(path);

  // A socket instead of a pipe: writing to it after ffmpeg died gives EPIPE from send()
  // with MSG_NOSIGNAL instead of a process-wide SIGPIPE.
  int ends[2];
  if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, ends) != 0) {
    throw UserError(path + ": cannot open a stream to ffmpeg: " + std::strerror(errno));
  }
  const int log_fd = make_temp_file(log_path_);
  try {
    pid_ = spawn(args, ends[1], -1, log_fd);
  } catch (...) {
    ::close(ends[0]);
    ::close(ends[1]);
    ::close(log_fd);
    std::remove(log_path_.c_str());
    throw;
  }
  ::close(ends[1]);
  ::close(log_fd);
  socket_ = ends[0];
}

VideoWriter::~VideoWriter() {
  if (socket_ >= 0) ::close(socket_);
  if (pid_ > 0) wait_for(pid_);
  if (!log_path_.empty()) std::remove(log_path_.c_str());
}

void VideoWriter::add_frame(const Image& frame) {
  if (frame.width() != width_ || frame.height() != height_) {
    throw std::invalid_argument("VideoWriter: frame is " + std::to_string(frame.width()) + "x" +
                                std::to_string(frame.height()) + ", video is " +
                                std::to_string(width_) + "x" + std::to_string(height_));
  }
  if (socket_ < 0) throw std::logic_error("VideoWriter: add_frame after close");
  const std::uint8_t* bytes = frame.data();
  std::size_t left = static_cast<std::size_t>(width_) * height_ * 3;
  while (left > 0) {
    const ssize_t sent = send(socket_, bytes, left, MSG_NOSIGNAL);
    if (sent < 0) {
      if (errno == EINTR) continue;
      close();  // reports ffmpeg's own message if it failed
      throw UserError(path_ + ": ffmpeg stopped reading frames");
    }
    bytes += sent;
    left -= static_cast<std::size_t>(sent);
  }
  ++frames_;
}

void VideoWriter::close() {
  if (socket_ < 0) return;
  ::close(socket_);
  socket_ = -1;
  const int status = wait_for(pid_);
  pid_ = -1;
  const std::string log = read_file(log_path_);
  std::remove(log_path_.c_str());
  log_path_.clear();
  if (status != 0) {
    const std::string message = last_line(log);
    throw UserError(path_ + ": ffmpeg failed (exit status " + std::to_string(status) + ")" +
                    (message.empty() ? "" : ": " + message));
  }
}

void write_side_by_side_video(const std::string& path, std::span<const VideoTrack> tracks,
                              const SideBySideOptions& options) {
  if (tracks.empty()) throw std::invalid_argument("side-by-side video: no tracks");
  std::size_t length = 0;
  std::vector<PosedModel> motions;
  for (std::size_t i = 0; i < tracks.size(); ++i) {
    if (tracks[i].model == nullptr || tracks[i].frames.empty()) {
      throw std::invalid_argument("side-by-side video: track " + std::to_string(i) +
                                  " has no model or no frames");
    }
    length = std::max(length, tracks[i].frames.size());
    motions.push_back({tracks[i].model, tracks[i].frames});
  }
  const int tile_w = options.tile_width;
  const int tile_h = options.tile_height;
  const SideCamera camera =
      options.camera ? *options.camera
                     : fit_shared_camera(motions, static_cast<double>(tile_w) / tile_h,
                                         options.ground_strips, options.camera_direction,
                                         options.camera_margin);

  // Layout: a header line (title, time), then a grid of tiles, each labelled in its corner.
  const int n = static_cast<int>(tracks.size());
  const int columns = options.columns > 0 ? std::min(options.columns, n) : n;
  const int rows = (n + columns - 1) / columns;
  const int gap = options.gap;
  const bool header = !options.title.empty() || options.show_time;
  const int header_h = header ? text_height(FontSize::kMedium) + 2 * gap : 0;
  const int width = columns * tile_w + (columns + 1) * gap;
  const int height = header_h + rows * tile_h + (rows + 1) * gap;

  std::vector<std::unique_ptr<OffscreenRenderer>> renderers;  // one per track
  for (const VideoTrack& track : tracks) {
    renderers.push_back(
        std::make_unique<OffscreenRenderer>(track.model, tile_w, tile_h, options.style));
    renderers.back()->set_ground_strips(options.ground_strips);
  }

  VideoWriter writer(path, width, height, options.video);
  Image canvas(width, height, options.background);
  for (std::size_t t = 0; t < length; ++t) {
    if (header) {
      canvas.fill_rect(0, 0, width, header_h, options.background);
      draw_text(canvas, options.title, gap, gap, options.text, FontSize::kMedium);
      if (options.show_time) {
        char time[32];
        std::snprintf(time, sizeof time, "t = %.2f s", static_cast<double>(t) / options.video.fps);
        draw_text(canvas, time, width - gap, gap, options.text, FontSize::kMedium, Align::kRight);
      }
    }
    for (int i = 0; i < n; ++i) {
      const VideoTrack& track = tracks[i];
      if (t >= track.frames.size()) continue;  // holds its last frame
      const int x = gap + (i % columns) * (tile_w + gap);
      const int y = header_h + gap + (i / columns) * (tile_h + gap);
      canvas.paste(renderers[i]->render(track.frames[t], camera), x, y);
      draw_text(canvas, track.label, x + 8, y + 6, options.text, FontSize::kLarge);
    }
    writer.add_frame(canvas);
  }
  writer.close();
}

}  // namespace diverse
