// Generates a few utterances with espeak-ng + sox into the build dir at test time and runs them
// through the threaded voice source (energy VAD -> one pocketsphinx pass over the command phrases
// and a filler-word loop -> rejection).
#include "tracking/voice.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

using namespace drape::tracking;

namespace {
const std::string kDir = std::string(DRAPE_BINARY_DIR) + "/voice_test";

// Speech at 16 kHz with 0.4 s / 0.7 s of padding and pink noise 20 dB below the speech.
std::string synth(const std::string& name, const std::string& text, const std::string& voice) {
  const std::string out = kDir + "/" + name + ".wav";
  const std::string cmd = "set -e; cd '" + kDir + "'; espeak-ng -v " + voice + " -s 150 -w " +
                          name + ".raw.wav '" + text + "'; sox " + name +
                          ".raw.wav -r 16000 -c 1 -b 16 " + name +
                          ".s.wav norm -6 pad 0.4 0.7; d=$(soxi -D " + name +
                          ".s.wav); sox -R -n -r 16000 -c 1 -b 16 " + name +
                          ".n.wav synth $d pinknoise vol 0.02; sox -m -v 1 " + name +
                          ".s.wav -v 1 " + name + ".n.wav " + name + ".wav";
  if (std::system(cmd.c_str()) != 0) return "";
  return out;
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
  };
  const Case cases[] = {{"release it", "en-us+f3", "release"},
                        {"stop now", "en-us", "stop"},
                        {"undo that", "en-us+f3", "undo"},
                        {"pinch cloth", "en-us", "pinch"},
                        {"pin here", "en-us", "pin"},
                        {"the weather is nice today", "en-us", ""},
                        {"pass me the tape measure", "en-us+f3", ""}};
  int i = 0;
  for (const auto& c : cases) {
    const std::string wav = synth("u" + std::to_string(i++), c.text, c.voice);
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
  std::printf("statuses: %s | %s\n", a.status().message.c_str(), b.status().message.c_str());
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
  // The shipped phrase file: nine distinct two-word phrases mapping to the nine commands.
  std::vector<VoicePhrase> ph;
  std::string err;
  ASSERT_TRUE(load_phrases(std::string(DRAPE_SOURCE_DIR) + "/assets/voice/phrases.tsv", ph, &err))
      << err;
  ASSERT_EQ(ph.size(), 9u);
  for (const auto& p : ph) EXPECT_NE(p.phrase.find(' '), std::string::npos) << p.phrase;
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
