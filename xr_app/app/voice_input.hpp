// The live voice input of a draping session: the microphone (the default ALSA capture device) or
// a WAV recording streamed at real time as if it were the microphone, decoded on the voice
// thread (tracking::VoiceSource: energy VAD + pocketsphinx) and handed to the frame loop through
// the source's locked queue. The frame loop polls it once per frame; each decoded utterance comes
// with its latency in frames, from the frame during which its last voiced sample was read to the
// frame that receives it. A missing or failing microphone or a malformed recording is a status,
// never an exception: the session goes on without voice.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tracking/voice.hpp"

namespace drape::app {

// When each block of audio reached the voice thread (steady clock, s), shared by the input that
// records it (voice thread) and the frame loop that reads it.
class AudioClock {
 public:
  void read(long samples_total, double when);
  // The time the sample with this stream index was read; -1 when it is not recorded (yet).
  double time_of(long sample) const;

 private:
  mutable std::mutex m_;
  std::deque<std::pair<long, double>> reads_;  // (samples read so far, when), oldest first
};

class VoiceInput {
 public:
  // spec: "mic" (the default ALSA capture device) or the path of a WAV file (16 kHz mono 16-bit).
  // tee_wav: when set, the audio as captured is also written there (--record's audio.wav).
  explicit VoiceInput(const std::string& spec, const std::string& tee_wav = "");
  // Any audio input (tests: a device that fails mid-stream); `name` is used in messages.
  VoiceInput(std::string name, std::unique_ptr<tracking::AudioInput> input,
             const std::string& tee_wav = "");
  ~VoiceInput();
  VoiceInput(const VoiceInput&) = delete;
  VoiceInput& operator=(const VoiceInput&) = delete;

  // What is listened to, for messages: "microphone (ALSA 'default')" or "recording 'F.wav'".
  const std::string& name() const { return name_; }
  // Why the tee file could not be written ("" when it is, or none was asked for).
  const std::string& tee_error() const { return tee_error_; }

  struct Heard {
    tracking::VoiceResult result;
    int latency_frames = -1;        // frames from the end of the speech to this frame (-1: unknown)
    double latency_ms = -1;         // time from reading the last voiced sample to this poll
    int64_t speech_end_frame = -1;  // the frame during which the last voiced sample was read
    double vad_decode_ms = 0;       // of which: the VAD's hangover and the decoding (voice thread)
  };
  // Once per frame: the utterances decoded since the last call (accepted or rejected).
  std::vector<Heard> poll(int64_t frame);
  // The input's state when it changed since the last call: "" = listening, else why not.
  std::optional<std::string> status_change();

 private:
  int64_t frame_at(double when) const;

  std::string name_;
  std::shared_ptr<AudioClock> clock_ = std::make_shared<AudioClock>();
  std::unique_ptr<tracking::VoiceSource> source_;
  std::deque<std::pair<int64_t, double>> frames_;  // (frame, when polled), the last minute
  std::string last_status_ = "(none)";             // the last status reported; none yet
  std::string tee_error_;
};

}  // namespace drape::app
