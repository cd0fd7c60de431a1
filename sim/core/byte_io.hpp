// Little-endian binary encoding shared by the session's files (the journal, the checkpoints):
// integers little-endian, doubles their IEEE-754 bits, strings and arrays a u32 count and the
// items. Reading checks every bound: `ok` turns false on the first short or oversized read and
// stays false; the values read after it are zeros.
#pragma once

#include <Eigen/Geometry>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "sim/core/scene_objects.hpp"
#include "sim/core/types.hpp"

namespace drape::sim {

// Scalars of arithmetic type T (double, float, integers) as little-endian bytes: a copy of the
// memory on a little-endian host, byte by byte otherwise.
template <class T>
void copy_little_endian(unsigned char* to, const unsigned char* from, size_t count) {
  if constexpr (std::endian::native == std::endian::little) {
    if (count > 0) std::memcpy(to, from, count * sizeof(T));
  } else {
    for (size_t k = 0; k < count; ++k)
      for (size_t b = 0; b < sizeof(T); ++b)
        to[k * sizeof(T) + b] = from[k * sizeof(T) + sizeof(T) - 1 - b];
  }
}

// True when the n doubles from p are all finite (a state read back must not bring NaN or inf).
inline bool all_finite(const double* p, size_t n) {
  for (size_t k = 0; k < n; ++k)
    if (!std::isfinite(p[k])) return false;
  return true;
}

struct ByteWriter {
  std::vector<unsigned char> b;
  void u8(uint8_t v) { b.push_back(v); }
  void u32(uint32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(static_cast<unsigned char>(v >> (8 * i)));
  }
  void u64(uint64_t v) {
    for (int i = 0; i < 8; ++i) b.push_back(static_cast<unsigned char>(v >> (8 * i)));
  }
  void i32(int32_t v) { u32(static_cast<uint32_t>(v)); }
  void f64(double d) {
    uint64_t v;
    std::memcpy(&v, &d, 8);
    u64(v);
  }
  void str(const std::string& s) {
    u32(static_cast<uint32_t>(s.size()));
    b.insert(b.end(), s.begin(), s.end());
  }
  // Named text fields (a file's header): the count, then each key and value.
  void fields(const std::map<std::string, std::string>& f) {
    u32(static_cast<uint32_t>(f.size()));
    for (const auto& [k, v] : f) {
      str(k);
      str(v);
    }
  }
  void vec3(const Vec3& v) {
    for (int k = 0; k < 3; ++k) f64(v[k]);
  }
  void vec2(const Vec2& v) {
    for (int k = 0; k < 2; ++k) f64(v[k]);
  }
  void hand(const HandProxy& h) {
    u32(static_cast<uint32_t>(h.id));
    u8(static_cast<uint8_t>((h.tracked ? 1 : 0) | (h.collides ? 2 : 0)));
    vec3(h.position);
    f64(h.orientation.w());
    f64(h.orientation.x());
    f64(h.orientation.y());
    f64(h.orientation.z());
    vec3(h.tip);
    f64(h.radius);
  }
  // An array of `count` items of `per_item` scalars T each (a Vec3 is 3 doubles): the item
  // count, then the scalars.
  template <class T>
  void array(const T* v, size_t count, size_t per_item = 1) {
    u32(static_cast<uint32_t>(count));
    const size_t at = b.size(), scalars = count * per_item;
    b.resize(at + scalars * sizeof(T));
    copy_little_endian<T>(b.data() + at, reinterpret_cast<const unsigned char*>(v), scalars);
  }
};

struct ByteReader {
  const unsigned char* p;
  size_t n, i = 0;
  bool ok = true;
  bool need(size_t k) {
    if (!ok || n - i < k) ok = false;
    return ok;
  }
  uint8_t u8() { return need(1) ? p[i++] : 0; }
  uint32_t u32() {
    if (!need(4)) return 0;
    uint32_t v = 0;
    for (int k = 0; k < 4; ++k) v |= static_cast<uint32_t>(p[i++]) << (8 * k);
    return v;
  }
  uint64_t u64() {
    if (!need(8)) return 0;
    uint64_t v = 0;
    for (int k = 0; k < 8; ++k) v |= static_cast<uint64_t>(p[i++]) << (8 * k);
    return v;
  }
  int32_t i32() { return static_cast<int32_t>(u32()); }
  double f64() {
    const uint64_t v = u64();
    double d;
    std::memcpy(&d, &v, 8);
    return d;
  }
  std::string str() {
    const uint32_t len = u32();
    if (!need(len)) return {};
    std::string s(reinterpret_cast<const char*>(p + i), len);
    i += len;
    return s;
  }
  // An item count of items at least `item_bytes` long each: a count the remaining bytes cannot
  // hold is a malformed file (no allocation is made for it).
  uint32_t count(size_t item_bytes) {
    const uint32_t c = u32();
    if (ok && item_bytes > 0 && c > (n - i) / item_bytes) ok = false;
    return ok ? c : 0;
  }
  Vec3 vec3() {
    Vec3 v;
    for (int k = 0; k < 3; ++k) v[k] = f64();
    return v;
  }
  Vec2 vec2() {
    Vec2 v;
    for (int k = 0; k < 2; ++k) v[k] = f64();
    return v;
  }
  HandProxy hand() {
    HandProxy h;
    h.id = static_cast<int>(u32());
    const uint8_t flags = u8();
    h.tracked = flags & 1;
    h.collides = (flags & 2) != 0;
    h.position = vec3();
    const double w = f64(), x = f64(), y = f64(), z = f64();
    h.orientation = Eigen::Quaterniond(w, x, y, z);
    h.tip = vec3();
    h.radius = f64();
    return h;
  }
  // An array written by ByteWriter::array into `out` (items of `per_item` scalars T): false
  // (and `ok` false) when the count exceeds the bytes left.
  template <class T, class Item>
  bool array(std::vector<Item>& out, size_t per_item = 1) {
    const uint32_t c = count(per_item * sizeof(T));
    if (!ok || sizeof(Item) != per_item * sizeof(T)) return ok = false;
    out.resize(c);
    copy_little_endian<T>(reinterpret_cast<unsigned char*>(out.data()), p + i, c * per_item);
    i += c * per_item * sizeof(T);
    return true;
  }
};

}  // namespace drape::sim
