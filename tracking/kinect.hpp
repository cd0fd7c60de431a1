// Kinect (v1) hands from depth: libfreenect 11-bit depth -> millimetres -> OpenCV hand
// segmentation (nearest depth band, contours, palm centre by distance transform) -> 3D with
// the Kinect depth intrinsics.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "tracking/hand_source.hpp"

namespace cv {
class Mat;
}

namespace drape::tracking {

// Depth camera intrinsics (Kinect v1 depth camera, N. Burrus' calibration) at 640x480.
struct DepthIntrinsics {
  double fx = 594.214, fy = 591.040, cx = 339.308, cy = 242.739;
  // Pixel (u, v) at depth z (m) -> camera point; right-handed, y up, looking along -z
  // (the OpenXR convention), so a point in front of the camera has negative z.
  Vec3 unproject(double u, double v, double z) const {
    return Vec3((u - cx) * z / fx, -(v - cy) * z / fy, -z);
  }
};

// Kinect raw 11-bit disparity <-> metres (Burrus' fit). raw 2047 = no reading.
double kinect_raw_to_m(uint16_t raw);
uint16_t kinect_m_to_raw(double metres);

struct SegmenterParams {
  double min_depth = 0.4, max_depth = 3.0;  // m: valid range
  double band = 0.15;                       // m: hand pixels are within this of the nearest point
  double min_area_m2 = 0.004;               // metric blob area (about 6x6 cm) to count as a hand
  int max_hands = 2;
};

struct DetectedHand {
  double u = 0, v = 0;   // palm centre in pixels
  double radius_px = 0;  // inscribed circle radius (distance transform maximum)
  double depth = 0;      // m
  double area_m2 = 0;
  Vec3 position;  // camera frame (see DepthIntrinsics)
};

class HandSegmenter {
 public:
  explicit HandSegmenter(SegmenterParams p = {}, DepthIntrinsics k = {}) : p_(p), k_(k) {}
  // depth_mm: CV_16UC1, 0 = invalid. Returns hands sorted by image u (left to right).
  std::vector<DetectedHand> detect(const cv::Mat& depth_mm);
  // 640x480 raw 11-bit buffer (libfreenect FREENECT_DEPTH_11BIT) -> frames (user facing the
  // camera: the hand on the image left is the user's right hand).
  std::vector<HandFrame> process_raw11(const uint16_t* raw, int width, int height, double time);

 private:
  SegmenterParams p_;
  DepthIntrinsics k_;
  std::vector<uint16_t> lut_;
};

// Live Kinect via libfreenect on its own thread. A missing device or library error gives a
// clear status (Unavailable) and the other sources keep working; the stream's end (a recording's
// last frame, a device gone) is an Error status naming which, a stream that stalls for over 1 s
// a NoData status. Under fakenect
// (FAKENECT_PATH + LD_LIBRARY_PATH, see docs/tracking.md) it replays a recording.
// `fakenect_recording`: the recording's directory when the program runs under fakenect (the
// executable passes on the FAKENECT_PATH that libfreenect's replay library reads itself). It is
// checked for INDEX.txt first, since fakenect exit()s on a missing recording; empty: no check.
class KinectSource : public HandSource {
 public:
  explicit KinectSource(SegmenterParams p = {}, int device_index = 0,
                        const std::string& fakenect_recording = {});
  ~KinectSource() override;
  KinectSource(const KinectSource&) = delete;
  KinectSource& operator=(const KinectSource&) = delete;
  std::string name() const override { return "kinect"; }
  std::vector<HandFrame> poll() override;
  SourceStatus status() const override;
  uint64_t frames_processed() const;
  bool running() const;
  struct Impl;  // libfreenect state (public so the C callback can reach it)

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace drape::tracking
