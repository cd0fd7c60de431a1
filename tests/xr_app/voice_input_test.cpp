// The app's live voice input (xr_app/app/voice_input.hpp) with the real voice thread and
// recogniser: a recording made with espeak-ng + sox is streamed at real time and polled as the
// frame loop polls it; a device that fails mid-stream becomes a status naming it.
#include "xr_app/app/voice_input.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

using drape::app::VoiceInput;
namespace tr = drape::tracking;

namespace {
const std::string kDir = std::string(DRAPE_BINARY_DIR) + "/xr_test_out/voice_input";

// "pin here" after `lead_s` of silence, 1 s of silence after it (16 kHz mono).
std::string speech(double lead_s, const std::string& name) {
  // One file per test: ctest runs the tests of this file as processes side by side, and one
  // rewriting a recording another streams would cut that stream short.
  const std::string wav = kDir + "/" + name + ".wav";
  const std::string cmd = "set -e; mkdir -p '" + kDir + "'; cd '" + kDir +
                          "'; espeak-ng -s 140 -w " + name + "_22k.wav 'pin here'; sox " + name +
                          "_22k.wav -r 16000 -c 1 -b 16 " + name + ".wav pad " +
                          std::to_string(lead_s) + " 1";
  return std::system(cmd.c_str()) == 0 ? wav : "";
}

// A capture device that delivers `good` samples of a recording, then fails as ALSA does.
class FailingDevice : public tr::AudioInput {
 public:
  FailingDevice(const std::string& wav, long good)
      : in_(tr::open_wav_input(wav, false)), left_(good) {}
  bool ok() const override { return in_->ok() && left_ > 0; }
  std::string error() const override {
    return in_->ok() ? "microphone 'hw:5,0': Input/output error" : in_->error();
  }
  long read(int16_t* buf, long n) override {
    if (left_ <= 0) return -1;
    const long got = in_->read(buf, std::min(n, left_));
    if (got > 0) left_ -= got;
    return got;
  }

 private:
  std::unique_ptr<tr::AudioInput> in_;
  long left_;
};
}  // namespace

TEST(VoiceInput, StreamsARecordingAtRealTimeAndCountsTheLatencyInFrames) {
  const std::string wav = speech(1.0, "stream");
  ASSERT_FALSE(wav.empty()) << "espeak-ng/sox failed";
  VoiceInput in(wav);
  EXPECT_EQ(in.name(), "recording '" + wav + "'");
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<VoiceInput::Heard> heard;
  bool listening = false;
  // The frame loop at ~90 Hz for at most 20 s.
  for (int64_t frame = 0; frame < 1800 && heard.empty(); ++frame) {
    if (auto st = in.status_change()) listening = listening || st->empty();
    for (auto& h : in.poll(frame)) heard.push_back(std::move(h));
    std::this_thread::sleep_for(std::chrono::milliseconds(11));
  }
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(listening);
  ASSERT_EQ(heard.size(), 1u);
  const VoiceInput::Heard& h = heard[0];
  EXPECT_EQ(h.result.command, "pin") << h.result.hypothesis << " " << h.result.reason;
  // Real time: the speech ends after the 1 s of lead silence and ~0.6 s of speech, so nothing can
  // be heard before that.
  EXPECT_GT(elapsed, 1.4);
  // The VAD's hangover (0.35 s) and the decoding lie between the end of the speech and the poll.
  EXPECT_GE(h.latency_ms, 300.0);
  EXPECT_LT(h.latency_ms, 5000.0);
  // Every poll takes at least its 11 ms sleep.
  EXPECT_GE(h.latency_frames, 1);
  EXPECT_LE(h.latency_frames * 11.0, h.latency_ms + 11.0);
  EXPECT_GE(h.speech_end_frame, 0);
  std::printf("latency: %d frames (%.0f ms) at ~90 polls a second\n", h.latency_frames,
              h.latency_ms);
}

TEST(VoiceInput, ADeviceFailingMidStreamIsAStatusNamingIt) {
  const std::string wav = speech(1.0, "failing");
  ASSERT_FALSE(wav.empty()) << "espeak-ng/sox failed";
  VoiceInput in("microphone (ALSA 'hw:5,0')",
                std::make_unique<FailingDevice>(wav, tr::kVoiceRate / 2));
  std::string last;
  for (int64_t frame = 0; frame < 900; ++frame) {
    if (auto st = in.status_change()) last = *st;
    if (last.find("Input/output error") != std::string::npos) break;
    in.poll(frame);
    std::this_thread::sleep_for(std::chrono::milliseconds(11));
  }
  EXPECT_NE(last.find("microphone 'hw:5,0': Input/output error"), std::string::npos) << last;
  EXPECT_NE(last.find("voice commands are off"), std::string::npos) << last;
  EXPECT_TRUE(in.poll(1000).empty());
}

TEST(VoiceInput, AMalformedRecordingIsAStatusNamingTheFile) {
  const std::string bad = kDir + "/bad.wav";
  ASSERT_EQ(
      std::system(("mkdir -p '" + kDir + "' && printf 'RIFF0000WAVEfmt ' > '" + bad + "'").c_str()),
      0);
  VoiceInput in(bad);
  std::string last;
  for (int64_t frame = 0; frame < 900 && last.empty(); ++frame) {
    if (auto st = in.status_change()) last = *st;
    std::this_thread::sleep_for(std::chrono::milliseconds(11));
  }
  EXPECT_EQ(last.rfind(bad + ": ", 0), 0u) << last;
}
