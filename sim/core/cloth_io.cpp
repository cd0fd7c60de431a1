// The cloth's encoding (see header).
#include "sim/core/cloth_io.hpp"

namespace drape::sim {

void put_vec3s(ByteWriter& o, const std::vector<Vec3>& v) {
  put_list(o, v, [](ByteWriter& w, const Vec3& x) { w.vec3(x); });
}
void get_vec3s(ByteReader& in, std::vector<Vec3>& v) {
  get_list(in, v, 24, [](ByteReader& r) { return r.vec3(); });
}
void put_vec2s(ByteWriter& o, const std::vector<Vec2>& v) {
  put_list(o, v, [](ByteWriter& w, const Vec2& x) { w.vec2(x); });
}
void get_vec2s(ByteReader& in, std::vector<Vec2>& v) {
  get_list(in, v, 16, [](ByteReader& r) { return r.vec2(); });
}
void put_ints(ByteWriter& o, const std::vector<int32_t>& v) {
  put_list(o, v, [](ByteWriter& w, int32_t x) { w.i32(x); });
}
void get_ints(ByteReader& in, std::vector<int32_t>& v) {
  get_list(in, v, 4, [](ByteReader& r) { return r.i32(); });
}
void put_doubles(ByteWriter& o, const std::vector<double>& v) {
  put_list(o, v, [](ByteWriter& w, double x) { w.f64(x); });
}
void get_doubles(ByteReader& in, std::vector<double>& v) {
  get_list(in, v, 8, [](ByteReader& r) { return r.f64(); });
}
void put_bytes(ByteWriter& o, const std::vector<uint8_t>& v) {
  put_list(o, v, [](ByteWriter& w, uint8_t x) { w.u8(x); });
}
void get_bytes(ByteReader& in, std::vector<uint8_t>& v) {
  get_list(in, v, 1, [](ByteReader& r) { return r.u8(); });
}

void put_topology(ByteWriter& o, const ClothTopology& t) {
  put_list(o, t.triangles, [](ByteWriter& w, const std::array<int32_t, 3>& tri) {
    for (int32_t v : tri) w.i32(v);
  });
  put_vec2s(o, t.material);
  put_ints(o, t.vertex_zone);
  put_ints(o, t.triangle_zone);
  put_ints(o, t.vertex_origin);
  o.f64(t.spacing);
  o.i32(t.grid_nx);
  o.i32(t.grid_ny);
}
void get_topology(ByteReader& in, ClothTopology& t) {
  get_list(in, t.triangles, 12, [](ByteReader& r) {
    std::array<int32_t, 3> tri{};
    for (int32_t& v : tri) v = r.i32();
    return tri;
  });
  get_vec2s(in, t.material);
  get_ints(in, t.vertex_zone);
  get_ints(in, t.triangle_zone);
  get_ints(in, t.vertex_origin);
  t.spacing = in.f64();
  t.grid_nx = in.i32();
  t.grid_ny = in.i32();
}

void put_state(ByteWriter& o, const ClothState& s) {
  put_vec3s(o, s.x);
  put_vec3s(o, s.x_prev);
  put_vec3s(o, s.v);
  put_doubles(o, s.mass);
  put_doubles(o, s.inv_mass);
  put_bytes(o, s.flags);
  o.f64(s.time);
}
void get_state(ByteReader& in, ClothState& s) {
  get_vec3s(in, s.x);
  get_vec3s(in, s.x_prev);
  get_vec3s(in, s.v);
  get_doubles(in, s.mass);
  get_doubles(in, s.inv_mass);
  get_bytes(in, s.flags);
  s.time = in.f64();
}

void put_fabric(ByteWriter& o, const FabricParams& f) {
  o.str(f.name);
  for (double d : {f.areal_density, f.thickness, f.stretch_warp, f.stretch_weft, f.shear,
                   f.bending_warp, f.bending_weft, f.rayleigh_damping})
    o.f64(d);
}
void get_fabric(ByteReader& in, FabricParams& f) {
  f.name = in.str();
  for (double* d : {&f.areal_density, &f.thickness, &f.stretch_warp, &f.stretch_weft, &f.shear,
                    &f.bending_warp, &f.bending_weft, &f.rayleigh_damping})
    *d = in.f64();
}

void put_incidence(ByteWriter& o, const ClothIncidence& c) {
  o.u8(c.built ? 1 : 0);
  o.u64(c.version);
  o.i32(c.num_triangles);
  for (const auto* v : {&c.start, &c.count, &c.tris, &c.component}) put_ints(o, *v);
  o.i32(c.components);
}
void get_incidence(ByteReader& in, ClothIncidence& c) {
  c.built = in.u8() != 0;
  c.version = in.u64();
  c.num_triangles = in.i32();
  for (auto* v : {&c.start, &c.count, &c.tris, &c.component}) get_ints(in, *v);
  c.components = in.i32();
}

void put_cloth(ByteWriter& o, const Cloth& c) {
  put_topology(o, c.topo);
  put_state(o, c.state);
  put_fabric(o, c.fabric);
  o.u64(c.topology_version);
  put_incidence(o, c.incidence);
}
void get_cloth(ByteReader& in, Cloth& c) {
  get_topology(in, c.topo);
  get_state(in, c.state);
  get_fabric(in, c.fabric);
  c.topology_version = in.u64();
  get_incidence(in, c.incidence);
}

}  // namespace drape::sim
