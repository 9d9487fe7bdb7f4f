#include "renders/image.h"

#include <png.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include "common/check.h"

namespace mjslam::renders {

namespace {

struct FileCloser {
  void operator()(std::FILE* file) const { std::fclose(file); }
};

// libpng reports an error by longjmp: the callback keeps the message and jumps
// back to the caller's setjmp, which cleans up and throws.
[[noreturn]] void PngError(png_structp png, png_const_charp message) {
  auto* text = static_cast<std::string*>(png_get_error_ptr(png));
  if (text != nullptr) *text = message;
  png_longjmp(png, 1);
}

void PngWarning(png_structp /*png*/, png_const_charp /*message*/) {}

}  // namespace

std::uint8_t Image::At(int x, int y, int channel) const {
  MJSLAM_CHECK(x >= 0 && x < width && y >= 0 && y < height && channel >= 0 && channel < 3);
  return rgb[(static_cast<std::size_t>(y) * width + x) * 3 + channel];
}

void WritePng(const std::string& path, const Image& image) {
  MJSLAM_CHECK(image.width > 0 && image.height > 0 &&
               image.rgb.size() == static_cast<std::size_t>(image.width) * image.height * 3);
  const std::string temp = path + ".tmp";
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(temp.c_str(), "wb"));
  if (!file) {
    throw std::runtime_error("cannot write '" + temp + "': " + std::strerror(errno));
  }
  std::string error;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, PngError, PngWarning);
  MJSLAM_CHECK(png != nullptr);
  png_infop info = png_create_info_struct(png);
  MJSLAM_CHECK(info != nullptr);
  std::vector<png_bytep> rows(image.height);
  for (int y = 0; y < image.height; ++y) {
    rows[y] = const_cast<png_bytep>(image.rgb.data() + static_cast<std::size_t>(y) * image.width * 3);
  }
  volatile bool ok = false;
  if (setjmp(png_jmpbuf(png)) == 0) {
    png_init_io(png, file.get());
    png_set_IHDR(png, info, image.width, image.height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, 6);
    png_write_info(png, info);
    png_write_image(png, rows.data());
    png_write_end(png, nullptr);
    ok = true;
  }
  png_destroy_write_struct(&png, &info);
  const bool flushed = std::fflush(file.get()) == 0;
  file.reset();
  if (!ok || !flushed) {
    std::filesystem::remove(temp);
    throw std::runtime_error("cannot write PNG '" + path + "': " +
                             (ok ? std::string("write failed") : error));
  }
  std::error_code rename_error;
  std::filesystem::rename(temp, path, rename_error);
  if (rename_error) {
    std::filesystem::remove(temp);
    throw std::runtime_error("cannot rename '" + temp + "' to '" + path +
                             "': " + rename_error.message());
  }
}

Image ReadPng(const std::string& path) {
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) throw std::runtime_error("cannot read '" + path + "': " + std::strerror(errno));
  std::string error;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &error, PngError, PngWarning);
  MJSLAM_CHECK(png != nullptr);
  png_infop info = png_create_info_struct(png);
  MJSLAM_CHECK(info != nullptr);
  Image image;
  volatile bool ok = false;
  if (setjmp(png_jmpbuf(png)) == 0) {
    png_init_io(png, file.get());
    png_read_info(png, info);
    const int depth = png_get_bit_depth(png, info);
    const int color = png_get_color_type(png, info);
    if (depth == 8 && (color == PNG_COLOR_TYPE_RGB || color == PNG_COLOR_TYPE_RGBA)) {
      if (color == PNG_COLOR_TYPE_RGBA) png_set_strip_alpha(png);
      png_read_update_info(png, info);
      image.width = static_cast<int>(png_get_image_width(png, info));
      image.height = static_cast<int>(png_get_image_height(png, info));
      image.rgb.resize(static_cast<std::size_t>(image.width) * image.height * 3);
      std::vector<png_bytep> rows(image.height);
      for (int y = 0; y < image.height; ++y) {
        rows[y] = image.rgb.data() + static_cast<std::size_t>(y) * image.width * 3;
      }
      png_read_image(png, rows.data());
      ok = true;
    } else {
      error = "not an 8-bit RGB or RGBA PNG";
    }
  }
  png_destroy_read_struct(&png, &info, nullptr);
  if (!ok) throw std::runtime_error("cannot read PNG '" + path + "': " + error);
  return image;
}

}  // namespace mjslam::renders
