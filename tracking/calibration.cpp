#include "tracking/calibration.hpp"

#include <Eigen/SVD>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

namespace drape::tracking {

HandFrame Calibration::apply(const HandFrame& f) const {
  HandFrame o = f;
  o.palm.position = apply(f.palm.position);
  o.palm.orientation = Quat(rotation * f.palm.orientation.toRotationMatrix());
  if (o.has_joints)
    for (auto& j : o.joints) j = apply(j);
  return o;
}

namespace {
void set(std::string* e, const std::string& m) {
  if (e) *e = m;
}
}  // namespace

std::optional<Calibration> calibrate(const std::vector<Vec3>& src, const std::vector<Vec3>& dst,
                                     std::string* error) {
  if (src.size() != dst.size()) {
    set(error, "calibration: point lists differ in size");
    return std::nullopt;
  }
  const int n = static_cast<int>(src.size());
  if (n < 3) {
    set(error, "calibration: need at least 3 point pairs, got " + std::to_string(n));
    return std::nullopt;
  }
  Eigen::Matrix3Xd X(3, n), Y(3, n);
  for (int i = 0; i < n; ++i) {
    if (!src[i].allFinite() || !dst[i].allFinite()) {
      set(error, "calibration: pair " + std::to_string(i) + " is not finite");
      return std::nullopt;
    }
    X.col(i) = src[i];
    Y.col(i) = dst[i];
  }
  const Vec3 mx = X.rowwise().mean(), my = Y.rowwise().mean();
  X.colwise() -= mx;
  Y.colwise() -= my;
  const double var_x = X.squaredNorm() / n;
  const Eigen::Matrix3d cov = Y * X.transpose() / n;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3 sv = svd.singularValues();
  if (var_x < 1e-12 || sv(1) < 1e-9 * std::max(1.0, sv(0))) {
    set(error, "calibration: points are coincident or collinear");
    return std::nullopt;
  }
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) S(2, 2) = -1;
  Calibration c;
  c.rotation = svd.matrixU() * S * svd.matrixV().transpose();
  c.scale = (sv.asDiagonal() * S).trace() / var_x;
  c.translation = my - c.scale * c.rotation * mx;
  c.pairs = n;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double r = (c.apply(src[i]) - dst[i]).norm();
    sum += r * r;
    c.max_residual = std::max(c.max_residual, r);
  }
  c.rms_residual = std::sqrt(sum / n);
  return c;
}

bool save_calibration(const Calibration& c, const std::string& path, std::string* error) {
  nlohmann::json j;
  j["format"] = "drape-calibration";
  j["version"] = 1;
  j["scale"] = c.scale;
  j["rotation"] = nlohmann::json::array();
  for (int r = 0; r < 3; ++r)
    j["rotation"].push_back({c.rotation(r, 0), c.rotation(r, 1), c.rotation(r, 2)});
  j["translation"] = {c.translation.x(), c.translation.y(), c.translation.z()};
  j["rms_residual_m"] = c.rms_residual;
  j["max_residual_m"] = c.max_residual;
  j["pairs"] = c.pairs;
  std::ofstream f(path);
  if (!f) {
    set(error, path + ": cannot open for writing");
    return false;
  }
  f << j.dump(2) << "\n";
  return static_cast<bool>(f);
}

std::optional<Calibration> load_calibration(const std::string& path, std::string* error) {
  std::ifstream f(path);
  if (!f) {
    set(error, path + ": cannot open");
    return std::nullopt;
  }
  nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    set(error, path + ": not valid JSON");
    return std::nullopt;
  }
  auto num = [&](const nlohmann::json& v, const std::string& field, double& out) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      set(error, path + ": field '" + field + "' must be a finite number");
      return false;
    }
    out = v.get<double>();
    return true;
  };
  Calibration c;
  if (!j.contains("scale") || !num(j["scale"], "scale", c.scale)) {
    if (!j.contains("scale")) set(error, path + ": missing field 'scale'");
    return std::nullopt;
  }
  if (!(c.scale > 0)) {
    set(error, path + ": field 'scale' must be > 0");
    return std::nullopt;
  }
  const auto& R = j.value("rotation", nlohmann::json());
  if (!R.is_array() || R.size() != 3) {
    set(error, path + ": field 'rotation' must be a 3x3 array");
    return std::nullopt;
  }
  for (int r = 0; r < 3; ++r) {
    if (!R[r].is_array() || R[r].size() != 3) {
      set(error, path + ": field 'rotation' must be a 3x3 array");
      return std::nullopt;
    }
    for (int k = 0; k < 3; ++k)
      if (!num(R[r][k], "rotation", c.rotation(r, k))) return std::nullopt;
  }
  if ((c.rotation * c.rotation.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-6 ||
      c.rotation.determinant() < 0) {
    set(error, path + ": field 'rotation' is not a rotation matrix");
    return std::nullopt;
  }
  const auto& T = j.value("translation", nlohmann::json());
  if (!T.is_array() || T.size() != 3) {
    set(error, path + ": field 'translation' must be an array of 3 numbers");
    return std::nullopt;
  }
  for (int k = 0; k < 3; ++k)
    if (!num(T[k], "translation", c.translation(k))) return std::nullopt;
  c.rms_residual = j.value("rms_residual_m", 0.0);
  c.max_residual = j.value("max_residual_m", 0.0);
  c.pairs = j.value("pairs", 0);
  return c;
}

}  // namespace drape::tracking
