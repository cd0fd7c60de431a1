#include "tracking/voice.hpp"

#include <alsa/asoundlib.h>
#include <pocketsphinx.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <utility>

#ifndef DRAPE_TRACKING_SOURCE_DIR
#define DRAPE_TRACKING_SOURCE_DIR "."
#endif

namespace drape::tracking {

namespace {
double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
uint32_t le32(const unsigned char* p) {
  return p[0] | p[1] << 8 | p[2] << 16 | uint32_t(p[3]) << 24;
}
uint16_t le16(const unsigned char* p) {
  return static_cast<uint16_t>(p[0] | p[1] << 8);
}

// Parses the RIFF header; leaves the stream at the first sample. Returns sample count.
long parse_wav_header(std::istream& in, const std::string& path, std::string* error) {
  auto fail = [&](const std::string& m) {
    if (error) *error = path + ": " + m;
    return -1L;
  };
  unsigned char h[12];
  if (!in.read(reinterpret_cast<char*>(h), 12)) return fail("too short for a WAV header");
  if (std::memcmp(h, "RIFF", 4) != 0 || std::memcmp(h + 8, "WAVE", 4) != 0)
    return fail("not a RIFF/WAVE file");
  bool fmt_ok = false;
  for (int chunks = 0; chunks < 64; ++chunks) {
    unsigned char c[8];
    if (!in.read(reinterpret_cast<char*>(c), 8)) return fail("no 'data' chunk");
    const uint32_t size = le32(c + 4);
    if (std::memcmp(c, "fmt ", 4) == 0) {
      if (size < 16 || size > 1024) return fail("bad 'fmt ' chunk size");
      std::vector<unsigned char> f(size + (size & 1));
      if (!in.read(reinterpret_cast<char*>(f.data()), static_cast<std::streamsize>(f.size())))
        return fail("truncated 'fmt ' chunk");
      const uint16_t format = le16(f.data()), channels = le16(f.data() + 2);
      const uint32_t rate = le32(f.data() + 4);
      const uint16_t bits = le16(f.data() + 14);
      if ((format != 1 && format != 0xFFFE) || channels != 1 || rate != kVoiceRate || bits != 16)
        return fail("unsupported audio (need PCM 16-bit mono 16000 Hz; got format " +
                    std::to_string(format) + ", " + std::to_string(channels) + " ch, " +
                    std::to_string(rate) + " Hz, " + std::to_string(bits) + " bit)");
      fmt_ok = true;
    } else if (std::memcmp(c, "data", 4) == 0) {
      if (!fmt_ok) return fail("'data' before 'fmt '");
      return static_cast<long>(size / 2);
    } else {
      if (size > (1u << 30)) return fail("corrupt chunk size");
      in.seekg(size + (size & 1), std::ios::cur);
    }
  }
  return fail("no 'data' chunk");
}

class WavInput : public AudioInput {
 public:
  WavInput(const std::string& path, bool realtime) : path_(path), realtime_(realtime) {
    in_.open(path, std::ios::binary);
    if (!in_) {
      err_ = path + ": cannot open";
      return;
    }
    left_ = parse_wav_header(in_, path, &err_);
    if (left_ < 0) return;
    t0_ = now_s();
    ok_ = true;
  }
  bool ok() const override { return ok_; }
  std::string error() const override { return err_; }
  long read(int16_t* buf, long n) override {
    if (!ok_) return -1;
    if (left_ <= 0) return 0;
    n = std::min(n, left_);
    in_.read(reinterpret_cast<char*>(buf), n * 2);
    const long got = static_cast<long>(in_.gcount() / 2);
    if (got < n) {
      err_ = path_ + ": truncated data chunk (" + std::to_string(left_ - got) + " samples missing)";
      ok_ = false;
      return got > 0 ? got : -1;
    }
    left_ -= got;
    done_ += got;
    if (realtime_) {
      const double due = t0_ + static_cast<double>(done_) / kVoiceRate;
      const double wait = due - now_s();
      if (wait > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
    }
    return got;
  }

 private:
  std::string path_, err_;
  bool realtime_, ok_ = false;
  std::ifstream in_;
  long left_ = 0, done_ = 0;
  double t0_ = 0;
};

class AlsaInput : public AudioInput {
 public:
  explicit AlsaInput(const std::string& dev) : dev_(dev) {
    int rc = snd_pcm_open(&pcm_, dev.c_str(), SND_PCM_STREAM_CAPTURE, 0);
    if (rc < 0) {
      err_ = "microphone '" + dev + "': cannot open it for capture: " + snd_strerror(rc);
      pcm_ = nullptr;
      return;
    }
    rc = snd_pcm_set_params(pcm_, SND_PCM_FORMAT_S16_LE, SND_PCM_ACCESS_RW_INTERLEAVED, 1,
                            kVoiceRate, 1, 100000);
    if (rc < 0) {
      err_ = "microphone '" + dev + "': cannot set 16 kHz mono S16: " + snd_strerror(rc);
      return;
    }
    ok_ = true;
  }
  ~AlsaInput() override {
    if (pcm_) snd_pcm_close(pcm_);
  }
  bool ok() const override { return ok_; }
  std::string error() const override { return err_; }
  long read(int16_t* buf, long n) override {
    if (!ok_) return -1;
    snd_pcm_sframes_t r = snd_pcm_readi(pcm_, buf, static_cast<snd_pcm_uframes_t>(n));
    if (r < 0) r = snd_pcm_recover(pcm_, static_cast<int>(r), 1);
    if (r < 0) {
      err_ = "microphone '" + dev_ + "': " + snd_strerror(static_cast<int>(r));
      ok_ = false;
      return -1;
    }
    return static_cast<long>(r);
  }

 private:
  snd_pcm_t* pcm_ = nullptr;
  std::string dev_, err_;
  bool ok_ = false;
};

std::string default_path(const std::string& v, const char* rel) {
  return v.empty() ? std::string(DRAPE_TRACKING_SOURCE_DIR) + "/" + rel : v;
}
}  // namespace

std::unique_ptr<AudioInput> open_wav_input(const std::string& path, bool realtime) {
  return std::make_unique<WavInput>(path, realtime);
}
std::unique_ptr<AudioInput> open_alsa_input(const std::string& device) {
  return std::make_unique<AlsaInput>(device);
}

bool read_wav(const std::string& path, std::vector<int16_t>& s, std::string* error) {
  WavInput in(path, false);
  if (!in.ok()) {
    if (error) *error = in.error();
    return false;
  }
  s.clear();
  int16_t buf[4096];
  for (;;) {
    const long n = in.read(buf, 4096);
    if (n < 0 || !in.ok()) {
      if (error) *error = in.error();
      return false;
    }
    if (n == 0) return true;
    s.insert(s.end(), buf, buf + n);
  }
}

const char* rejection_name(Rejection r) {
  switch (r) {
    case Rejection::None:
      return "none";
    case Rejection::Duration:
      return "duration";
    case Rejection::Garbage:
      return "filler-margin";
    case Rejection::Combined:
      return "filler-margin+duration";
    case Rejection::Single:
      return "single-pass";
  }
  return "?";
}

bool load_phrases(const std::string& path, std::vector<VoicePhrase>& out, std::string* error) {
  std::ifstream in(path);
  if (!in) {
    if (error) *error = path + ": cannot open";
    return false;
  }
  out.clear();
  int ln = 0;
  for (std::string line; std::getline(in, line);) {
    ++ln;
    if (line.empty() || line[0] == '#') continue;
    const auto tab = line.find('\t');
    VoicePhrase p;
    if (tab != std::string::npos) {
      p.phrase = line.substr(0, tab);
      p.command = line.substr(tab + 1);
    }
    const bool word_ok = std::all_of(p.phrase.begin(), p.phrase.end(), [](char c) {
      return (c >= 'a' && c <= 'z') || c == ' ' || c == '\'';
    });
    if (p.phrase.empty() || p.command.empty() || !word_ok ||
        p.command.find_first_of(" \t") != std::string::npos) {
      if (error)
        *error = path + ":" + std::to_string(ln) +
                 ": expected 'lower-case phrase<TAB>command', got '" + line + "'";
      return false;
    }
    out.push_back(std::move(p));
  }
  if (out.empty()) {
    if (error) *error = path + ": no phrases";
    return false;
  }
  return true;
}

VoiceRecognizer::VoiceRecognizer(VoiceConfig cfg) : cfg_(std::move(cfg)) {
  cfg_.dict = default_path(cfg_.dict, "assets/voice/commands.dict");
  cfg_.phrases = default_path(cfg_.phrases, "assets/voice/phrases.tsv");
  cfg_.filler = default_path(cfg_.filler, "assets/voice/filler.txt");
  for (const auto& f : {cfg_.model_dir + "/mdef", cfg_.dict, cfg_.phrases, cfg_.filler}) {
    if (!std::ifstream(f)) {
      error_ = "voice: missing " + f;
      return;
    }
  }
  std::string err;
  if (!load_phrases(cfg_.phrases, phrases_, &err)) {
    error_ = "voice: " + err;
    return;
  }
  // Command grammar: the phrases (with Single, also the filler branch). Filler grammar (Garbage,
  // Combined): the filler words only, for the second pass.
  std::ifstream fin(cfg_.filler);
  std::vector<std::string> fw;
  for (std::string w; fin >> w;) fw.push_back(w);
  if (fw.empty()) {
    error_ = "voice: " + cfg_.filler + ": no filler words";
    return;
  }
  // No Kleene '+' / '*': with this sphinxbase, the loop's null transitions join the start of
  // the public rule, so the FSG can run from fillers into <command> ("it move cloth") and JSGF
  // branch weights have no effect. min_filler_words..12 filler words as nested optionals
  // instead (longer speech fails the duration limit anyway).
  auto fillers = [&](std::ostringstream& g) {
    g << "<filler> = ";
    for (size_t i = 0; i < fw.size(); ++i) g << (i ? " | " : "") << fw[i];
    const int need = std::clamp(cfg_.min_filler_words, 1, 6);
    g << ";\n<fillers> =";
    for (int k = 0; k < need; ++k) g << " <filler>";
    for (int k = need; k < 12; ++k) g << " [<filler>";
    for (int k = need; k < 12; ++k) g << "]";
    g << ";\n";
  };
  std::ostringstream g, gf;
  g << "#JSGF V1.0;\ngrammar drape;\n<command> = ";
  for (size_t i = 0; i < phrases_.size(); ++i) g << (i ? " | " : "") << phrases_[i].phrase;
  g << ";\n";
  if (cfg_.rejection == Rejection::Single) {
    fillers(g);
    g << "public <utterance> = <command> | <fillers>;\n";
  } else {
    g << "public <utterance> = <command>;\n";
  }
  grammar_ = g.str();
  gf << "#JSGF V1.0;\ngrammar filler;\n";
  fillers(gf);
  gf << "public <utterance> = <fillers>;\n";
  const std::string filler_grammar = gf.str();
  char wip[32];
  std::snprintf(wip, sizeof wip, "%g", cfg_.word_penalty);
  // Front end: see VoiceConfig::remove_noise / comfort_noise. extra: "-name value ..." pairs
  // (VoiceConfig::decoder_args / garbage_args).
  auto make = [&](const std::string& extra) -> ps_decoder_t* {
    std::vector<std::string> a = {"drape",
                                  "-hmm",
                                  cfg_.model_dir,
                                  "-dict",
                                  cfg_.dict,
                                  "-logfn",
                                  "/dev/null",
                                  "-remove_silence",
                                  "no",
                                  "-remove_noise",
                                  cfg_.remove_noise ? "yes" : "no",
                                  "-wip",
                                  wip,
                                  "-allphone_ci",
                                  "yes"};
    std::istringstream in(extra);
    for (std::string w; in >> w;) a.push_back(w);
    std::vector<char*> argv;
    for (auto& w : a) argv.push_back(w.data());
    cmd_ln_t* c =
        cmd_ln_parse_r(nullptr, ps_args(), static_cast<int32>(argv.size()), argv.data(), FALSE);
    if (!c) return nullptr;
    ps_decoder_t* d = ps_init(c);
    cmd_ln_free_r(c);
    return d;
  };
  const bool two_pass =
      cfg_.rejection == Rejection::Garbage || cfg_.rejection == Rejection::Combined;
  ps_decoder_t* ps = make(cfg_.decoder_args);
  char glw[32];
  std::snprintf(glw, sizeof glw, "%g", cfg_.garbage_lw);
  ps_decoder_t* gs =
      two_pass ? make(cfg_.decoder_args + " -lw " + glw + " " + cfg_.garbage_args) : nullptr;
  auto fail = [&](const std::string& m) {
    error_ = m;
    if (ps) ps_free(ps);
    if (gs) ps_free(gs);
  };
  if (!ps || (two_pass && !gs)) {
    fail("voice: pocketsphinx failed to load " + cfg_.model_dir);
    return;
  }
  const bool phones = cfg_.garbage == GarbageModel::Phones;
  const std::string phone_lm = cfg_.model_dir + "/../en-us-phone.lm.bin";
  if (two_pass && phones && !std::ifstream(phone_lm)) {
    fail("voice: missing " + phone_lm);
    return;
  }
  if (ps_set_jsgf_string(ps, "drape", grammar_.c_str()) < 0 ||
      (two_pass && (phones ? ps_set_allphone_file(gs, "garbage", phone_lm.c_str())
                           : ps_set_jsgf_string(gs, "garbage", filler_grammar.c_str())) < 0)) {
    fail("voice: bad grammar from " + cfg_.phrases + " / " + cfg_.filler +
         " (a word missing from " + cfg_.dict + "?)");
    return;
  }
  ps_set_search(ps, "drape");
  if (gs) ps_set_search(gs, "garbage");
  ps_ = ps;
  gs_ = gs;
}

VoiceRecognizer::~VoiceRecognizer() {
  if (ps_) ps_free(static_cast<ps_decoder_t*>(ps_));
  if (gs_) ps_free(static_cast<ps_decoder_t*>(gs_));
}

void VoiceRecognizer::begin() {
  if (!ps_) return;
  if (in_utt_) finish(0);
  if (cfg_.streaming) {
    ps_start_utt(static_cast<ps_decoder_t*>(ps_));
    if (gs_) ps_start_utt(static_cast<ps_decoder_t*>(gs_));
  }
  in_utt_ = true;
  feed_ms_ = 0;
  fed_ = 0;
  utt_.clear();
  noise_state_ = 12345u;  // the same comfort noise for the same audio: deterministic results
}

void VoiceRecognizer::feed(const int16_t* s, long n) {
  if (!ps_ || !in_utt_ || n <= 0) return;
  const double t0 = now_s();
  // Comfort noise (uniform, fixed-seed LCG, +-comfort_noise LSB): a floor under digital silence
  // for the noise subtraction (VoiceConfig::comfort_noise); a real microphone's floor is higher.
  const size_t at = utt_.size();
  utt_.resize(at + static_cast<size_t>(n));
  const int amp = static_cast<int>(cfg_.comfort_noise);
  for (long i = 0; i < n; ++i) {
    int d = 0;
    if (amp > 0) {
      noise_state_ = noise_state_ * 1664525u + 1013904223u;
      d = static_cast<int>((noise_state_ >> 16) % (2u * amp + 1u)) - amp;
    }
    utt_[at + i] = static_cast<int16_t>(std::clamp(int(s[i]) + d, -32768, 32767));
  }
  if (cfg_.streaming) {  // live CMN (see VoiceConfig::streaming)
    ps_process_raw(static_cast<ps_decoder_t*>(ps_), utt_.data() + at, static_cast<size_t>(n), FALSE,
                   FALSE);
    if (gs_)
      ps_process_raw(static_cast<ps_decoder_t*>(gs_), utt_.data() + at, static_cast<size_t>(n),
                     FALSE, FALSE);
  }
  feed_ms_ += (now_s() - t0) * 1000.0;
  fed_ += n;
}

VoiceResult VoiceRecognizer::decode(const int16_t* s, long n, double speech_s) {
  // 50 ms blocks like VoiceSource (live cepstral mean normalisation updates per block and
  // carries over between utterances: scores vary slightly, see the test).
  begin();
  for (long k = 0; k < n; k += kVoiceRate / 20) feed(s + k, std::min<long>(kVoiceRate / 20, n - k));
  return finish(speech_s);
}

namespace {
struct Seg {
  std::string w;
  int sf = 0, ef = 0;
  int32 ascr = 0;
};
std::string finish_pass(ps_decoder_t* ps, int32& score, std::vector<Seg>& segs) {
  ps_end_utt(ps);
  score = 0;
  const char* hyp = ps_get_hyp(ps, &score);
  std::string h = hyp ? hyp : "";
  segs.clear();
  for (ps_seg_t* it = ps_seg_iter(ps); it; it = ps_seg_next(it)) {
    Seg g;
    g.w = ps_seg_word(it);
    ps_seg_frames(it, &g.sf, &g.ef);
    int32 lscr = 0, lback = 0;
    ps_seg_prob(it, &g.ascr, &lscr, &lback);
    segs.push_back(g);
  }
  return h;
}
}  // namespace

VoiceResult VoiceRecognizer::finish(double speech_s) {
  VoiceResult r;
  r.speech_s = speech_s;
  if (!ps_ || !in_utt_) {
    r.reason = ps_ ? "no utterance" : error_;
    return r;
  }
  in_utt_ = false;
  auto* ps = static_cast<ps_decoder_t*>(ps_);
  auto* gs = static_cast<ps_decoder_t*>(gs_);
  const double t0 = now_s();
  if (!cfg_.streaming) {
    // The whole utterance at once: batch cepstral mean normalisation over it (the model's
    // feat.params says -cmn batch), both passes decoded now (their time is the latency part).
    for (auto* d : {ps, gs}) {
      if (!d) continue;
      ps_start_utt(d);
      ps_process_raw(d, utt_.data(), utt_.size(), FALSE, TRUE);
    }
  }
  int32 score = 0, fscore = 0;
  std::vector<Seg> cs, gsegs;
  r.hypothesis = finish_pass(ps, score, cs);
  if (gs) {
    r.filler_hypothesis = finish_pass(gs, fscore, gsegs);
    const int frames = std::max(1, ps_get_n_frames(ps));
    r.margin = double(score - fscore) / frames;
    // Word level: each command word's acoustic score against the garbage path's acoustic score
    // over the same frames (garbage segments counted pro rata); the weakest word decides.
    auto garbage_ascr = [&](int sf, int ef) {
      double a = 0;
      for (const auto& g : gsegs) {
        const int lo = std::max(sf, g.sf), hi = std::min(ef, g.ef);
        if (hi >= lo) a += double(g.ascr) * (hi - lo + 1) / (g.ef - g.sf + 1);
      }
      return a;
    };
    r.word_margin = r.hypothesis.empty() ? -1e9 : 1e9;
    for (const auto& c : cs) {
      if (c.w.empty() || c.w[0] == '<' || c.w[0] == '[' || c.ef < c.sf) continue;
      r.word_margin =
          std::min(r.word_margin, (c.ascr - garbage_ascr(c.sf, c.ef)) / (c.ef - c.sf + 1));
    }
  }
  // Speech the phrase does not explain: the FSG lets silence and noise fillers stand between and
  // around the phrase words, so a sentence that contains a phrase word ("the cloth is too long
  // here" -> "move cloth") aligns its other words to them. Count the voiced 10 ms frames (energy
  // above the utterance's noise floor + outside_db) outside the phrase words.
  {
    constexpr size_t F = kVoiceRate / 100;
    std::vector<double> db;
    for (size_t k = 0; k + F <= utt_.size(); k += F) {
      double e = 0;
      for (size_t q = k; q < k + F; ++q) e += double(utt_[q]) * utt_[q];
      db.push_back(10 * std::log10(e / F + 1.0));
    }
    std::vector<char> in_word(db.size(), 0);
    int first = -1, last = -1, wframes = 0;
    for (const auto& c : cs) {
      if (c.w.empty() || c.w[0] == '<' || c.w[0] == '[' || c.w[0] == '+' || c.ef < c.sf) continue;
      if (first < 0) first = c.sf;
      last = c.ef;
      wframes += c.ef - c.sf + 1;
      for (int f = std::max(0, c.sf); f <= c.ef && f < static_cast<int>(db.size()); ++f)
        in_word[f] = 1;
    }
    if (!db.empty()) {
      std::vector<double> sorted = db;
      std::sort(sorted.begin(), sorted.end());
      const double floor_db = sorted[sorted.size() / 10];
      int out = 0;
      for (size_t f = 0; f < db.size(); ++f)
        out += !in_word[f] && db[f] > floor_db + cfg_.outside_db;
      r.outside_s = out / 100.0;
    }
    r.words_s = first >= 0 ? (last - first + 1) / 100.0 : 0;
    if (gs && wframes > 0) r.word_span_margin = double(score - fscore) / wframes;
  }
  r.decode_ms = (now_s() - t0) * 1000.0;
  r.feed_ms = feed_ms_;
  r.audio_s = double(fed_) / kVoiceRate;
  const bool dur = cfg_.rejection == Rejection::Duration || cfg_.rejection == Rejection::Combined;
  if (dur && speech_s > cfg_.max_command_s) {
    r.reason = "too long for a command";
    return r;
  }
  if (dur && speech_s < cfg_.min_command_s) {
    r.reason = "too short";
    return r;
  }
  if (r.hypothesis.empty()) {
    r.reason = "nothing recognised";
    return r;
  }
  if (gs && r.margin - cfg_.margin_per_s * speech_s < -cfg_.filler_margin) {
    r.reason = "garbage path wins (" + r.filler_hypothesis + ")";
    return r;
  }
  if (gs && r.outside_s > cfg_.max_outside_s) {
    r.reason = "speech outside the phrase words (a sentence?)";
    return r;
  }
  if (gs && r.word_margin < cfg_.min_word_margin) {
    r.reason = "a command word fits no better than the filler path";
    return r;
  }
  for (const auto& p : phrases_)
    if (p.phrase == r.hypothesis) r.command = p.command;
  if (r.command.empty()) r.reason = "out of grammar (filler: " + r.hypothesis + ")";
  return r;
}

// ---- energy VAD ----------------------------------------------------------------------
constexpr double kMinFloorDb = 30.0;  // dB re 1 LSB^2

void EnergyVad::feed(const int16_t* s, long n, std::vector<Segment>& out) {
  constexpr int F = kVoiceRate / 100;
  for (long i = 0; i < n; ++i) {
    partial_.push_back(s[i]);
    if (static_cast<int>(partial_.size()) == F) {
      frame(partial_.data(), out);
      partial_.clear();
    }
  }
}

void EnergyVad::frame(const int16_t* f, std::vector<Segment>& out) {
  constexpr int F = kVoiceRate / 100;
  double e = 0;
  for (int i = 0; i < F; ++i) {
    const double x = c_.vad_preemphasis > 0 ? f[i] - c_.vad_preemphasis * prev_ : double(f[i]);
    prev_ = f[i];
    e += x * x;
  }
  const double db = 10 * std::log10(e / F + 1.0);
  if (floor_db_ < 0) floor_db_ = db;
  // Noise floor: follows down fast, up slowly (only outside speech).
  if (!in_speech_) floor_db_ = db < floor_db_ ? 0.9 * floor_db_ + 0.1 * db : floor_db_ + 0.02;
  // Never below -60 dBFS (RMS 33): a real microphone's floor is above it, and digital silence
  // in a synthesised file (0 dB here) would make every quiet frame between words "speech".
  floor_db_ = std::max(floor_db_, kMinFloorDb);
  const long preroll = static_cast<long>(c_.preroll_s * kVoiceRate);
  const long hang = static_cast<long>(c_.hangover_s * kVoiceRate);
  if (!in_speech_) {
    ring_.insert(ring_.end(), f, f + F);
    if (static_cast<long>(ring_.size()) > preroll)
      ring_.erase(ring_.begin(), ring_.end() - preroll);
    above_ = db > floor_db_ + c_.vad_on_db ? above_ + 1 : 0;
    if (above_ >= 3) {  // 30 ms of loud frames
      in_speech_ = true;
      cur_ = ring_;
      start_ = pos_ + F - static_cast<long>(ring_.size());
      last_voiced_ = pos_ + F;
      ring_.clear();
    }
  } else {
    cur_.insert(cur_.end(), f, f + F);
    if (db > floor_db_ + c_.vad_off_db) last_voiced_ = pos_ + F;
    if (pos_ + F - last_voiced_ >= hang || cur_.size() > 10u * kVoiceRate) {
      Segment s;
      s.audio = std::move(cur_);
      s.start = start_;
      s.speech_end = last_voiced_;
      s.decided = pos_ + F;
      out.push_back(std::move(s));
      cur_.clear();
      in_speech_ = false;
      above_ = 0;
    }
  }
  pos_ += F;
}

void EnergyVad::flush(std::vector<Segment>& out) {
  if (!in_speech_) return;
  Segment s;
  s.audio = std::move(cur_);
  s.start = start_;
  s.speech_end = last_voiced_;
  s.decided = pos_;
  out.push_back(std::move(s));
  cur_.clear();
  in_speech_ = false;
}

// ---- threaded source ------------------------------------------------------------------
VoiceSource::VoiceSource(VoiceConfig cfg, std::unique_ptr<AudioInput> input)
    : cfg_(std::move(cfg)), in_(std::move(input)) {
  th_ = std::thread([this] { run(); });
}

VoiceSource::~VoiceSource() {
  stop_ = true;
  wait();
}

void VoiceSource::wait() {
  if (th_.joinable()) th_.join();
}

void VoiceSource::run() {
  auto set = [&](SourceState s, const std::string& m) {
    std::lock_guard lk(mu_);
    status_ = {s, m};
  };
  if (!in_ || !in_->ok()) {
    set(SourceState::Unavailable, "voice: " + (in_ ? in_->error() : std::string("no input")));
    done_ = true;
    return;
  }
  VoiceRecognizer rec(cfg_);
  if (!rec.ok()) {
    set(SourceState::Unavailable, rec.error());
    done_ = true;
    return;
  }
  set(SourceState::Ok, "voice: listening");
  EnergyVad vad(cfg_);
  std::vector<int16_t> buf(kVoiceRate / 20);
  std::vector<EnergyVad::Segment> segs;
  bool ended = false, streaming = false;
  long stream_start = -1, fed = 0;
  while (!stop_ && !ended) {
    const long n = in_->read(buf.data(), static_cast<long>(buf.size()));
    if (n < 0) {
      set(SourceState::Error, "voice: " + in_->error());
      break;
    }
    if (n == 0) {
      ended = true;
      vad.flush(segs);
    } else {
      vad.feed(buf.data(), n, segs);
    }
    // Completed utterances: the one being fed only needs its last audio; one that started and
    // ended within this block is fed whole. finish() decodes it (VoiceConfig::streaming).
    for (auto& s : segs) {
      const double speech_s = double(s.speech_end - s.start) / kVoiceRate - cfg_.preroll_s;
      if (!streaming || s.start != stream_start) {
        rec.begin();
        fed = 0;
      }
      rec.feed(s.audio.data() + fed, static_cast<long>(s.audio.size()) - fed);
      streaming = false;
      VoiceEvent ev;
      ev.result = rec.finish(speech_s);
      ev.speech_end = s.speech_end;
      ev.decided = s.decided;
      ev.latency_ms = double(s.decided - s.speech_end) * 1000.0 / kVoiceRate + ev.result.decode_ms;
      std::lock_guard lk(mu_);
      if (!ev.result.command.empty())
        triggers_.push_back(Trigger{ev.result.command, "voice", now_s(), Hand::Right, true});
      events_.push_back(std::move(ev));
    }
    // An utterance in progress: feed its audio as it arrives.
    if (vad.in_speech()) {
      if (!streaming || vad.current_start() != stream_start) {
        rec.begin();
        streaming = true;
        stream_start = vad.current_start();
        fed = 0;
      }
      const auto& cur = vad.current();
      rec.feed(cur.data() + fed, static_cast<long>(cur.size()) - fed);
      fed = static_cast<long>(cur.size());
    }
    segs.clear();
  }
  if (ended) {
    std::lock_guard lk(mu_);
    if (status_.state == SourceState::Ok) status_ = {SourceState::NoData, "voice: end of input"};
  }
  done_ = true;
}

std::vector<Trigger> VoiceSource::take_triggers() {
  std::lock_guard lk(mu_);
  return std::exchange(triggers_, {});
}
std::vector<VoiceEvent> VoiceSource::take_events() {
  std::lock_guard lk(mu_);
  return std::exchange(events_, {});
}
SourceStatus VoiceSource::status() const {
  std::lock_guard lk(mu_);
  return status_;
}

}  // namespace drape::tracking
