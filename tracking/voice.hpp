// Voice -> triggers with pocketsphinx (Debian 0.8+5prealpha API): an energy VAD cuts utterances;
// each is decoded whole (batch CMN) by a JSGF grammar of two-word command phrases and by a garbage
// path (a phone loop, or filler words); out-of-grammar rejection by the garbage margin and by the
// voiced speech outside the phrase words (plus optional word-margin and duration rules); audio
// from ALSA or a WAV file on its own thread. A missing microphone or a corrupt file gives a clear
// status; nothing else stops.
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
  Garbage,   // two passes: the command-phrase grammar and a garbage path (GarbageModel); reject
             // when the garbage path beats the command path by more than filler_margin per frame
             // or the weakest command word by more than -min_word_margin
  Combined,  // Garbage + Duration
  Single,    // one pass over "<command phrase> | <filler words>": a command only when the
             // command branch wins (faster, but absorbs many commands: see docs/tracking.md)
};
const char* rejection_name(Rejection r);

// The competing path of the second pass (Garbage/Combined).
enum class GarbageModel {
  Fillers,  // 1-12 words of assets/voice/filler.txt
  Phones,   // free phone loop with the model's phone bigram (en-us-phone.lm.bin)
};

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
  GarbageModel garbage = GarbageModel::Phones;  // tuned: better than Fillers on the tuning set
  // pocketsphinx word insertion penalty (-wip, probability per word; default 0.65). Smaller
  // values make the many-short-words filler path expensive against a two-word phrase.
  double word_penalty = 0.65;
  // The filler path needs at least this many words: a two-word command phrase then never
  // competes with a one- or two-word filler path (sentences are longer).
  int min_filler_words = 1;
  // Garbage/Combined: reject when (garbage score - command score) per 10 ms frame exceeds this
  // (log base 1.0001); 3 = the garbage path may win by up to 3 per frame. The defaults of this
  // rule, max_outside_s, garbage_lw, min_word_margin and max_command_s are the values
  // bench/voice.sh picked on its 524-utterance tuning set, never on a test, held-out or FINAL
  // set.
  double filler_margin = 1.5;
  // Garbage/Combined: the margin rule compares (margin - margin_per_s * speech_s)
  // with -filler_margin, i.e. each second of speech costs this much margin. A sentence that
  // contains a phrase word is long and has a middling margin; an accented or slow command is
  // short with a low margin. 0 = plain margin. Chosen by bench/voice.sh on its tuning set (2 margin
  // units per s).
  double margin_per_s = 2;
  // Garbage/Combined: reject when the weakest command word's acoustic score beats the garbage
  // path's over the same frames by less than this (per frame); -1e9 = off (tuned: adds nothing
  // once max_outside_s is used).
  double min_word_margin = -1e9;
  // Combined: speech longer than this is not a single command (1e9 = off: tuned, adds nothing).
  double max_command_s = 1e9;
  double min_command_s = 0.15;
  // Energy VAD (10 ms frames).
  double vad_on_db = 9.0;    // dB above the noise floor to start speech
  double vad_off_db = 6.0;   // dB above the noise floor to continue speech
  double hangover_s = 0.35;  // silence that ends an utterance (latency floor; tuned)
  double preroll_s = 0.2;    // audio kept before the detected start
  // Energy measured on x[n] - a*x[n-1] (0 = plain energy): lifts fricatives and bursts over
  // low-frequency noise so that a weak consonant between words does not end the utterance.
  double vad_preemphasis = 0;  // 0.97 tried: cut weak word ends, split more (docs)
  // Front end. remove_noise: pocketsphinx's spectral noise subtraction (-remove_noise): +6 points
  // of grammar-only accuracy at 10 dB SNR on the tuning set, but on digital silence (exact zeros
  // in a synthesised WAV) its noise estimate collapses and a clean 'pin here' decodes as 'undo
  // that'. comfort_noise: +- this many LSB of fixed-seed uniform noise (RMS 28 LSB, -61 dBFS) added
  // before decoding keep the estimate sane; any noise floor >= ~10 LSB RMS fixed it (docs).
  bool remove_noise = true;
  double comfort_noise = 48;
  // false (default): each utterance is decoded whole after its end (batch CMN over the
  // utterance, as the model was trained). true: decoded while it arrives (live CMN that starts
  // from the model's -cmninit and carries over between utterances: the first utterance of a
  // fresh decoder is normalised with a wrong mean: a clean 'pin here' decoded as 'redo').
  bool streaming = false;
  // Language-model weight of the phone loop (the garbage decoder's -lw; pocketsphinx default 6.5):
  // larger = the phone bigram constrains the garbage path more. Tuned by bench/voice.sh over 6.5, 8
  // and 10 on the tuning set.
  double garbage_lw = 10;
  // Extra pocketsphinx arguments ("-name value ..."): for both decoders / the garbage decoder only.
  std::string decoder_args, garbage_args;
  double outside_db = 10;  // a frame is voiced above the utterance's 10th-percentile energy + this
  // Garbage/Combined: reject when more than this much voiced audio (s) lies outside the phrase
  // words: pocketsphinx lets silence and noise fillers stand around and between the phrase words,
  // so a sentence that contains a phrase word aligns its other words to them. Tuned on the tuning
  // set (the grid's floor; 0.05 s rejects the clean "pin here" cue).
  double max_outside_s = 0.1;
};

// Reads a phrase file ("spoken phrase<TAB>command" per line, '#' comments); error names the file
// and line.
bool load_phrases(const std::string& path, std::vector<VoicePhrase>& out, std::string* error);

struct VoiceResult {
  std::string hypothesis;       // raw decoder output
  std::string command;          // accepted command, empty when rejected
  std::string reason;           // why rejected
  double speech_s = 0;          // VAD speech duration
  double margin = 0;            // (command score - filler score) per frame (Garbage/Combined)
  double word_margin = 0;       // weakest command word: (word - garbage) acoustic score per frame
  double word_span_margin = 0;  // (command score - garbage score) per frame of the phrase words
  double outside_s = 0;  // voiced audio (s) outside the phrase words (a sentence around them)
  double words_s = 0;    // first phrase word start .. last word end (s)
  std::string filler_hypothesis;
  double decode_ms = 0;  // finish(): decoding after the end of the utterance (latency part)
  double feed_ms = 0;    // feed(): buffering (+ decoding when VoiceConfig::streaming)
  double audio_s = 0;    // audio decoded
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
  VoiceResult decode(const int16_t* samples, long n, double speech_s);  // begin+feed+finish
  // Incremental input: feed() collects the utterance as it arrives; finish() decodes it whole
  // (both passes; its time is VoiceResult::decode_ms, the latency after the end of the
  // utterance). With VoiceConfig::streaming, feed() decodes and finish() only finalises.
  void begin();
  void feed(const int16_t* samples, long n);
  VoiceResult finish(double speech_s);
  const VoiceConfig& config() const { return cfg_; }
  const std::vector<VoicePhrase>& phrases() const { return phrases_; }
  const std::string& grammar() const { return grammar_; }  // the generated JSGF (commands)

 private:
  VoiceConfig cfg_;
  std::vector<VoicePhrase> phrases_;
  std::string grammar_;
  void* ps_ = nullptr;  // ps_decoder_t: command phrases
  void* gs_ = nullptr;  // ps_decoder_t: garbage path (Garbage/Combined)
  bool in_utt_ = false;
  double feed_ms_ = 0;
  long fed_ = 0;
  std::vector<int16_t> utt_;  // the utterance so far (plus comfort noise)
  uint32_t noise_state_ = 12345u;
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
  // The utterance in progress (fed to the recognizer as it arrives): its audio and start index.
  bool in_speech() const { return in_speech_; }
  const std::vector<int16_t>& current() const { return cur_; }
  long current_start() const { return start_; }

 private:
  void frame(const int16_t* f, std::vector<Segment>& out);
  VoiceConfig c_;
  std::vector<int16_t> ring_, partial_;
  std::vector<int16_t> cur_;
  bool in_speech_ = false;
  int above_ = 0;
  long pos_ = 0, start_ = 0, last_voiced_ = 0;
  double floor_db_ = -1;
  double prev_ = 0;  // last sample (pre-emphasis)
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
