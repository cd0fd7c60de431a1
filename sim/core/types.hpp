// Basic math and error types shared by the simulation core (SI units, stage space: y up,
// floor at y = 0, metres).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <variant>

namespace drape::sim {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

inline constexpr double kGravity = 9.80665;  // m/s^2, method eq. 3-2

// Error with a message that names the file and field at fault.
struct Error {
  std::string message;
};

// Result of loading or parsing: a value or an Error. [[nodiscard]] so a failed load is never
// silently ignored.
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}  // NOLINT(google-explicit-constructor)
  Result(Error e) : v_(std::move(e)) {}      // NOLINT(google-explicit-constructor)
  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  T& value() & { return std::get<0>(v_); }
  const T& value() const& { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  const std::string& error() const { return std::get<1>(v_).message; }

 private:
  std::variant<T, Error> v_;
};

inline Error make_error(std::string where, const std::string& what) {
  return Error{std::move(where) + ": " + what};
}

}  // namespace drape::sim
