// Voice benchmark driver (bench/voice_driver.cpp, run by bench/voice.sh): reads a list "wav \t
// expected \t text \t speech_end_s", decodes every file through the same path as the app (energy
// VAD -> pocketsphinx), compares rejection methods and writes out/bench/voice.json.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tracking/voice.hpp"

using namespace drape::tracking;

struct Item {
  std::string wav, expect, text;
  double speech_end = 0;
  std::vector<int16_t> audio;
};

struct Outcome {
  std::string hyp, command, garbage_hyp;
  double speech_s = 0, margin = 0, latency_ms = 0, decode_ms = 0;
};

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: voice_bench list.tsv out.json\n");
    return 2;
  }
  std::vector<Item> items;
  std::ifstream in(argv[1]);
  for (std::string line; std::getline(in, line);) {
    std::stringstream ss(line);
    Item it;
    std::string end;
    std::getline(ss, it.wav, '\t');
    std::getline(ss, it.expect, '\t');
    std::getline(ss, it.text, '\t');
    std::getline(ss, end, '\t');
    it.speech_end = std::stod(end);
    std::string err;
    if (!read_wav(it.wav, it.audio, &err)) {
      std::fprintf(stderr, "%s\n", err.c_str());
      return 1;
    }
    items.push_back(std::move(it));
  }
  // Decode once with everything computed (garbage margin on), then apply each rejection rule.
  VoiceConfig cfg;
  cfg.rejection = Rejection::Garbage;
  cfg.garbage_margin = 1e9;  // compute margins, never reject here
  VoiceRecognizer rec(cfg);
  if (!rec.ok()) {
    std::fprintf(stderr, "%s\n", rec.error().c_str());
    return 1;
  }
  std::vector<Outcome> out;
  for (const auto& it : items) {
    EnergyVad vad(cfg);
    std::vector<EnergyVad::Segment> segs;
    vad.feed(it.audio.data(), static_cast<long>(it.audio.size()), segs);
    vad.flush(segs);
    Outcome o;
    // The utterance = the longest segment (the VAD may also fire on noise bursts).
    const EnergyVad::Segment* best = nullptr;
    for (const auto& s : segs)
      if (!best || s.speech_end - s.start > best->speech_end - best->start) best = &s;
    if (best) {
      const double speech_s = double(best->speech_end - best->start) / kVoiceRate - cfg.preroll_s;
      const auto r =
          rec.decode(best->audio.data(), static_cast<long>(best->audio.size()), speech_s);
      o.hyp = r.hypothesis;
      o.command = r.command;
      o.garbage_hyp = r.garbage_hypothesis;
      o.speech_s = speech_s;
      o.margin = r.margin;
      o.decode_ms = r.decode_ms;
      // end of utterance (known from synthesis) -> trigger: VAD decision time + decode time.
      o.latency_ms = (double(best->decided) / kVoiceRate - it.speech_end) * 1000.0 + r.decode_ms;
    }
    out.push_back(o);
  }
  struct Method {
    std::string name;
    double margin;  // reject if margin < -margin
    bool duration;
  };
  std::vector<Method> methods = {{"none", 1e9, false},         {"duration", 1e9, true},
                                 {"garbage(m=10)", 10, false}, {"garbage(m=0)", 0, false},
                                 {"garbage(m=-5)", -5, false}, {"garbage(m=0)+duration", 0, true}};
  nlohmann::json j;
  std::printf("\n%-24s %9s %9s %8s %8s\n", "rejection", "accuracy", "false_tr", "cmds", "non-cmd");
  std::string chosen = "garbage(m=0)+duration";
  for (const auto& m : methods) {
    int cmd = 0, ok = 0, non = 0, fa = 0;
    for (size_t i = 0; i < items.size(); ++i) {
      const auto& o = out[i];
      bool accept = !o.command.empty();
      if (m.duration && (o.speech_s > cfg.max_command_s || o.speech_s < cfg.min_command_s))
        accept = false;
      if (o.margin < -m.margin) accept = false;
      if (items[i].expect == "-") {
        ++non;
        fa += accept;
      } else {
        ++cmd;
        ok += accept && o.command == items[i].expect;
      }
    }
    const double acc = cmd ? double(ok) / cmd : 0, far = non ? double(fa) / non : 0;
    std::printf("%-24s %8.1f%% %8.1f%% %8d %8d\n", m.name.c_str(), 100 * acc, 100 * far, cmd, non);
    j["methods"][m.name] = {{"accuracy", acc}, {"false_trigger_rate", far}};
    if (m.name == chosen) {
      j["accuracy"] = acc;
      j["false_trigger_rate"] = far;
      j["rejection"] = chosen;
      j["commands"] = cmd;
      j["non_commands"] = non;
    }
  }
  std::vector<double> lat;
  double dec = 0;
  for (size_t i = 0; i < items.size(); ++i)
    if (items[i].expect != "-" && !out[i].command.empty()) {
      lat.push_back(out[i].latency_ms);
      dec += out[i].decode_ms;
    }
  std::sort(lat.begin(), lat.end());
  const double med = lat.empty() ? 0 : lat[lat.size() / 2];
  const double p90 = lat.empty() ? 0 : lat[lat.size() * 9 / 10];
  j["latency_ms"] = med;
  j["latency_p90_ms"] = p90;
  j["decode_ms_mean"] = lat.empty() ? 0 : dec / lat.size();
  j["utterances"] = items.size();
  j["snr_db"] = 10;
  j["hangover_ms"] = cfg.hangover_s * 1000;
  // Per-utterance detail for inspection.
  for (size_t i = 0; i < items.size(); ++i)
    j["detail"].push_back({{"wav", items[i].wav},
                           {"expect", items[i].expect},
                           {"hyp", out[i].hyp},
                           {"garbage_hyp", out[i].garbage_hyp},
                           {"margin", out[i].margin},
                           {"speech_s", out[i].speech_s},
                           {"latency_ms", out[i].latency_ms}});
  std::printf(
      "\nlatency end of utterance -> trigger: median %.0f ms, p90 %.0f ms (hangover %.0f ms "
      "+ decode %.0f ms mean)\nutterances: %zu\n",
      med, p90, cfg.hangover_s * 1000, j["decode_ms_mean"].get<double>(), items.size());
  std::ofstream(argv[2]) << j.dump(2) << "\n";
  std::printf("wrote %s\n", argv[2]);
  return 0;
}
