// Generates a few utterances with espeak-ng + sox into the build dir at test time and runs them
// through the threaded voice source (energy VAD -> pocketsphinx over the command phrases and a
// phone-loop garbage path -> rejection by garbage margin and speech outside the phrase words).
#include "tracking/voice.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <string>
#include <vector>

using namespace drape::tracking;

namespace {
const std::string kDir = std::string(DRAPE_BINARY_DIR) + "/voice_test";

// Speech at 16 kHz with 0.4 s / 0.7 s of padding and pink noise `noise_vol` (sox vol; 0.02 is
// about 20 dB below the speech, 0.09 about 10 dB, 0 = none: digital silence around the speech).
std::string synth(const std::string& name, const std::string& text, const std::string& voice,
                  int speed = 150, double noise_vol = 0.02) {
  const std::string out = kDir + "/" + name + ".wav";
  std::string cmd = "set -e; cd '" + kDir + "'; espeak-ng -v " + voice + " -s " +
                    std::to_string(speed) + " -w " + name + ".raw.wav '" + text + "'; sox " + name +
                    ".raw.wav -r 16000 -c 1 -b 16 " + name + ".s.wav norm -6 pad 0.4 0.7; ";
  if (noise_vol > 0)
    cmd += "d=$(soxi -D " + name + ".s.wav); sox -R -n -r 16000 -c 1 -b 16 " + name +
           ".n.wav synth $d pinknoise vol " + std::to_string(noise_vol) + "; sox -m -v 1 " + name +
           ".s.wav -v 1 " + name + ".n.wav " + name + ".wav";
  else
    cmd += "cp " + name + ".s.wav " + name + ".wav";
  if (std::system(cmd.c_str()) != 0) return "";
  return out;
}

double rms(const std::string& wav) {
  std::vector<int16_t> s;
  std::string err;
  if (!read_wav(wav, s, &err) || s.empty()) return 0;
  double e = 0;
  for (int16_t x : s) e += double(x) * x;
  return std::sqrt(e / double(s.size()));
}

std::vector<VoiceEvent> run(const std::string& wav) {
  VoiceSource src(VoiceConfig{}, open_wav_input(wav));
  src.wait();
  EXPECT_NE(src.status().state, SourceState::Error) << src.status().message;
  return src.take_events();
}
}  // namespace

class Voice : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { std::system(("mkdir -p '" + kDir + "'").c_str()); }
};

TEST_F(Voice, RecognisesCommandsAndRejectsSentence) {
  struct Case {
    const char* text;
    const char* voice;
    const char* expect;  // "" = must be rejected
    int speed;
  };
  const Case cases[] = {{"release it", "en-us+f3", "release", 150},
                        {"stop now", "en-us", "stop", 150},
                        {"undo change", "en-us+f3", "undo", 150},
                        {"cut across", "en-us", "cut", 150},
                        {"pinch cloth", "en-us", "pinch", 150},
                        // slow speech: the pause between the words must not end the utterance
                        {"pinch cloth", "en-us+m3", "pinch", 110},
                        {"pin here", "en-us", "pin", 150},
                        {"the weather is nice today", "en-us", "", 150},
                        {"pass me the tape measure", "en-us+f3", "", 150},
                        // contains a phrase word: the phrase path aligns "move cloth" inside it
                        {"the cloth is too long here", "en-us", "", 150}};
  int i = 0;
  for (const auto& c : cases) {
    const std::string wav = synth("u" + std::to_string(i++), c.text, c.voice, c.speed);
    ASSERT_FALSE(wav.empty()) << "espeak-ng/sox failed";
    const auto ev = run(wav);
    std::string got;
    for (const auto& e : ev) {
      std::printf("'%s' -> hyp '%s' command '%s' (%s) speech %.2f s latency %.0f ms\n", c.text,
                  e.result.hypothesis.c_str(), e.result.command.c_str(), e.result.reason.c_str(),
                  e.result.speech_s, e.latency_ms);
      if (!e.result.command.empty()) got += (got.empty() ? "" : " ") + e.result.command;
    }
    EXPECT_EQ(got, c.expect) << c.text;
  }
}

TEST_F(Voice, CorruptAudioAndMissingMicrophoneGiveStatus) {
  const std::string bad = kDir + "/corrupt.wav";
  std::ofstream(bad) << "RIFF\x10\x00\x00\x00WAVEjunkjunk";
  VoiceSource a(VoiceConfig{}, open_wav_input(bad));
  a.wait();
  EXPECT_EQ(a.status().state, SourceState::Unavailable);
  EXPECT_NE(a.status().message.find("corrupt.wav"), std::string::npos) << a.status().message;
  VoiceSource b(VoiceConfig{}, open_alsa_input("hw:97,0"));
  b.wait();
  EXPECT_EQ(b.status().state, SourceState::Unavailable);
  EXPECT_NE(b.status().message.find("microphone"), std::string::npos) << b.status().message;
  EXPECT_TRUE(b.take_triggers().empty());
  std::printf("statuses: %s | %s\n", a.status().message.c_str(), b.status().message.c_str());
  // The other sources keep working while the failed voice sources exist: XR controller input
  // still gives frames and button triggers, and a voice source on good audio still triggers.
  XrHandSource xr;
  XrControllerInput ctl;
  ctl.active = true;
  ctl.time = 1.0;
  ctl.a = true;
  xr.feed_controller(Hand::Right, ctl);
  EXPECT_EQ(xr.poll().size(), 1u);
  EXPECT_FALSE(xr.take_triggers().empty());
  const std::string good = synth("good", "stop now", "en-us");
  ASSERT_FALSE(good.empty());
  VoiceSource ok(VoiceConfig{}, open_wav_input(good));
  ok.wait();
  const auto trig = ok.take_triggers();
  ASSERT_EQ(trig.size(), 1u) << ok.status().message;
  EXPECT_EQ(trig[0].command, "stop");
  // Truncated data chunk: header promises more samples than the file holds.
  const std::string trunc = kDir + "/truncated.wav";
  {
    std::ofstream f(trunc, std::ios::binary);
    const unsigned char h[44] = {'R', 'I', 'F',  'F',  36,  0,   1,   0,    'W', 'A', 'V',
                                 'E', 'f', 'm',  't',  ' ', 16,  0,   0,    0,   1,   0,
                                 1,   0,   0x80, 0x3e, 0,   0,   0,   0x7d, 0,   0,   2,
                                 0,   16,  0,    'd',  'a', 't', 'a', 0,    0,   1,   0};
    f.write(reinterpret_cast<const char*>(h), 44);
    std::vector<char> some(1000, 0);
    f.write(some.data(), some.size());
  }
  VoiceSource c(VoiceConfig{}, open_wav_input(trunc));
  c.wait();
  EXPECT_EQ(c.status().state, SourceState::Error);
  EXPECT_NE(c.status().message.find("truncated"), std::string::npos) << c.status().message;
}

TEST_F(Voice, PhraseFileAndGrammar) {
  // The shipped phrase file: fifteen distinct two-word phrases mapping to the fifteen commands
  // (the sim's operations, the help, the pattern, the colour map and "save session").
  std::vector<VoicePhrase> ph;
  std::string err;
  ASSERT_TRUE(load_phrases(std::string(DRAPE_SOURCE_DIR) + "/assets/voice/phrases.tsv", ph, &err))
      << err;
  ASSERT_EQ(ph.size(), 15u);
  std::set<std::string> phrases, commands;
  for (const auto& p : ph) phrases.insert(p.phrase), commands.insert(p.command);
  EXPECT_EQ(phrases.size(), 15u);
  EXPECT_EQ(commands.size(), 15u);
  for (const auto& p : ph) EXPECT_NE(p.phrase.find(' '), std::string::npos) << p.phrase;
  EXPECT_EQ(ph.back().phrase, "save session");
  EXPECT_EQ(ph.back().command, "save");
  VoiceRecognizer rec(VoiceConfig{});
  ASSERT_TRUE(rec.ok()) << rec.error();
  EXPECT_NE(rec.grammar().find("pinch cloth | release it"), std::string::npos) << rec.grammar();
  EXPECT_NE(rec.grammar().find("public <utterance> = <command>;"), std::string::npos)
      << rec.grammar();
  // The single-pass variant puts the filler path (no Kleene loop, see voice.cpp) in the grammar.
  VoiceConfig single;
  single.rejection = Rejection::Single;
  VoiceRecognizer rs(single);
  ASSERT_TRUE(rs.ok()) << rs.error();
  EXPECT_NE(rs.grammar().find("<command> | <fillers>"), std::string::npos) << rs.grammar();
  EXPECT_EQ(rs.grammar().find('+'), std::string::npos) << rs.grammar();
  // Bad phrase files: a clear error naming the file and line; the recognizer reports it.
  const std::string bad = kDir + "/bad_phrases.tsv";
  std::ofstream(bad) << "pinch cloth\tpinch\nno tab here\n";
  EXPECT_FALSE(load_phrases(bad, ph, &err));
  EXPECT_NE(err.find("bad_phrases.tsv:2"), std::string::npos) << err;
  VoiceConfig c;
  c.phrases = bad;
  VoiceRecognizer r2(c);
  EXPECT_FALSE(r2.ok());
  EXPECT_NE(r2.error().find("bad_phrases.tsv:2"), std::string::npos) << r2.error();
  // A phrase word missing from the dictionary: the grammar is refused with a clear error.
  const std::string oov = kDir + "/oov_phrases.tsv";
  std::ofstream(oov) << "zorbify cloth\tpinch\n";
  c.phrases = oov;
  VoiceRecognizer r3(c);
  EXPECT_FALSE(r3.ok());
  EXPECT_NE(r3.error().find("bad grammar"), std::string::npos) << r3.error();
  std::printf("errors: %s | %s\n", r2.error().c_str(), r3.error().c_str());
}

TEST_F(Voice, CleanAndNoisyCommands) {
  // The app's scenario cue: espeak-ng 'pin here' at 140 wpm, no noise at all (digital silence
  // around it), cut by the VAD and decoded as in xr_app. pocketsphinx's noise subtraction breaks
  // on digital silence (without the comfort noise floor this decoded as 'undo that' with the old
  // phrases).
  // Made exactly as xr_app's make_voice_wav() and tests/xr_app make it (no normalisation).
  const std::string clean = kDir + "/clean_pin.wav";
  const std::string make = "cd '" + kDir +
                           "' && espeak-ng -s 140 -w clean_pin_22k.wav 'pin here' " +
                           "&& sox clean_pin_22k.wav -r 16000 -c 1 -b 16 clean_pin.wav pad 0.3 0.5";
  ASSERT_EQ(std::system(make.c_str()), 0) << make;
  std::vector<int16_t> pcm;
  std::string err;
  ASSERT_TRUE(read_wav(clean, pcm, &err)) << err;
  auto app_path = [&](const VoiceConfig& cfg) {
    VoiceRecognizer rec(cfg);
    EXPECT_TRUE(rec.ok()) << rec.error();
    EnergyVad vad(rec.config());
    std::vector<EnergyVad::Segment> segs;
    vad.feed(pcm.data(), static_cast<long>(pcm.size()), segs);
    vad.flush(segs);
    EXPECT_EQ(segs.size(), 1u);
    if (segs.empty()) return VoiceResult{};
    const auto& sg = segs.front();
    return rec.decode(sg.audio.data(), static_cast<long>(sg.audio.size()),
                      double(sg.speech_end - sg.start) / kVoiceRate);
  };
  const VoiceResult r = app_path(VoiceConfig{});
  VoiceConfig bare;
  bare.comfort_noise = 0;
  const VoiceResult b = app_path(bare);
  std::printf(
      "clean 'pin here': hyp '%s' command '%s' margin %.1f outside %.2f s (%s) | without comfort "
      "noise: hyp '%s'\n",
      r.hypothesis.c_str(), r.command.c_str(), r.margin, r.outside_s, r.reason.c_str(),
      b.hypothesis.c_str());
  EXPECT_EQ(r.hypothesis, "pin here");
  EXPECT_EQ(r.command, "pin") << r.reason;
  // The whole file (0.3 s + 0.5 s of digital silence plus espeak's own) decoded at once: the
  // comfort noise floor is what keeps the noise subtraction sane here.
  auto whole_file = [&](const VoiceConfig& cfg) {
    VoiceRecognizer rec(cfg);
    return rec.decode(pcm.data(), static_cast<long>(pcm.size()), 0.9);
  };
  const VoiceResult wf = whole_file(VoiceConfig{}), wb = whole_file(bare);
  std::printf("whole clean file: hyp '%s' | without comfort noise: hyp '%s'\n",
              wf.hypothesis.c_str(), wb.hypothesis.c_str());
  EXPECT_EQ(wf.hypothesis, "pin here");
  // The same file through the threaded source.
  const auto ev = run(clean);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].result.command, "pin") << ev[0].result.reason;

  // A command at 10 dB SNR (pink noise, RMS over the whole padded speech file vs the noise).
  const std::string noisy = synth("noisy_stop", "stop now", "en-us+f3", 150, 0.09);
  ASSERT_FALSE(noisy.empty());
  const double snr =
      20 * std::log10(rms(kDir + "/noisy_stop.s.wav") / rms(kDir + "/noisy_stop.n.wav"));
  const auto nev = run(noisy);
  std::string got;
  for (const auto& e : nev) {
    std::printf("10 dB: SNR %.1f dB, hyp '%s' command '%s' (%s) margin %.1f latency %.0f ms\n", snr,
                e.result.hypothesis.c_str(), e.result.command.c_str(), e.result.reason.c_str(),
                e.result.margin, e.latency_ms);
    got += e.result.command;
  }
  EXPECT_NEAR(snr, 10.0, 1.5);
  EXPECT_EQ(got, "stop");
}

TEST_F(Voice, DecodeIsDeterministicAndBlockSizeIndependent) {
  // The utterance is decoded whole after its end (batch CMN): feeding it in any blocks gives
  // exactly decode()'s result on a recognizer with the same history. (pocketsphinx's noise
  // subtraction keeps its noise estimate from one utterance to the next, so a recognizer's first
  // utterance scores differently from a repeat: printed.)
  const std::string wav = synth("blocks", "move cloth", "en-us+m3");
  ASSERT_FALSE(wav.empty());
  std::vector<int16_t> audio;
  std::string err;
  ASSERT_TRUE(read_wav(wav, audio, &err)) << err;
  auto fresh = [&](size_t block) {
    VoiceRecognizer rec(VoiceConfig{});
    EXPECT_TRUE(rec.ok()) << rec.error();
    if (block == 0) return rec.decode(audio.data(), static_cast<long>(audio.size()), 0.6);
    rec.begin();
    for (size_t k = 0; k < audio.size(); k += block)
      rec.feed(audio.data() + k, static_cast<long>(std::min(block, audio.size() - k)));
    return rec.finish(0.6);
  };
  const VoiceResult whole = fresh(0), small = fresh(kVoiceRate / 20), big = fresh(kVoiceRate / 3);
  VoiceRecognizer rec(VoiceConfig{});
  ASSERT_TRUE(rec.ok()) << rec.error();
  rec.decode(audio.data(), static_cast<long>(audio.size()), 0.6);
  const VoiceResult again = rec.decode(audio.data(), static_cast<long>(audio.size()), 0.6);
  std::printf(
      "fresh decode '%s' margin %.3f outside %.2f (%.1f ms) | 50 ms blocks '%s' %.3f | 333 ms "
      "'%s' %.3f | repeat on the same recognizer '%s' %.3f\n",
      whole.hypothesis.c_str(), whole.margin, whole.outside_s, whole.decode_ms,
      small.hypothesis.c_str(), small.margin, big.hypothesis.c_str(), big.margin,
      again.hypothesis.c_str(), again.margin);
  EXPECT_EQ(whole.hypothesis, "move cloth");
  EXPECT_EQ(whole.command, "move");
  EXPECT_EQ(small.hypothesis, whole.hypothesis);
  EXPECT_EQ(big.hypothesis, whole.hypothesis);
  EXPECT_EQ(small.margin, whole.margin);
  EXPECT_EQ(big.margin, whole.margin);
  EXPECT_EQ(small.outside_s, whole.outside_s);
  EXPECT_EQ(again.command, "move");
  EXPECT_NEAR(small.audio_s, double(audio.size()) / kVoiceRate, 1e-9);
  // finish() without begin(): a clear reason, no crash.
  EXPECT_EQ(rec.finish(0.5).reason, "no utterance");
}

TEST_F(Voice, MarginPerSecondChargesLongUtterances) {
  // VoiceConfig::margin_per_s: the margin rule compares margin - margin_per_s * speech_s with
  // -filler_margin. The same audio with a stated speech duration just under and just over the
  // break-even duration is accepted and rejected.
  const std::string wav = synth("per_s", "move cloth", "en-us+m3");
  ASSERT_FALSE(wav.empty());
  std::vector<int16_t> audio;
  std::string err;
  ASSERT_TRUE(read_wav(wav, audio, &err)) << err;
  const long n = static_cast<long>(audio.size());
  VoiceConfig cfg;
  cfg.margin_per_s = 0;
  const VoiceResult base = VoiceRecognizer(cfg).decode(audio.data(), n, 0.6);
  ASSERT_EQ(base.command, "move") << base.reason;
  const double slack = base.margin + cfg.filler_margin;  // > 0: accepted by the plain rule
  ASSERT_GT(slack, 0.0);
  cfg.margin_per_s = 4;
  const double even_s = slack / cfg.margin_per_s;  // speech_s where the rule breaks even
  const VoiceResult shorter = VoiceRecognizer(cfg).decode(audio.data(), n, even_s * 0.9);
  const VoiceResult longer = VoiceRecognizer(cfg).decode(audio.data(), n, even_s * 1.1);
  std::printf("margin %.3f, break-even speech %.3f s: %.3f s -> '%s', %.3f s -> '%s' (%s)\n",
              base.margin, even_s, even_s * 0.9, shorter.command.c_str(), even_s * 1.1,
              longer.command.c_str(), longer.reason.c_str());
  EXPECT_DOUBLE_EQ(shorter.margin, base.margin);
  ASSERT_GE(even_s * 0.9, cfg.min_command_s);  // else "too short" would decide
  EXPECT_EQ(shorter.command, "move") << shorter.reason;
  EXPECT_EQ(longer.command, "");
  EXPECT_NE(longer.reason.find("garbage path wins"), std::string::npos) << longer.reason;
}
