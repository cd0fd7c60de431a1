// The live voice input of a draping session (see voice_input.hpp).
#include "xr_app/app/voice_input.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <thread>

namespace drape::app {

namespace {
double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The audio as captured, teed into a WAV file (16 kHz mono 16-bit) on the voice thread: the
// header's sizes are rewritten after every block, so the file is a whole WAV at any moment (a
// crash loses at most the block being written).
class WavTee {
 public:
  explicit WavTee(const std::string& path) : f_(std::fopen(path.c_str(), "wb")) {
    if (!f_) return;
    const uint32_t rate = tracking::kVoiceRate;
    unsigned char h[44] = {'R', 'I', 'F', 'F', 36, 0, 0, 0, 'W', 'A', 'V', 'E',
                           'f', 'm', 't', ' ', 16, 0, 0, 0, 1,   0,   1,   0};
    put32(h + 24, rate);
    put32(h + 28, rate * 2);  // bytes per second
    h[32] = 2;                // block align
    h[34] = 16;               // bits per sample
    std::memcpy(h + 36, "data", 4);
    std::fwrite(h, 1, sizeof h, f_);
    std::fflush(f_);
  }
  ~WavTee() {
    if (f_) std::fclose(f_);
  }
  bool ok() const { return f_ != nullptr; }
  void write(const int16_t* s, long n) {
    if (!f_ || n <= 0) return;
    for (long i = 0; i < n; ++i) {  // little-endian samples
      const auto v = static_cast<uint16_t>(s[i]);
      const unsigned char b[2] = {static_cast<unsigned char>(v & 0xFF),
                                  static_cast<unsigned char>(v >> 8)};
      std::fwrite(b, 1, 2, f_);
    }
    data_ += static_cast<uint32_t>(n) * 2;
    unsigned char sz[4];
    put32(sz, 36 + data_);
    std::fseek(f_, 4, SEEK_SET);
    std::fwrite(sz, 1, 4, f_);
    put32(sz, data_);
    std::fseek(f_, 40, SEEK_SET);
    std::fwrite(sz, 1, 4, f_);
    std::fseek(f_, 0, SEEK_END);
    std::fflush(f_);
  }

 private:
  static void put32(unsigned char* p, uint32_t v) {
    for (int i = 0; i < 4; ++i) p[i] = static_cast<unsigned char>(v >> (8 * i));
  }
  std::FILE* f_ = nullptr;
  uint32_t data_ = 0;
};

// Wraps the microphone or the recording: never delivers audio faster than real time (a WAV file
// reads at disk speed, and an ALSA device with no clock of its own, such as the `null` slave of
// the `file` plugin, returns at once), and records when each block was read.
class ClockedInput : public tracking::AudioInput {
 public:
  ClockedInput(std::unique_ptr<tracking::AudioInput> in, std::shared_ptr<AudioClock> clock,
               std::unique_ptr<WavTee> tee)
      : in_(std::move(in)), clock_(std::move(clock)), tee_(std::move(tee)) {}
  bool ok() const override { return in_->ok(); }
  std::string error() const override { return in_->error(); }
  long read(int16_t* buf, long n) override {
    // A device that reports samples without writing them gives silence, not the last block again.
    std::memset(buf, 0, static_cast<size_t>(n) * sizeof(int16_t));
    if (t0_ < 0) t0_ = now_s();  // the capture starts with the first read
    const long got = in_->read(buf, n);
    if (got <= 0) return got;
    if (tee_) tee_->write(buf, got);
    total_ += got;
    const double wait = t0_ + static_cast<double>(total_) / tracking::kVoiceRate - now_s();
    if (wait > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
    clock_->read(total_, now_s());
    return got;
  }

 private:
  std::unique_ptr<tracking::AudioInput> in_;
  std::shared_ptr<AudioClock> clock_;
  std::unique_ptr<WavTee> tee_;
  double t0_ = -1;
  long total_ = 0;
};

// The source's status message without its "voice: " prefix.
std::string plain(const std::string& message) {
  const std::string prefix = "voice: ";
  return message.rfind(prefix, 0) == 0 ? message.substr(prefix.size()) : message;
}
}  // namespace

void AudioClock::read(long samples_total, double when) {
  std::lock_guard lock(m_);
  reads_.emplace_back(samples_total, when);
  // About a minute of 50 ms blocks: an utterance is decoded seconds after it ends at most.
  if (reads_.size() > 1200) reads_.pop_front();
}

double AudioClock::time_of(long sample) const {
  std::lock_guard lock(m_);
  auto it = std::lower_bound(reads_.begin(), reads_.end(), sample,
                             [](const std::pair<long, double>& r, long s) { return r.first < s; });
  return it == reads_.end() ? -1.0 : it->second;
}

VoiceInput::VoiceInput(const std::string& spec, const std::string& tee_wav)
    : VoiceInput(spec == "mic" ? "microphone (ALSA 'default')" : "recording '" + spec + "'",
                 spec == "mic" ? tracking::open_alsa_input("default")
                               : tracking::open_wav_input(spec, false),  // ClockedInput paces
                 tee_wav) {}

VoiceInput::VoiceInput(std::string name, std::unique_ptr<tracking::AudioInput> input,
                       const std::string& tee_wav)
    : name_(std::move(name)) {
  auto tee = tee_wav.empty() ? nullptr : std::make_unique<WavTee>(tee_wav);
  if (tee && !tee->ok()) {
    tee_error_ = tee_wav + ": cannot write (the audio is not recorded)";
    tee.reset();
  }
  source_ = std::make_unique<tracking::VoiceSource>(
      tracking::VoiceConfig{},
      std::make_unique<ClockedInput>(std::move(input), clock_, std::move(tee)));
}

VoiceInput::~VoiceInput() = default;

int64_t VoiceInput::frame_at(double when) const {
  int64_t frame = -1;
  for (const auto& [f, t] : frames_)
    if (t <= when) frame = f;
  return frame;
}

std::vector<VoiceInput::Heard> VoiceInput::poll(int64_t frame) {
  const double now = now_s();
  frames_.emplace_back(frame, now);
  while (frames_.size() > 2 && frames_.front().second < now - 60.0) frames_.pop_front();
  // The events carry every utterance with its command; the source's trigger queue holds the
  // accepted ones again and is drained so that it does not grow.
  source_->take_triggers();
  std::vector<Heard> out;
  for (auto& ev : source_->take_events()) {
    Heard h;
    h.result = std::move(ev.result);
    h.vad_decode_ms = ev.latency_ms;
    const double end = clock_->time_of(ev.speech_end);
    if (end >= 0) {
      h.latency_ms = (now - end) * 1e3;
      h.speech_end_frame = frame_at(end);
      if (h.speech_end_frame >= 0) h.latency_frames = static_cast<int>(frame - h.speech_end_frame);
    }
    out.push_back(std::move(h));
  }
  return out;
}

std::optional<std::string> VoiceInput::status_change() {
  const tracking::SourceStatus st = source_->status();
  std::string msg;
  switch (st.state) {
    case tracking::SourceState::Ok:
      msg = "";
      break;
    case tracking::SourceState::NoData:
      if (st.message == "voice: starting") return std::nullopt;
      msg = name_ + ": ended (" + plain(st.message) + "); voice commands are off";
      break;
    case tracking::SourceState::Unavailable:
    case tracking::SourceState::Error:
      msg = plain(st.message) + "; voice commands are off, the session goes on";
      break;
  }
  if (msg == last_status_) return std::nullopt;
  last_status_ = msg;
  return msg;
}

}  // namespace drape::app
