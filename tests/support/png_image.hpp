#pragma once
// A picture read back as 8-bit RGB (stb_image), for the tests that look at what was rendered.

#include <stb_image.h>

#include <cstddef>
#include <filesystem>
#include <vector>

namespace aloft::test {

struct Image {
  int width = 0, height = 0;       // pixels; both 0 when the file could not be read
  std::vector<unsigned char> rgb;  // rows from the top, 3 bytes a pixel
  const unsigned char* at(int x, int y) const { return &rgb[(static_cast<std::size_t>(y) * width + x) * 3]; }
};

inline Image load_png(const std::filesystem::path& p) {
  Image image;
  int channels = 0;
  unsigned char* data = stbi_load(p.c_str(), &image.width, &image.height, &channels, 3);
  if (!data) return {};
  image.rgb.assign(data, data + static_cast<std::size_t>(image.width) * image.height * 3);
  stbi_image_free(data);
  return image;
}

}  // namespace aloft::test
