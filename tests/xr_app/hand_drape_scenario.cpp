// Writes the scenario of a hand-draped tight-skirt panel on the 9AR form (test data of
// xr_drape_hand_drape: assets/scenarios/hand_drape_{front,back}.json), the way a pattern maker
// drapes one: the left hand maps the muslin onto the form along the grain from the centre line
// (thumb-ring pinch; in front of the form: centre front, behind it: centre back), the right hand
// pins it 1 cm below the waist and at the hip, 3 cm inside each side line (thumb-middle pinch),
// cuts down both side lines, trims above the waist line and cuts down the centre line
// (thumb-ring pinch toggles each cut). The hands' pinch points follow the form's lines, computed
// from the form; the scenario holds the palm poses the simulated runtime plays.
//
//   hand_drape_scenario front|back OUT.json
#include <cmath>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sim/draping/mapping.hpp"
#include "sim/form/dress_form.hpp"

namespace {

using drape::sim::ArcTable;
using drape::sim::DressForm;
using drape::sim::MappingSurface;
using drape::sim::Vec3;
using json = nlohmann::json;

constexpr double kPi = 3.14159265358979323846;
constexpr double kPanel = 0.5;     // the scripted scene's panel (m)
constexpr int kRes = 51;           // drape run --cloth-res: 10 mm grid
constexpr double kOffset = 0.002;  // the scene's collision offset (m)
constexpr double kSpeed = 0.25;    // m/s of the hand along a cut
constexpr double kRate = 90;       // frames per second

// The pinch point (midpoint of the thumb and index tips) of the runtime's generated right hand
// in its palm frame, per hand shape (xr_app/mock_runtime/scenario.cpp; the left hand mirrors x).
Vec3 pinch_point(const std::string& shape, bool left) {
  Vec3 p(-0.042, -0.011, -0.08);                                    // open
  if (shape == "pinch_middle") p = Vec3(-0.012, -0.0025, -0.1225);  // thumb under the middle tip
  if (shape == "pinch_ring") p = Vec3(-0.001, -0.0025, -0.115);     // thumb under the ring tip
  if (left) p.x() = -p.x();
  return p;
}

// A hand's keyframes; each key puts the pinch point at a target with the fingers pointing
// into the form at angle theta (palm turned by theta about +y).
struct Track {
  bool left = false;
  json keys = json::array();
  int frame = 0;

  void key(int f, const Vec3& target, double theta, const std::string& shape) {
    const double c = std::cos(theta), s = std::sin(theta);
    const Vec3 o = pinch_point(shape, left);
    const Vec3 ro(c * o.x() + s * o.z(), o.y(), -s * o.x() + c * o.z());  // R_y(theta) o
    const Vec3 palm = target - ro;
    keys.push_back({{"frame", f},
                    {"palm",
                     {{"position", {palm.x(), palm.y(), palm.z()}},
                      {"orientation", {0.0, std::sin(theta / 2), 0.0, std::cos(theta / 2)}}}},
                    {"pinch", 0.0},
                    {"shape", shape}});
  }
  // Holds a shape at the target for 12 frames (the gesture fires), then opens the hand.
  void gesture(const Vec3& target, double theta, const std::string& shape) {
    key(frame, target, theta, "open");
    key(frame + 1, target, theta, shape);
    key(frame + 12, target, theta, shape);
    key(frame + 13, target, theta, "open");
    frame += 13;
  }
};

struct Drape {
  const DressForm& form;
  MappingSurface surf;
  double tc;  // centre line angle
  double waist, hip;
  Drape(const DressForm& f, double centre)
      : form(f),
        surf(f, 0.0, false),
        tc(centre),
        waist(f.landmarks().waist_y),
        hip(f.landmarks().hip_y) {}

  Vec3 normal(double theta) const { return DressForm::direction(theta); }
  Vec3 on_cloth(double y, double theta) const {
    return surf.point(y, theta) + normal(theta) * kOffset;
  }
  double top() const { return waist + 0.03; }
  double bottom() const { return top() - kPanel; }
};

// Walks the hand along the points (each with its angle) at kSpeed, cutting: a thumb-ring pinch
// at the first point starts the stroke, one at the last ends it.
void cut(Track& t, const std::vector<std::pair<Vec3, double>>& pts) {
  const auto& [p0, a0] = pts.front();
  t.frame += 20;
  t.key(t.frame, p0 + 0.08 * DressForm::direction(a0), a0, "open");
  t.frame += 20;
  t.gesture(p0, a0, "pinch_ring");
  for (size_t i = 1; i < pts.size(); ++i) {
    const double d = (pts[i].first - pts[i - 1].first).norm();
    t.frame += std::max(1, static_cast<int>(std::lround(d / kSpeed * kRate)));
    t.key(t.frame, pts[i].first, pts[i].second, "open");
  }
  t.frame += 5;
  t.gesture(pts.back().first, pts.back().second, "pinch_ring");
  t.frame += 15;
  t.key(t.frame, pts.back().first + 0.08 * DressForm::direction(pts.back().second),
        pts.back().second, "open");
}

// Pins the cloth node at `part` of the way from the centre line to `inset` inside the side line
// at height y (the map puts the nodes there: the pinch point on a node, so the pin moves
// nothing).
void pin(Track& t, const Drape& d, double y, double side_theta, double inset, double part) {
  const double sp = kPanel / (kRes - 1);
  const double yj = d.top() - std::round((d.top() - y) / sp) * sp;
  const int dir = std::sin(side_theta - d.tc) > 0 ? +1 : -1;
  const ArcTable T = ArcTable::build(d.surf, yj, d.tc, dir);
  const double l = std::round(part * (T.arc_at(side_theta) - inset) / sp) * sp;
  const double th = T.theta_at(l);
  const Vec3 p = d.on_cloth(yj, th);
  t.frame += 12;
  t.key(t.frame, p + 0.05 * d.normal(th), th, "open");
  t.frame += 12;
  t.gesture(p, th, "pinch_middle");
  t.frame += 12;
  t.key(t.frame, p + 0.05 * d.normal(th), th, "open");
}

std::vector<std::pair<Vec3, double>> vertical(const Drape& d, double theta, double y0, double y1) {
  std::vector<std::pair<Vec3, double>> pts;
  const int n = static_cast<int>(std::ceil((y0 - y1) / 0.02));
  for (int i = 0; i <= n; ++i) pts.push_back({d.on_cloth(y0 + (y1 - y0) * i / n, theta), theta});
  return pts;
}

json scenario(const DressForm& form, bool back) {
  const Drape d(form, back ? kPi : 0.0);
  const double zs = back ? -1 : 1;
  const double left_side = kPi / 2, right_side = 3 * kPi / 2;
  Track L{true}, R{false};
  // Map: the left hand in front of (behind) the form.
  L.key(0, Vec3(0.35, 1.0, 0.6 * zs), d.tc, "open");
  L.frame = 20;
  L.gesture(Vec3(0.15, d.waist - 0.15, 0.3 * zs), d.tc, "pinch_ring");
  L.key(L.frame + 20, Vec3(0.35, 1.0, 0.6 * zs), d.tc, "open");
  // Pins, then the cuts.
  R.key(0, Vec3(-0.35, 1.0, 0.6 * zs), d.tc, "open");
  R.frame = 60;
  for (double side : {right_side, left_side})
    for (double y : {d.waist - 0.01, d.hip}) pin(R, d, y, side, 0.03, 1.0);
  for (double side : {right_side, left_side})
    cut(R, vertical(d, side, d.top() + 0.03, d.bottom() - 0.08));
  std::vector<std::pair<Vec3, double>> trim;  // 1 cm above the waist, side to side
  const double reach = kPi / 2 - 0.1;
  for (int i = 0; i <= 30; ++i) {
    const double th = d.tc - reach + 2 * reach * i / 30;
    trim.push_back({d.on_cloth(d.waist + 0.01, th), th});
  }
  cut(R, trim);
  cut(R, vertical(d, d.tc, d.waist + 0.005, d.bottom() - 0.08));
  R.frame += 20;
  R.key(R.frame, Vec3(-0.35, 1.0, 0.6 * zs), d.tc, "open");
  const int end = R.frame + 60;
  const json head_q = back ? json{0.0, 0.9962, 0.0872, 0.0} : json{-0.0872, 0.0, 0.0, 0.9962};
  json s;
  s["name"] = back ? "hand_drape_back" : "hand_drape_front";
  s["description"] =
      std::string("Written by tests/xr_app/hand_drape_scenario.cpp (do not edit by hand). ") +
      "The tight skirt's " + (back ? "back" : "front") +
      " draped by hand on the 9AR form (drape run --cloth-res 51): the left hand's thumb-ring "
      "pinch maps the 0.5 m muslin onto the form along the grain from the centre " +
      (back ? "back (the hand behind the form)" : "front") +
      "; the right hand pins it 1 cm below the waist line and at the hip line, 3 cm inside "
      "each side line (thumb-middle pinch), cuts "
      "down the right and the left side line, trims 1 cm above the "
      "waist line from side to side and cuts down the centre line (a thumb-ring pinch starts and "
      "ends each cut). tests/xr_app/drape_hand_drape_test.sh compares the two half pieces' hip "
      "and waist widths with drape pattern --design tight-skirt.";
  s["end_after_frames"] = end;
  s["fast"] = true;
  s["head"] = {{{"frame", 0}, {"position", {0.0, 1.45, 1.1 * zs}}, {"orientation", head_q}}};
  s["hands"] = {{"left", L.keys}, {"right", R.keys}};
  s["audio"] = json::array();
  s["events"] = json::array();
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string which = argc == 3 ? argv[1] : "";
  if (which != "front" && which != "back") {
    std::cerr << "usage: hand_drape_scenario front|back OUT.json\n";
    return 2;
  }
  auto m = drape::sim::measurements_for_size("9AR");
  if (!m) return std::cerr << m.error() << "\n", 1;
  auto form = DressForm::from_measurements(*m);
  if (!form) return std::cerr << form.error() << "\n", 1;
  std::ofstream f(argv[2]);
  f << scenario(*form, which == "back").dump(1) << "\n";
  if (!f) return std::cerr << argv[2] << ": write failed\n", 1;
  return 0;
}
