#pragma once
// Writing rendered frames: PNG images (stb_image_write) and videos (MP4, GIF, WebM, MKV) through an
// ffmpeg process fed raw frames on a pipe. Frames are RGBA8 with rows bottom-up, as glReadPixels
// gives them. Problems (unwritable file, no ffmpeg, ffmpeg failing) throw std::runtime_error naming the
// file and the cause.

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace aloft::render {

void write_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgba_bottom_up);

// Whether an executable named `program` is on PATH.
bool program_on_path(const std::string& program);

// A video file being written by ffmpeg. The container and codec follow the extension: .mp4 and .mkv
// H.264 (yuv420p, odd sizes padded by one pixel), .webm VP9, .gif a palette-optimised GIF that loops.
class VideoEncoder {
 public:
  VideoEncoder(const std::string& path, int width, int height, double fps);
  ~VideoEncoder();  // closes the pipe (errors then are only printed)
  VideoEncoder(const VideoEncoder&) = delete;
  VideoEncoder& operator=(const VideoEncoder&) = delete;

  void add_frame(const std::vector<std::uint8_t>& rgba_bottom_up);
  // Close the pipe and wait for ffmpeg; throws if it failed.
  void finish();
  long long frames() const { return frames_; }
  const std::string& path() const { return path_; }

  static bool is_video_path(const std::string& path);

 private:
  std::string path_;
  int width_, height_;
  std::FILE* pipe_ = nullptr;
  long long frames_ = 0;
};

// Where `aloft render` sends its frames, chosen by the output path: "x.png" one image (the last frame),
// a video by extension, or a directory ("frames/", created if needed) of frame_00000.png, ...
class FrameSink {
 public:
  enum class Kind { Image, Video, Directory };
  FrameSink(const std::string& path, int width, int height, double fps);
  Kind kind() const { return kind_; }
  // Whether the sink wants every frame (videos, directories) or only the last (a still image).
  bool wants_every_frame() const { return kind_ != Kind::Image; }
  void add_frame(const std::vector<std::uint8_t>& rgba_bottom_up);
  // Write what remains (the still image; close the video). Returns a description, e.g. "120 frames".
  std::string finish();

 private:
  Kind kind_;
  std::string path_;
  int width_, height_;
  std::vector<std::uint8_t> last_;
  std::unique_ptr<VideoEncoder> video_;
  long long frames_ = 0;
};

}  // namespace aloft::render
