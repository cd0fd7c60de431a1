// PNG files for screenshots and golden images (libpng), and image comparison.
#pragma once

#include <string>

#include "render/renderer.hpp"

namespace drape::render {

// Writes 8-bit RGBA (alpha dropped: screenshots are opaque) as PNG; empty string or an error.
std::string write_png(const std::string& path, const Image& img);
// Reads an 8-bit RGB or RGBA PNG (other depths/palettes converted) into RGBA.
sim::Result<Image> read_png(const std::string& path);

struct ImageDiff {
  double psnr_db = 0;       // over RGB, +inf for identical images
  int max_abs = 0;          // largest channel difference
  double frac_over_16 = 0;  // fraction of pixels with any channel differing by more than 16
};
// Compares two images of equal size (an error when sizes differ).
sim::Result<ImageDiff> compare_images(const Image& a, const Image& b);

}  // namespace drape::render
