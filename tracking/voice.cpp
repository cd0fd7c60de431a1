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
  explicit AlsaInput(const std::string& dev) {
    int rc = snd_pcm_open(&pcm_, dev.c_str(), SND_PCM_STREAM_CAPTURE, 0);
    if (rc < 0) {
      err_ = "microphone '" + dev + "': " + snd_strerror(rc);
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
      err_ = std::string("microphone: ") + snd_strerror(static_cast<int>(r));
      ok_ = false;
      return -1;
    }
    return static_cast<long>(r);
  }

 private:
  snd_pcm_t* pcm_ = nullptr;
  std::string err_;
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
  cmd_ln_t* c = cmd_ln_init(nullptr, ps_args(), TRUE, "-hmm", cfg_.model_dir.c_str(), "-dict",
                            cfg_.dict.c_str(), "-logfn", "/dev/null", "-remove_silence", "no",
                            "-wip", wip, nullptr);
  if (!c) {
    error_ = "voice: pocketsphinx rejected the configuration";
    return;
  }
  ps_decoder_t* ps = ps_init(c);
  cmd_ln_free_r(c);
  if (!ps) {
    error_ = "voice: pocketsphinx failed to load " + cfg_.model_dir;
    return;
  }
  if (ps_set_jsgf_string(ps, "drape", grammar_.c_str()) < 0 ||
      ps_set_jsgf_string(ps, "filler", filler_grammar.c_str()) < 0) {
    error_ = "voice: bad grammar from " + cfg_.phrases + " / " + cfg_.filler +
             " (a word missing from " + cfg_.dict + "?)";
    ps_free(ps);
    return;
  }
  ps_ = ps;
}

VoiceRecognizer::~VoiceRecognizer() {
  if (ps_) ps_free(static_cast<ps_decoder_t*>(ps_));
}

VoiceResult VoiceRecognizer::decode(const int16_t* s, long n, double speech_s) {
  VoiceResult r;
  r.speech_s = speech_s;
  if (!ps_) {
    r.reason = error_;
    return r;
  }
  auto* ps = static_cast<ps_decoder_t*>(ps_);
  const double t0 = now_s();
  auto pass = [&](const char* search, int32& score) {
    ps_set_search(ps, search);
    ps_start_utt(ps);
    ps_process_raw(ps, s, static_cast<size_t>(n), FALSE, TRUE);
    ps_end_utt(ps);
    score = 0;
    const char* hyp = ps_get_hyp(ps, &score);
    return std::string(hyp ? hyp : "");
  };
  int32 score = 0, fscore = 0;
  r.hypothesis = pass("drape", score);
  const bool garbage =
      cfg_.rejection == Rejection::Garbage || cfg_.rejection == Rejection::Combined;
  if (garbage && !r.hypothesis.empty()) {
    const int frames = std::max(1, ps_get_n_frames(ps));
    r.filler_hypothesis = pass("filler", fscore);
    r.margin = double(score - fscore) / frames;
  }
  r.decode_ms = (now_s() - t0) * 1000.0;
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
  if (garbage && r.margin < -cfg_.filler_margin) {
    r.reason = "filler path wins (" + r.filler_hypothesis + ")";
    return r;
  }
  for (const auto& p : phrases_)
    if (p.phrase == r.hypothesis) r.command = p.command;
  if (r.command.empty()) r.reason = "out of grammar (filler: " + r.hypothesis + ")";
  return r;
}

// ---- energy VAD ----------------------------------------------------------------------
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
  for (int i = 0; i < F; ++i) e += double(f[i]) * f[i];
  const double db = 10 * std::log10(e / F + 1.0);
  if (floor_db_ < 0) floor_db_ = db;
  // Noise floor: follows down fast, up slowly (only outside speech).
  if (!in_speech_) floor_db_ = db < floor_db_ ? 0.9 * floor_db_ + 0.1 * db : floor_db_ + 0.02;
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
  bool ended = false;
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
    for (auto& s : segs) {
      const double speech_s = double(s.speech_end - s.start) / kVoiceRate - cfg_.preroll_s;
      VoiceEvent ev;
      ev.result = rec.decode(s.audio.data(), static_cast<long>(s.audio.size()), speech_s);
      ev.speech_end = s.speech_end;
      ev.decided = s.decided;
      ev.latency_ms = double(s.decided - s.speech_end) * 1000.0 / kVoiceRate + ev.result.decode_ms;
      std::lock_guard lk(mu_);
      if (!ev.result.command.empty())
        triggers_.push_back(Trigger{ev.result.command, "voice", now_s(), Hand::Right, true});
      events_.push_back(std::move(ev));
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
