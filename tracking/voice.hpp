// Voice -> triggers with pocketsphinx (Debian 0.8+5prealpha API): a JSGF grammar of two-word
// command phrases with a filler-word loop for out-of-grammar speech (one decoder pass),
// an energy VAD that cuts utterances, out-of-grammar rejection, audio from ALSA or a WAV file on
// its own thread. A missing microphone or a corrupt file gives a clear status; nothing else stops.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "tracking/hand_source.hpp"

namespace drape::tracking {

inline constexpr int kVoiceRate = 16000;

// Audio input: 16 kHz mono signed 16-bit.
class AudioInput {
 public:
  virtual ~AudioInput() = default;
  virtual bool ok() const = 0;
  virtual std::string error() const = 0;
  // Reads up to n samples; returns count, 0 at end of stream, -1 on error (see error()).
  virtual long read(int16_t* buf, long n) = 0;
};

// RIFF/WAVE PCM 16-bit mono 16 kHz. realtime: read() paces to the sample rate.
std::unique_ptr<AudioInput> open_wav_input(const std::string& path, bool realtime = false);
// ALSA capture ("default" or e.g. "hw:1,0").
std::unique_ptr<AudioInput> open_alsa_input(const std::string& device = "default");
// Whole-file WAV reader (same validation); error names the file.
bool read_wav(const std::string& path, std::vector<int16_t>& samples, std::string* error);

enum class Rejection {
  None,      // command grammar only: every utterance maps to some command
  Duration,  // command grammar; reject speech longer than max_command_s or shorter than min
  Garbage,   // two passes: the command-phrase grammar and a filler-word grammar; reject when the
             // filler path beats the command path by more than filler_margin per frame
  Combined,  // Garbage + Duration
  Single,    // one pass over "<command phrase> | <filler words>": a command only when the
             // command branch wins (faster, but absorbs many commands: see docs/tracking.md)
};
const char* rejection_name(Rejection r);

// A spoken phrase and the trigger command it produces ("pinch cloth" -> "pinch").
struct VoicePhrase {
  std::string phrase, command;
};

struct VoiceConfig {
  std::string model_dir = "/usr/share/pocketsphinx/model/en-us/en-us";
  std::string dict = "";     // default: <source>/assets/voice/commands.dict
  std::string phrases = "";  // default: <source>/assets/voice/phrases.tsv ("phrase\tcommand")
  std::string filler = "";   // default: <source>/assets/voice/filler.txt (one word a line)
  Rejection rejection = Rejection::Combined;
  // pocketsphinx word insertion penalty (-wip, probability per word; default 0.65). Smaller
  // values make the many-short-words filler path expensive against a two-word phrase.
  double word_penalty = 0.65;
  // The filler path needs at least this many words: a two-word command phrase then never
  // competes with a one- or two-word filler path (sentences are longer).
  int min_filler_words = 1;
  // Garbage/Combined: reject when (filler score - command score) per 10 ms frame exceeds this
  // (log base 1.0001); -5 = the phrase path must win by 5 per frame. Tuned (with max_command_s)
  // on the tuning set of bench/voice.sh, never on its test set.
  double filler_margin = -5;
  double max_command_s = 1.2;  // speech longer than this is not a single command
  double min_command_s = 0.15;
  // Energy VAD (10 ms frames).
  double vad_on_db = 9.0;    // dB above the noise floor to start speech
  double vad_off_db = 6.0;   // dB above the noise floor to continue speech
  double hangover_s = 0.25;  // silence that ends an utterance (latency floor)
  double preroll_s = 0.2;    // audio kept before the detected start
};

// Reads a phrase file ("spoken phrase<TAB>command" per line, '#' comments); error names the file
// and line.
bool load_phrases(const std::string& path, std::vector<VoicePhrase>& out, std::string* error);

struct VoiceResult {
  std::string hypothesis;  // raw decoder output
  std::string command;     // accepted command, empty when rejected
  std::string reason;      // why rejected
  double speech_s = 0;     // VAD speech duration
  double margin = 0;       // (command score - filler score) per frame (Garbage/Combined)
  std::string filler_hypothesis;
  double decode_ms = 0;
};

// Decoder for whole utterances (used by VoiceSource and directly by tests/bench).
class VoiceRecognizer {
 public:
  explicit VoiceRecognizer(VoiceConfig cfg);
  ~VoiceRecognizer();
  VoiceRecognizer(const VoiceRecognizer&) = delete;
  VoiceRecognizer& operator=(const VoiceRecognizer&) = delete;
  bool ok() const { return ps_ != nullptr; }
  const std::string& error() const { return error_; }
  VoiceResult decode(const int16_t* samples, long n, double speech_s);
  const VoiceConfig& config() const { return cfg_; }
  const std::vector<VoicePhrase>& phrases() const { return phrases_; }
  const std::string& grammar() const { return grammar_; }  // the generated JSGF (commands)

 private:
  VoiceConfig cfg_;
  std::vector<VoicePhrase> phrases_;
  std::string grammar_;
  void* ps_ = nullptr;  // ps_decoder_t
  std::string error_;
};

// Segments a stream into utterances (energy VAD with adaptive noise floor).
class EnergyVad {
 public:
  explicit EnergyVad(const VoiceConfig& c) : c_(c) {}
  struct Segment {
    std::vector<int16_t> audio;
    long start = 0, speech_end = 0, decided = 0;  // sample indices in the stream
  };
  // Feed samples; completed utterances are appended to out.
  void feed(const int16_t* s, long n, std::vector<Segment>& out);
  void flush(std::vector<Segment>& out);  // end of stream: close an open utterance

 private:
  void frame(const int16_t* f, std::vector<Segment>& out);
  VoiceConfig c_;
  std::vector<int16_t> ring_, partial_;
  std::vector<int16_t> cur_;
  bool in_speech_ = false;
  int above_ = 0;
  long pos_ = 0, start_ = 0, last_voiced_ = 0;
  double floor_db_ = -1;
};

struct VoiceEvent {
  VoiceResult result;
  long speech_end = 0, decided = 0;  // sample indices (stream clock)
  double latency_ms = 0;             // (decided - speech_end) / rate + decode time
};

// Voice on its own thread: audio input -> VAD -> recognizer -> triggers.
class VoiceSource {
 public:
  VoiceSource(VoiceConfig cfg, std::unique_ptr<AudioInput> input);
  ~VoiceSource();
  VoiceSource(const VoiceSource&) = delete;
  VoiceSource& operator=(const VoiceSource&) = delete;
  std::vector<Trigger> take_triggers();
  std::vector<VoiceEvent> take_events();  // every decoded utterance, accepted or not
  SourceStatus status() const;
  bool finished() const { return done_.load(); }
  void wait();  // join (file input ends by itself)

 private:
  void run();
  VoiceConfig cfg_;
  std::unique_ptr<AudioInput> in_;
  std::thread th_;
  std::atomic<bool> stop_{false}, done_{false};
  mutable std::mutex mu_;
  std::vector<Trigger> triggers_;
  std::vector<VoiceEvent> events_;
  SourceStatus status_{SourceState::NoData, "voice: starting"};
};

}  // namespace drape::tracking
