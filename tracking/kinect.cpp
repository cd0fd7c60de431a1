#include "tracking/kinect.hpp"

#include <libfreenect.h>
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <utility>

namespace drape::tracking {

double kinect_raw_to_m(uint16_t raw) {
  if (raw >= 2047) return 0.0;
  const double d = raw * -0.0030711016 + 3.3309495161;
  return d > 0 ? 1.0 / d : 0.0;
}

uint16_t kinect_m_to_raw(double m) {
  if (!(m > 0)) return 2047;
  const double r = (1.0 / m - 3.3309495161) / -0.0030711016;
  return static_cast<uint16_t>(std::clamp(std::lround(r), 0L, 2047L));
}

std::vector<DetectedHand> HandSegmenter::detect(const cv::Mat& depth) {
  std::vector<DetectedHand> hands;
  CV_Assert(depth.type() == CV_16UC1);
  const uint16_t lo = static_cast<uint16_t>(p_.min_depth * 1000);
  const uint16_t hi = static_cast<uint16_t>(p_.max_depth * 1000);
  // Nearest valid depth (row scan; cheaper than masks).
  uint16_t nearest = 0xffff;
  for (int r = 0; r < depth.rows; ++r) {
    const uint16_t* row = depth.ptr<uint16_t>(r);
    for (int c = 0; c < depth.cols; ++c)
      if (row[c] >= lo && row[c] <= hi && row[c] < nearest) nearest = row[c];
  }
  if (nearest == 0xffff) return hands;
  const uint16_t far = static_cast<uint16_t>(std::min<double>(hi, nearest + p_.band * 1000));
  cv::Mat mask;
  cv::inRange(depth, cv::Scalar(nearest), cv::Scalar(far), mask);
  cv::morphologyEx(mask, mask, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  struct Blob {
    double area;
    int idx;
  };
  std::vector<Blob> blobs;
  for (int i = 0; i < static_cast<int>(contours.size()); ++i)
    blobs.push_back({cv::contourArea(contours[i]), i});
  std::sort(blobs.begin(), blobs.end(), [](auto& a, auto& b) { return a.area > b.area; });
  for (const auto& b : blobs) {
    if (static_cast<int>(hands.size()) >= p_.max_hands) break;
    const cv::Rect box = cv::boundingRect(contours[b.idx]) & cv::Rect(0, 0, depth.cols, depth.rows);
    // Blob mask inside its box (only this contour, filled), padded by 1 so the distance
    // transform sees a border.
    cv::Mat blob = cv::Mat::zeros(box.height + 2, box.width + 2, CV_8U);
    cv::drawContours(blob, contours, b.idx, cv::Scalar(255), cv::FILLED, cv::LINE_8, cv::noArray(),
                     0, cv::Point(1 - box.x, 1 - box.y));
    cv::Mat dist;
    cv::distanceTransform(blob, dist, cv::DIST_L2, 3);
    double maxv;
    cv::Point maxp;
    cv::minMaxLoc(dist, nullptr, &maxv, nullptr, &maxp);
    const int u = maxp.x - 1 + box.x, v = maxp.y - 1 + box.y;
    // Depth at the palm: median of in-band pixels in a small window around the centre.
    std::vector<uint16_t> zs;
    const int w = std::max(2, static_cast<int>(maxv / 2));
    for (int y = std::max(0, v - w); y <= std::min(depth.rows - 1, v + w); ++y)
      for (int x = std::max(0, u - w); x <= std::min(depth.cols - 1, u + w); ++x) {
        const uint16_t z = depth.at<uint16_t>(y, x);
        if (z >= nearest && z <= far) zs.push_back(z);
      }
    if (zs.empty()) continue;
    std::nth_element(zs.begin(), zs.begin() + zs.size() / 2, zs.end());
    const double z = zs[zs.size() / 2] / 1000.0;
    const double px_m = z / k_.fx;  // metres per pixel at this depth
    const double area_m2 = b.area * px_m * px_m;
    if (area_m2 < p_.min_area_m2) continue;
    DetectedHand h;
    h.u = u;
    h.v = v;
    h.radius_px = maxv;
    h.depth = z;
    h.area_m2 = area_m2;
    h.position = k_.unproject(u, v, z);
    hands.push_back(h);
  }
  std::sort(hands.begin(), hands.end(), [](auto& a, auto& b) { return a.u < b.u; });
  return hands;
}

std::vector<HandFrame> HandSegmenter::process_raw11(const uint16_t* raw, int width, int height,
                                                    double time) {
  if (lut_.empty()) {
    lut_.resize(2048);
    for (int i = 0; i < 2048; ++i)
      lut_[i] =
          static_cast<uint16_t>(std::lround(kinect_raw_to_m(static_cast<uint16_t>(i)) * 1000));
  }
  cv::Mat mm(height, width, CV_16UC1);
  const size_t n = static_cast<size_t>(width) * height;
  auto* out = mm.ptr<uint16_t>();
  // Read through bytes: libfreenect's fakenect hands over a buffer at an odd address (UBSan:
  // misaligned uint16_t load), and a real device's buffer alignment is not promised either.
  const auto* bytes = reinterpret_cast<const unsigned char*>(raw);
  for (size_t i = 0; i < n; ++i) {
    uint16_t v;
    std::memcpy(&v, bytes + 2 * i, sizeof v);
    out[i] = lut_[v & 2047];
  }
  auto hands = detect(mm);
  std::vector<HandFrame> frames;
  for (size_t i = 0; i < hands.size(); ++i) {
    HandFrame f;
    // Sorted by u: with two hands the image-left one is the user's right hand (mirror).
    f.hand = (hands.size() == 2 && i == 1) ? Hand::Left : Hand::Right;
    if (hands.size() == 1) f.hand = hands[0].u < width / 2.0 ? Hand::Right : Hand::Left;
    f.time = time;
    f.tracked = true;
    f.confidence = std::clamp(hands[i].radius_px / 10.0, 0.0, 1.0);
    f.palm.position = hands[i].position;
    frames.push_back(f);
  }
  return frames;
}

struct KinectSource::Impl {
  HandSegmenter seg;
  freenect_context* ctx = nullptr;
  freenect_device* dev = nullptr;
  std::thread thread;
  std::atomic<bool> stop{false};
  mutable std::mutex mu;
  std::vector<HandFrame> pending;
  SourceStatus status{SourceState::NoData, "kinect: starting"};
  std::atomic<uint64_t> frames{0};
  std::atomic<bool> running{false};
  std::string recording;   // the fakenect recording replayed ("" = a device)
  double last_frame = -1;  // steady clock (s) of the newest depth frame, under mu
};

namespace {
constexpr double kStallSeconds = 1.0;  // no depth frame for this long: a stalled stream
double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
void depth_cb(freenect_device* dev, void* data, uint32_t) {
  auto* impl = static_cast<KinectSource::Impl*>(freenect_get_user(dev));
  if (!impl || !data) return;
  auto frames = impl->seg.process_raw11(static_cast<const uint16_t*>(data), 640, 480, now_s());
  ++impl->frames;
  std::lock_guard lk(impl->mu);
  impl->last_frame = now_s();
  for (auto& f : frames) impl->pending.push_back(f);
  if (impl->pending.size() > 64)
    impl->pending.erase(impl->pending.begin(), impl->pending.end() - 64);
  impl->status = {SourceState::Ok, "kinect: streaming"};
}
}  // namespace

KinectSource::KinectSource(SegmenterParams p, int device_index,
                           const std::string& fakenect_recording)
    : impl_(std::make_unique<Impl>()) {
  impl_->seg = HandSegmenter(p);
  impl_->recording = fakenect_recording;
  auto set = [&](SourceState s, const std::string& m) {
    std::lock_guard lk(impl_->mu);
    impl_->status = {s, m};
  };
  // Under fakenect a missing recording directory would make the library exit(): check first.
  if (!fakenect_recording.empty()) {
    struct stat st {};
    const std::string index = fakenect_recording + "/INDEX.txt";
    if (::stat(index.c_str(), &st) != 0) {
      set(SourceState::Unavailable, "kinect: fakenect recording " + index + " is missing");
      return;
    }
  }
  if (freenect_init(&impl_->ctx, nullptr) < 0) {
    impl_->ctx = nullptr;
    set(SourceState::Unavailable, "kinect: libfreenect init failed (no USB access?)");
    return;
  }
  freenect_select_subdevices(impl_->ctx, FREENECT_DEVICE_CAMERA);
  const int n = freenect_num_devices(impl_->ctx);
  if (n <= device_index) {
    set(SourceState::Unavailable,
        "kinect: no Kinect found (libfreenect reports " + std::to_string(n) + " devices)");
    return;
  }
  if (freenect_open_device(impl_->ctx, &impl_->dev, device_index) < 0) {
    impl_->dev = nullptr;
    set(SourceState::Unavailable, "kinect: cannot open device " + std::to_string(device_index));
    return;
  }
  freenect_set_user(impl_->dev, impl_.get());
  freenect_set_depth_mode(
      impl_->dev, freenect_find_depth_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_DEPTH_11BIT));
  freenect_set_depth_callback(impl_->dev, depth_cb);
  if (freenect_start_depth(impl_->dev) < 0) {
    set(SourceState::Error, "kinect: cannot start depth stream");
    return;
  }
  impl_->running = true;
  impl_->thread = std::thread([this] {
    while (!impl_->stop) {
      if (freenect_process_events(impl_->ctx) < 0) {
        // fakenect (loop off) returns an error at the recording's end; a device on a USB error
        // (unplugged).
        std::lock_guard lk(impl_->mu);
        impl_->status = {SourceState::Error,
                         impl_->recording.empty()
                             ? "kinect: the device went away (USB error or unplugged)"
                             : "kinect: the recording " + impl_->recording + " ended"};
        break;
      }
    }
    impl_->running = false;
  });
}

KinectSource::~KinectSource() {
  impl_->stop = true;
  if (impl_->thread.joinable()) impl_->thread.join();
  if (impl_->dev) {
    freenect_stop_depth(impl_->dev);
    freenect_close_device(impl_->dev);
  }
  if (impl_->ctx) freenect_shutdown(impl_->ctx);
}

uint64_t KinectSource::frames_processed() const {
  return impl_->frames.load();
}
bool KinectSource::running() const {
  return impl_->running.load();
}

std::vector<HandFrame> KinectSource::poll() {
  std::lock_guard lk(impl_->mu);
  return std::exchange(impl_->pending, {});
}

SourceStatus KinectSource::status() const {
  std::lock_guard lk(impl_->mu);
  // A stream that stalls without an error (a device that stops sending) says so.
  if (impl_->status.state == SourceState::Ok && impl_->last_frame >= 0 &&
      now_s() - impl_->last_frame > kStallSeconds)
    return {SourceState::NoData, "kinect: no depth frame for over 1 s"};
  return impl_->status;
}

}  // namespace drape::tracking
