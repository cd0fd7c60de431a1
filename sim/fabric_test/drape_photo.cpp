// The shadow of a drape test from a photograph (sim/fabric_test/drape_photo.hpp).
#include "sim/fabric_test/drape_photo.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace drape::sim {

namespace {

// The largest dark region of the grey image (Otsu), holes filled; its pixel count in `area`
// and the share of it that is dark in `solid` (a drape: ~1; a printed ring's inside: ~0).
cv::Mat drape_mask(const cv::Mat& grey, int& area, double& solid) {
  cv::Mat blur, mask;
  cv::GaussianBlur(grey, blur, cv::Size(5, 5), 0);
  cv::threshold(blur, mask, 0, 255, cv::THRESH_BINARY_INV | cv::THRESH_OTSU);
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  cv::Mat out = cv::Mat::zeros(grey.size(), CV_8U);
  area = 0;
  if (contours.empty()) return out;
  auto largest = std::max_element(contours.begin(), contours.end(), [](auto& a, auto& b) {
    return cv::contourArea(a) < cv::contourArea(b);
  });
  cv::drawContours(out, contours, static_cast<int>(largest - contours.begin()), 255, cv::FILLED);
  area = cv::countNonZero(out);
  cv::Mat dark;
  cv::bitwise_and(out, mask, dark);
  solid = area > 0 ? static_cast<double>(cv::countNonZero(dark)) / area : 0;
  return out;
}

bool touches_border(const cv::Mat& mask) {
  const int w = mask.cols, h = mask.rows;
  return cv::countNonZero(mask.row(0)) || cv::countNonZero(mask.row(h - 1)) ||
         cv::countNonZero(mask.col(0)) || cv::countNonZero(mask.col(w - 1));
}

// The printed circle around the drape: the Hough circle centred nearest the drape's centroid
// whose radius exceeds the drape's farthest pixel. Returns false when there is none.
bool reference_circle(const cv::Mat& grey, const cv::Point2d& c, double r_drape, cv::Vec3f& out) {
  std::vector<cv::Vec3f> circles;
  const int max_r = std::min(grey.cols, grey.rows) / 2;
  cv::HoughCircles(grey, circles, cv::HOUGH_GRADIENT, 1, 5, 100, 40,
                   static_cast<int>(r_drape * 0.98), max_r);
  double best = 1e300;
  for (const auto& k : circles) {
    const double d = std::hypot(k[0] - c.x, k[1] - c.y);
    if (d < 0.05 * k[2] && d < best) {
      best = d;
      out = k;
    }
  }
  return best < 1e300;
}

// The printed circle's radius refined to a fraction of a pixel: along 360 rays from the centre,
// the darkness-weighted mean radius of the line within +-4 % of the Hough radius (the line is
// darker than the ground on either side); the median over the rays.
double refine_radius(const cv::Mat& grey, const cv::Vec3f& c) {
  std::vector<double> found;
  const double r0 = c[2];
  for (int a = 0; a < 360; ++a) {
    const double ca = std::cos(a * CV_PI / 180), sa = std::sin(a * CV_PI / 180);
    double wsum = 0, rsum = 0, ground = 0;
    std::vector<std::pair<double, double>> samples;
    for (double r = 0.96 * r0; r <= 1.04 * r0; r += 0.25) {
      const int x = static_cast<int>(std::lround(c[0] + r * ca));
      const int y = static_cast<int>(std::lround(c[1] + r * sa));
      if (x < 0 || y < 0 || x >= grey.cols || y >= grey.rows) break;
      const double g = grey.at<uint8_t>(y, x);
      samples.emplace_back(r, g);
      ground = std::max(ground, g);
    }
    for (const auto& [r, g] : samples) {
      const double w = std::max(0.0, ground - g - 10);  // 10 grey levels of noise ignored
      wsum += w;
      rsum += w * r;
    }
    if (wsum > 0) found.push_back(rsum / wsum);
  }
  if (found.size() < 90) return r0;
  std::nth_element(found.begin(), found.begin() + found.size() / 2, found.end());
  return found[found.size() / 2];
}

// Resamples the mask around `centre` into a ShadowRaster of 0.5 mm cells.
void resample(const cv::Mat& mask, const cv::Point2d& centre, double mpp, double half_width,
              ShadowRaster& r) {
  r.reset(half_width, 0.0005);
  for (int j = 0; j < r.size; ++j)
    for (int i = 0; i < r.size; ++i) {
      const int px = static_cast<int>(std::lround(centre.x + r.centre(i) / mpp));
      const int py = static_cast<int>(std::lround(centre.y - r.centre(j) / mpp));
      if (px >= 0 && py >= 0 && px < mask.cols && py < mask.rows && mask.at<uint8_t>(py, px))
        r.cells[static_cast<size_t>(j) * r.size + i] = 1;
    }
  fill_holes(r);
}

}  // namespace

Result<PhotoShadow> shadow_from_photo(const std::string& path, const DrapeMeasureOptions& opt) {
  const cv::Mat img = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (img.empty()) return make_error(path, "cannot read it as an image (PNG, JPEG, ...)");
  if (img.cols < 100 || img.rows < 100)
    return make_error(path, "too small: a drape photo needs at least 100 x 100 pixels");
  int area = 0;
  double solid = 0;
  const cv::Mat mask = drape_mask(img, area, solid);
  const double frac = static_cast<double>(area) / (img.cols * img.rows);
  if (frac < 0.01 || solid < 0.5)
    return make_error(path, "no dark drape on a lighter background found");
  if (touches_border(mask)) return make_error(path, "the drape is cut off by the frame");
  if (frac > 0.8)
    return make_error(path, "the dark region covers " +
                                std::to_string(static_cast<int>(frac * 100)) +
                                " % of the photo: no background around the drape");
  const cv::Moments m = cv::moments(mask, true);
  const cv::Point2d c(m.m10 / m.m00, m.m01 / m.m00);
  std::vector<cv::Point> pts;
  cv::findNonZero(mask, pts);
  double r_px = 0;
  for (const auto& p : pts) r_px = std::max(r_px, std::hypot(p.x - c.x, p.y - c.y));
  cv::Vec3f circle;
  if (!reference_circle(img, c, r_px, circle))
    return make_error(path,
                      "no printed circle of the specimen's diameter around the drape: the "
                      "scale is unknown");
  PhotoShadow out;
  out.metres_per_pixel = opt.specimen_diameter / (2.0 * refine_radius(img, circle));
  resample(mask, cv::Point2d(circle[0], circle[1]), out.metres_per_pixel,
           0.5 * opt.specimen_diameter + 0.01, out.raster);
  out.measures = measure_shadow(out.raster, opt);
  if (!(out.measures.dc >= 0 && out.measures.dc <= 1))
    return make_error(path, "DC " + std::to_string(out.measures.dc) +
                                " is outside [0, 1]: the scale (the printed circle) is wrong");
  if (out.measures.r_max > 0.5 * opt.specimen_diameter * 1.02)
    out.warnings.push_back("the outline reaches past the specimen's radius: the scale may be off");
  return out;
}

std::string write_synthetic_photo(const ShadowRaster& s, const DrapeMeasureOptions& opt, double ppm,
                                  double noise, const std::string& path, bool print_circle) {
  const double half = 0.5 * opt.specimen_diameter + 0.03;
  const int n = static_cast<int>(std::ceil(2 * half * ppm));
  cv::Mat img(n, n, CV_8U, cv::Scalar(225));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double u = (x + 0.5) / ppm - half, w = half - (y + 0.5) / ppm;
      const int i = static_cast<int>(std::floor((u + s.half_width) / s.pixel));
      const int j = static_cast<int>(std::floor((w + s.half_width) / s.pixel));
      if (i >= 0 && j >= 0 && i < s.size && j < s.size && s.at(i, j)) img.at<uint8_t>(y, x) = 45;
    }
  if (print_circle)
    cv::circle(img, cv::Point(n / 2, n / 2),
               static_cast<int>(std::lround(0.5 * opt.specimen_diameter * ppm)), cv::Scalar(120), 2,
               cv::LINE_AA);
  if (noise > 0) {
    cv::Mat nz(img.size(), CV_16S);
    cv::theRNG().state = 12345;
    cv::randn(nz, 0, noise);
    cv::Mat sum;
    img.convertTo(sum, CV_16S);
    sum += nz;
    sum.convertTo(img, CV_8U);
  }
  try {
    if (!cv::imwrite(path, img)) return path + ": cannot write the image";
  } catch (const cv::Exception& e) {
    return path + ": cannot write the image (" + e.what() + ")";
  }
  return {};
}

}  // namespace drape::sim
