// PNG reading/writing through libpng and image comparison (render/image_io.hpp).
#include "render/image_io.hpp"

#include <png.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

namespace drape::render {
namespace {
struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
}  // namespace

std::string write_png(const std::string& path, const Image& img) {
  if (img.width <= 0 || img.height <= 0 ||
      img.rgba.size() != static_cast<size_t>(img.width) * img.height * 4)
    return path + ": image is empty or its pixel array has the wrong size";
  std::unique_ptr<std::FILE, FileCloser> f(std::fopen(path.c_str(), "wb"));
  if (!f) return path + ": cannot open for writing";
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    return path + ": libpng initialisation failed";
  }
  std::vector<uint8_t> row(static_cast<size_t>(img.width) * 3);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return path + ": libpng write error";
  }
  png_init_io(png, f.get());
  png_set_IHDR(png, info, img.width, img.height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  png_set_compression_level(png, 9);
  png_write_info(png, info);
  for (int y = 0; y < img.height; ++y) {
    const uint8_t* src = img.px(0, y);
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 3; ++c) row[static_cast<size_t>(x) * 3 + c] = src[x * 4 + c];
    png_write_row(png, row.data());
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return {};
}

sim::Result<Image> read_png(const std::string& path) {
  std::unique_ptr<std::FILE, FileCloser> f(std::fopen(path.c_str(), "rb"));
  if (!f) return sim::make_error(path, "cannot open");
  uint8_t sig[8] = {};
  if (std::fread(sig, 1, 8, f.get()) != 8 || png_sig_cmp(sig, 0, 8))
    return sim::make_error(path, "not a PNG file");
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_read_struct(&png, &info, nullptr);
    return sim::make_error(path, "libpng initialisation failed");
  }
  Image img;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return sim::make_error(path, "corrupt or truncated PNG");
  }
  png_init_io(png, f.get());
  png_set_sig_bytes(png, 8);
  png_read_info(png, info);
  const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
  if (w == 0 || h == 0 || w > 16384 || h > 16384) {
    png_destroy_read_struct(&png, &info, nullptr);
    return sim::make_error(path, "image size out of range");
  }
  png_set_expand(png);
  png_set_strip_16(png);
  png_set_gray_to_rgb(png);
  png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER);
  png_read_update_info(png, info);
  img.width = static_cast<int>(w);
  img.height = static_cast<int>(h);
  img.rgba.resize(static_cast<size_t>(w) * h * 4);
  std::vector<png_bytep> rows(h);
  for (png_uint_32 y = 0; y < h; ++y) rows[y] = &img.rgba[static_cast<size_t>(y) * w * 4];
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return img;
}

sim::Result<ImageDiff> compare_images(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height)
    return sim::Error{"image sizes differ: " + std::to_string(a.width) + "x" +
                      std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                      std::to_string(b.height)};
  ImageDiff d;
  double se = 0;
  size_t over = 0;
  const size_t n = static_cast<size_t>(a.width) * a.height;
  for (size_t i = 0; i < n; ++i) {
    bool big = false;
    for (int c = 0; c < 3; ++c) {
      const int e = std::abs(int(a.rgba[i * 4 + c]) - int(b.rgba[i * 4 + c]));
      se += double(e) * e;
      d.max_abs = std::max(d.max_abs, e);
      big = big || e > 16;
    }
    over += big;
  }
  const double mse = se / (3.0 * n);
  d.psnr_db =
      mse == 0 ? std::numeric_limits<double>::infinity() : 10.0 * std::log10(255.0 * 255.0 / mse);
  d.frac_over_16 = double(over) / n;
  return d;
}

}  // namespace drape::render
