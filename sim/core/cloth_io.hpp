// The cloth and the lists it is made of in the little-endian encoding of byte_io.hpp: what a
// session's checkpoints (sim/ops/checkpoint.hpp) and a solver's saved state write. Readers check
// every bound through ByteReader (its `ok` turns false); a cloth read back is not validated here
// (Cloth::validate(), and the checkpoint's own checks).
#pragma once

#include <cstdint>
#include <vector>

#include "sim/core/byte_io.hpp"
#include "sim/core/cloth.hpp"

namespace drape::sim {

// A list: its u32 count, then each item as `put` writes it.
template <class T, class F>
void put_list(ByteWriter& o, const std::vector<T>& v, F put) {
  o.u32(static_cast<uint32_t>(v.size()));
  for (const T& x : v) put(o, x);
}
// `min_bytes`: the smallest encoding of one item (bounds the count by the bytes left).
template <class T, class F>
void get_list(ByteReader& in, std::vector<T>& v, size_t min_bytes, F get) {
  const uint32_t n = in.count(min_bytes);
  v.clear();
  v.reserve(n);
  for (uint32_t i = 0; i < n && in.ok; ++i) v.push_back(get(in));
}

void put_vec3s(ByteWriter& o, const std::vector<Vec3>& v);
void get_vec3s(ByteReader& in, std::vector<Vec3>& v);
void put_vec2s(ByteWriter& o, const std::vector<Vec2>& v);
void get_vec2s(ByteReader& in, std::vector<Vec2>& v);
void put_ints(ByteWriter& o, const std::vector<int32_t>& v);
void get_ints(ByteReader& in, std::vector<int32_t>& v);
void put_doubles(ByteWriter& o, const std::vector<double>& v);
void get_doubles(ByteReader& in, std::vector<double>& v);
void put_bytes(ByteWriter& o, const std::vector<uint8_t>& v);
void get_bytes(ByteReader& in, std::vector<uint8_t>& v);

// The cloth's parts and the whole cloth (topology, state, fabric, topology version, incidence).
void put_topology(ByteWriter& o, const ClothTopology& t);
void get_topology(ByteReader& in, ClothTopology& t);
void put_state(ByteWriter& o, const ClothState& s);
void get_state(ByteReader& in, ClothState& s);
void put_fabric(ByteWriter& o, const FabricParams& f);
void get_fabric(ByteReader& in, FabricParams& f);
void put_incidence(ByteWriter& o, const ClothIncidence& c);
void get_incidence(ByteReader& in, ClothIncidence& c);
void put_cloth(ByteWriter& o, const Cloth& c);
void get_cloth(ByteReader& in, Cloth& c);

}  // namespace drape::sim
