#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace mjslam::renders {

/// An 8-bit RGB image, rows from the top, 3 bytes per pixel.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;

  /// Red, green and blue of pixel (column x, row y from the top); both must be
  /// inside the image (checked).
  std::uint8_t At(int x, int y, int channel) const;
};

/// Writes `image` as a PNG file (libpng, 8-bit RGB, no metadata, so the same
/// pixels give the same bytes) through a temporary file in the same folder
/// and a rename: `path` is never left half-written. Throws std::runtime_error
/// naming the file when it cannot be written.
void WritePng(const std::string& path, const Image& image);

/// Reads an 8-bit RGB or RGBA PNG file (alpha dropped). Throws
/// std::runtime_error naming the file when it is missing or not such a PNG.
Image ReadPng(const std::string& path);

}  // namespace mjslam::renders
