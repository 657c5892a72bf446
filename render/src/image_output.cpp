#include "aloft/render/image_output.hpp"

#include <stb_image_write.h>
#include <sys/wait.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <unistd.h>

namespace aloft::render {

namespace {

std::string extension_of(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

// Single-quoted for /bin/sh.
std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace

void write_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgba_bottom_up) {
  if (rgba_bottom_up.size() != static_cast<std::size_t>(width) * height * 4)
    throw std::runtime_error("cannot write " + path + ": the image has the wrong size");
  // Start at the last row and step backwards: the file is written top row first.
  const std::uint8_t* top = rgba_bottom_up.data() + static_cast<std::size_t>(height - 1) * width * 4;
  if (!stbi_write_png(path.c_str(), width, height, 4, top, -width * 4))
    throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
}

bool program_on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::string dirs = path;
  std::size_t start = 0;
  while (start <= dirs.size()) {
    std::size_t end = dirs.find(':', start);
    if (end == std::string::npos) end = dirs.size();
    const std::string dir = dirs.substr(start, end - start);
    if (!dir.empty() && ::access((dir + "/" + program).c_str(), X_OK) == 0) return true;
    start = end + 1;
  }
  return false;
}

bool VideoEncoder::is_video_path(const std::string& path) {
  const std::string e = extension_of(path);
  return e == ".mp4" || e == ".mkv" || e == ".webm" || e == ".gif" || e == ".mov";
}

VideoEncoder::VideoEncoder(const std::string& path, int width, int height, double fps)
    : path_(path), width_(width), height_(height) {
  if (!program_on_path("ffmpeg"))
    throw std::runtime_error("cannot write " + path + ": ffmpeg is not installed (apt-get install ffmpeg), "
                             "or write PNG frames to a directory instead");
  const std::string e = extension_of(path);
  // glReadPixels rows run bottom-up: flip. H.264 in yuv420p needs even sizes: pad by one pixel if odd.
  std::string codec;
  if (e == ".gif")
    codec = "-vf \"vflip,split[a][b];[a]palettegen=stats_mode=diff[p];[b][p]paletteuse=dither=bayer\" -loop 0";
  else if (e == ".webm")
    codec = "-vf vflip -c:v libvpx-vp9 -b:v 0 -crf 32 -pix_fmt yuv420p";
  else
    codec = "-vf \"vflip,pad=ceil(iw/2)*2:ceil(ih/2)*2\" -c:v libx264 -preset veryfast -crf 20 -pix_fmt yuv420p "
            "-movflags +faststart";
  const std::string command = "ffmpeg -hide_banner -loglevel error -y -f rawvideo -pix_fmt rgba -s " +
                              std::to_string(width) + "x" + std::to_string(height) + " -r " + std::to_string(fps) +
                              " -i - " + codec + " " + shell_quote(path);
  // A dying ffmpeg must give a write error here, not kill us with SIGPIPE.
  std::signal(SIGPIPE, SIG_IGN);
  pipe_ = ::popen(command.c_str(), "w");
  if (!pipe_) throw std::runtime_error("cannot start ffmpeg to write " + path + ": " + std::strerror(errno));
}

VideoEncoder::~VideoEncoder() {
  if (pipe_) ::pclose(pipe_);
}

void VideoEncoder::add_frame(const std::vector<std::uint8_t>& rgba) {
  if (!pipe_) throw std::runtime_error("cannot write " + path_ + ": the video is already closed");
  if (rgba.size() != static_cast<std::size_t>(width_) * height_ * 4)
    throw std::runtime_error("cannot write " + path_ + ": a frame has the wrong size");
  if (std::fwrite(rgba.data(), 1, rgba.size(), pipe_) != rgba.size())
    throw std::runtime_error("cannot write " + path_ + ": ffmpeg stopped taking frames (see its message above)");
  ++frames_;
}

void VideoEncoder::finish() {
  if (!pipe_) return;
  const int status = ::pclose(pipe_);
  pipe_ = nullptr;
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error("cannot write " + path_ + ": ffmpeg failed (see its message above)");
}

FrameSink::FrameSink(const std::string& path, int width, int height, double fps)
    : path_(path), width_(width), height_(height) {
  namespace fs = std::filesystem;
  const bool directory = !path.empty() && (path.back() == '/' || fs::is_directory(path));
  if (directory) {
    kind_ = Kind::Directory;
    std::error_code ec;
    fs::create_directories(path, ec);
    if (ec) throw std::runtime_error("cannot create the directory " + path + ": " + ec.message());
  } else if (extension_of(path) == ".png") {
    kind_ = Kind::Image;
  } else if (VideoEncoder::is_video_path(path)) {
    kind_ = Kind::Video;
    video_ = std::make_unique<VideoEncoder>(path, width, height, fps);
  } else {
    throw std::runtime_error("cannot tell what to write to " + path +
                             ": use a .png (one image), .mp4, .gif, .webm, .mkv (video) or a directory ending in /");
  }
}

void FrameSink::add_frame(const std::vector<std::uint8_t>& rgba) {
  switch (kind_) {
    case Kind::Image: last_ = rgba; break;
    case Kind::Video: video_->add_frame(rgba); break;
    case Kind::Directory: {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%05lld.png", frames_);
      write_png((std::filesystem::path(path_) / name).string(), width_, height_, rgba);
      break;
    }
  }
  ++frames_;
}

std::string FrameSink::finish() {
  switch (kind_) {
    case Kind::Image:
      if (!last_.empty()) write_png(path_, width_, height_, last_);
      return std::to_string(width_) + "x" + std::to_string(height_) + " image";
    case Kind::Video: video_->finish(); break;
    case Kind::Directory: break;
  }
  return std::to_string(frames_) + " frames of " + std::to_string(width_) + "x" + std::to_string(height_);
}

}  // namespace aloft::render
