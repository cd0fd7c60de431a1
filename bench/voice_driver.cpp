// Voice benchmark driver (bench/voice_driver.cpp, run by bench/voice.sh): reads a list "wav \t
// expected \t text \t speech_end_s" and decodes every file through the same path as the app
// (energy VAD -> one pocketsphinx pass over command phrases + filler loop).
//   voice_bench --tune list.tsv tuned.txt [--phrases F]: grid over wip, filler margin and the
//     duration limit; picks the best accuracy with false triggers <= 1 % and writes
//     "min_fillers wip margin max_command_s" to tuned.txt. Only the tuning set is used here.
//   voice_bench list.tsv out.json [--weight W] [--max-s D] [--phrases F]: evaluates one fixed
//     configuration on the (separate) test set and writes out/bench/voice.json.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tracking/voice.hpp"

using namespace drape::tracking;

namespace {
struct Item {
  std::string wav, expect, text;
  double speech_end = 0;
  std::vector<int16_t> audio;
};

struct Outcome {
  std::string hyp, command;
  double speech_s = 0, latency_ms = 0, decode_ms = 0, margin = 0;
  bool heard = false;
};

struct Score {
  int cmd = 0, ok = 0, non = 0, fa = 0;
  double acc() const { return cmd ? double(ok) / cmd : 0; }
  double far() const { return non ? double(fa) / non : 0; }
};

// Decodes every item with cfg (duration rule off: applied afterwards by score()).
std::vector<Outcome> decode_all(const std::vector<Item>& items, VoiceConfig cfg) {
  if (cfg.rejection != Rejection::Single) cfg.rejection = Rejection::Garbage;
  cfg.filler_margin = 1e9;  // margins computed, applied afterwards by score()
  VoiceRecognizer rec(cfg);
  if (!rec.ok()) {
    std::fprintf(stderr, "%s\n", rec.error().c_str());
    std::exit(1);
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
      o.heard = true;
      o.hyp = r.hypothesis;
      o.command = r.command;
      o.speech_s = speech_s;
      o.decode_ms = r.decode_ms;
      o.margin = r.margin;
      // end of utterance (known from synthesis) -> trigger: VAD decision time + decode time.
      o.latency_ms = (double(best->decided) / kVoiceRate - it.speech_end) * 1000.0 + r.decode_ms;
    }
    out.push_back(o);
  }
  return out;
}

Score score(const std::vector<Item>& items, const std::vector<Outcome>& out, double max_s,
            double min_s, double margin) {
  Score sc;
  for (size_t i = 0; i < items.size(); ++i) {
    const auto& o = out[i];
    const bool accept =
        !o.command.empty() && o.speech_s <= max_s && o.speech_s >= min_s && o.margin >= -margin;
    if (items[i].expect == "-") {
      ++sc.non;
      sc.fa += accept;
    } else {
      ++sc.cmd;
      sc.ok += accept && o.command == items[i].expect;
    }
  }
  return sc;
}

std::vector<double> parse_list(const std::string& s) {
  std::vector<double> v;
  std::stringstream ss(s);
  for (std::string t; std::getline(ss, t, ',');) v.push_back(std::stod(t));
  return v;
}
}  // namespace

int main(int argc, char** argv) {
  bool tune = false;
  VoiceConfig cfg;
  std::vector<std::string> pos;
  std::vector<double> wips = {0.65, 1e-2, 1e-4, 1e-6};
  std::vector<int> minf;
  const std::vector<double> max_grid = {1.2, 1.5, 1.8, 2.2, 1e9};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--tune")
      tune = true;
    else if (a == "--phrases")
      cfg.phrases = next();
    else if (a == "--wip")
      cfg.word_penalty = std::stod(next());
    else if (a == "--single")
      cfg.rejection = Rejection::Single;
    else if (a == "--margin")
      cfg.filler_margin = std::stod(next());
    else if (a == "--min-fillers")
      cfg.min_filler_words = std::stoi(next());
    else if (a == "--min-fillers-grid")
      for (double m : parse_list(next())) minf.push_back(static_cast<int>(m));
    else if (a == "--wips")
      wips = parse_list(next());
    else if (a == "--max-s")
      cfg.max_command_s = std::stod(next());
    else
      pos.push_back(a);
  }
  if (pos.size() != 2) {
    std::fprintf(stderr,
                 "usage: voice_bench [--tune] list.tsv out [--phrases F] [--wip P] [--wips a,b] "
                 "[--margin M] [--single] [--max-s D]\n");
    return 2;
  }
  std::vector<Item> items;
  std::ifstream in(pos[0]);
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
  if (items.empty()) {
    std::fprintf(stderr, "%s: no utterances\n", pos[0].c_str());
    return 1;
  }

  if (tune) {
    std::printf("\nTUNING set (%zu utterances)\n%-10s %-10s %-8s %9s %9s\n", items.size(),
                "filler_w", "wip", "max_s", "accuracy", "false_tr");
    double best_acc = -1, best_wip = cfg.word_penalty, best_max = cfg.max_command_s;
    if (minf.empty()) minf.push_back(cfg.min_filler_words);
    double best_minf = cfg.min_filler_words, best_margin = 1e9;
    const std::vector<double> margin_grid =
        cfg.rejection == Rejection::Single ? std::vector<double>{1e9}
                                           : std::vector<double>{-30, -20, -15, -10, -7, -5, -3, 0};
    for (int mf : minf)
      for (double p : wips) {
        cfg.min_filler_words = mf;
        cfg.word_penalty = p;
        const auto out = decode_all(items, cfg);
        for (double mg : margin_grid)
          for (double mx : max_grid) {
            const Score sc = score(items, out, mx, cfg.min_command_s, mg);
            std::printf("min_fill %d  %-10g margin %-6g %-8g %8.1f%% %8.1f%%\n", mf, p, mg, mx,
                        100 * sc.acc(), 100 * sc.far());
            if (sc.far() <= 0.01 && sc.acc() > best_acc) {
              best_acc = sc.acc();
              best_wip = p;
              best_minf = mf;
              best_max = mx;
              best_margin = mg;
            }
          }
        for (size_t i = 0; i < items.size(); ++i)
          if (out[i].command != (items[i].expect == "-" ? "" : items[i].expect))
            std::printf("    minf=%d wip=%g %s: '%s' -> '%s' (%.2f s)\n", mf, p,
                        items[i].wav.c_str(), items[i].text.c_str(), out[i].hyp.c_str(),
                        out[i].speech_s);
        std::fflush(stdout);
      }
    std::printf(
        "chosen on the tuning set: min_filler_words %g, wip %g, margin %g, max_command_s %g "
        "(accuracy %.1f %%, false triggers <= 1 %%)\n",
        best_minf, best_wip, best_margin, best_max, 100 * best_acc);
    std::ofstream(pos[1]) << best_minf << " " << best_wip << " " << best_margin << " " << best_max
                          << "\n";
    return 0;
  }

  const auto out = decode_all(items, cfg);
  nlohmann::json j;
  std::printf(
      "\nTEST set: min_filler_words %d, wip %g, margin %g, max_command_s %g\n%-24s %9s %9s %8s "
      "%8s\n",
      cfg.min_filler_words, cfg.word_penalty, cfg.filler_margin, cfg.max_command_s, "rejection",
      "accuracy", "false_tr", "cmds", "non-cmd");
  const Score plain = score(items, out, 1e9, 0, 1e9);
  const Score durs = score(items, out, cfg.max_command_s, cfg.min_command_s, 1e9);
  const Score marg = score(items, out, 1e9, 0, cfg.filler_margin);
  const Score dur = score(items, out, cfg.max_command_s, cfg.min_command_s, cfg.filler_margin);
  for (const auto& [name, sc] : {std::pair<std::string, Score>{"grammar only", plain},
                                 std::pair<std::string, Score>{"duration", durs},
                                 std::pair<std::string, Score>{"filler margin", marg},
                                 std::pair<std::string, Score>{"margin+duration", dur}}) {
    std::printf("%-24s %8.1f%% %8.1f%% %8d %8d\n", name.c_str(), 100 * sc.acc(), 100 * sc.far(),
                sc.cmd, sc.non);
    j["methods"][name] = {{"accuracy", sc.acc()}, {"false_trigger_rate", sc.far()}};
  }
  j["accuracy"] = dur.acc();
  j["false_trigger_rate"] = dur.far();
  j["rejection"] =
      rejection_name(cfg.rejection == Rejection::Single ? Rejection::Single : Rejection::Combined);
  j["filler_margin"] = cfg.filler_margin;
  j["min_filler_words"] = cfg.min_filler_words;
  j["word_penalty"] = cfg.word_penalty;
  j["max_command_s"] = cfg.max_command_s;
  j["commands"] = dur.cmd;
  j["non_commands"] = dur.non;
  std::map<std::string, int> confusions;
  for (size_t i = 0; i < items.size(); ++i) {
    const bool accept = !out[i].command.empty() && out[i].speech_s <= cfg.max_command_s &&
                        out[i].speech_s >= cfg.min_command_s && out[i].margin >= -cfg.filler_margin;
    const std::string got = accept ? out[i].command : "(rejected)";
    if (got != (items[i].expect == "-" ? "(rejected)" : items[i].expect)) {
      ++confusions[items[i].expect + " -> " + got];
      std::printf("  error: %s '%s' -> hyp '%s' (%.2f s)\n", items[i].wav.c_str(),
                  items[i].text.c_str(), out[i].hyp.c_str(), out[i].speech_s);
    }
  }
  for (const auto& [k, v] : confusions) j["confusions"][k] = v;
  std::vector<double> lat;
  double dec = 0;
  for (size_t i = 0; i < items.size(); ++i)
    if (items[i].expect != "-" && out[i].heard) {
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
  for (size_t i = 0; i < items.size(); ++i)
    j["detail"].push_back({{"wav", items[i].wav},
                           {"expect", items[i].expect},
                           {"hyp", out[i].hyp},
                           {"speech_s", out[i].speech_s},
                           {"latency_ms", out[i].latency_ms}});
  std::printf(
      "\nlatency end of utterance -> trigger: median %.0f ms, p90 %.0f ms (hangover %.0f ms "
      "+ decode %.0f ms mean)\nutterances: %zu\n",
      med, p90, cfg.hangover_s * 1000, j["decode_ms_mean"].get<double>(), items.size());
  std::ofstream(pos[1]) << j.dump(2) << "\n";
  std::printf("wrote %s\n", pos[1].c_str());
  return 0;
}
