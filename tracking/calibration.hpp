// Calibration of an external tracker's frame to the XR stage from >= 3 point pairs:
// similarity transform (scale, rotation, translation) by Umeyama's method.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "tracking/types.hpp"

namespace drape::tracking {

struct Calibration {
  double scale = 1.0;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Vec3 translation = Vec3::Zero();
  double rms_residual = 0.0;  // metres, over the pairs used
  double max_residual = 0.0;
  int pairs = 0;

  Vec3 apply(const Vec3& p) const { return scale * (rotation * p) + translation; }
  HandFrame apply(const HandFrame& f) const;
};

// src[i] (tracker frame) -> dst[i] (stage). Returns nullopt with `error` set when fewer than
// 3 pairs, non-finite values or degenerate (collinear) points.
std::optional<Calibration> calibrate(const std::vector<Vec3>& src, const std::vector<Vec3>& dst,
                                     std::string* error = nullptr);

bool save_calibration(const Calibration& c, const std::string& path, std::string* error = nullptr);
std::optional<Calibration> load_calibration(const std::string& path, std::string* error = nullptr);

}  // namespace drape::tracking
