// The draping session's voice input: the scenario's audio cues (the simulated runtime's voice
// side channel, docs/xr.md), each decoded by the voice recogniser when its frame is reached, and
// the live input (the microphone or a recording, voice_input.hpp), polled every frame. Both give
// voice triggers of the right hand, like the gestures' and buttons' through the command map.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "xr_app/app/draping_session.hpp"

namespace drape::app {

namespace {
// The phrase the panel shows: what the decoder heard, or a mark when it heard no word at all.
std::string shown_phrase(const tracking::VoiceResult& vr) {
  return vr.hypothesis.empty() ? "(no words)" : vr.hypothesis;
}
}  // namespace

void DrapingSession::load_cues() {
  if (!opt_.voice_input.empty()) {
    // --record: the audio as captured into audio.wav (a resumed session's into a file of its own).
    const std::string tee = opt_.record_dir.empty()   ? ""
                            : opt_.resume_dir.empty() ? opt_.record_dir + "/audio.wav"
                                                      : opt_.record_dir + "/audio_resumed.wav";
    if (!tee.empty()) {
      std::error_code ec;
      std::filesystem::create_directories(opt_.record_dir, ec);
    }
    live_voice_ = std::make_unique<VoiceInput>(opt_.voice_input, tee);
    rep_.note("voice: live input: " + live_voice_->name());
    if (!live_voice_->tee_error().empty()) rep_.note("record: " + live_voice_->tee_error());
  }
  if (!opt_.voice || opt_.scenario_path.empty()) return;
  std::ifstream in(opt_.scenario_path);
  if (!in) return;  // the runtime reports an unreadable scenario itself
  nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.contains("audio") || !j["audio"].is_array()) return;
  const std::filesystem::path dir = std::filesystem::path(opt_.scenario_path).parent_path();
  for (const auto& a : j["audio"]) {
    if (!a.is_object() || !a.contains("frame") || !a.contains("wav")) continue;
    Cue c;
    c.frame = a["frame"].get<int64_t>();
    std::filesystem::path wav = a["wav"].get<std::string>();
    c.wav = (wav.is_absolute() ? wav : dir / wav).string();
    if (a.contains("text") && a["text"].is_string()) c.text = a["text"].get<std::string>();
    cues_.push_back(c);
  }
  if (!cues_.empty()) rep_.note("voice: " + std::to_string(cues_.size()) + " audio cue(s)");
}

void DrapingSession::hear_cues(int64_t frame, double t, std::vector<tracking::Trigger>& trig) {
  if (live_voice_) hear_live_voice(frame, t, trig);
  for (auto& c : cues_) {
    if (c.done || frame < c.frame) continue;
    c.done = true;
    if (!voice_) {
      voice_ = std::make_unique<tracking::VoiceRecognizer>(tracking::VoiceConfig{});
      if (!voice_->ok()) rep_.note("voice: recogniser unavailable: " + voice_->error());
    }
    std::vector<int16_t> pcm;
    std::string err;
    if (!voice_->ok()) continue;
    if (!tracking::read_wav(c.wav, pcm, &err)) {
      rep_.note("voice: " + err);
      continue;
    }
    // The recogniser's own energy VAD cuts the utterance out of the recording.
    tracking::EnergyVad vad(voice_->config());
    std::vector<tracking::EnergyVad::Segment> segs;
    vad.feed(pcm.data(), static_cast<long>(pcm.size()), segs);
    vad.flush(segs);
    if (segs.empty()) {
      rep_.note("voice: no speech in " + c.wav);
      continue;
    }
    const auto& sg = segs.front();
    auto vr = voice_->decode(sg.audio.data(), static_cast<long>(sg.audio.size()),
                             static_cast<double>(sg.speech_end - sg.start) / tracking::kVoiceRate);
    rep_.note("voice: frame " + std::to_string(frame) + " '" + c.wav + "' heard '" + vr.hypothesis +
              "' -> " + (vr.command.empty() ? "(rejected: " + vr.reason + ")" : vr.command));
    feedback_.heard(frame, shown_phrase(vr), vr.command);
    if (!vr.command.empty()) {
      rep_.r.voice_commands.push_back(vr.command);
      trig.push_back({vr.command, "voice", t, tracking::Hand::Right, true});
    }
  }
}

// The live input's utterances decoded since the last frame -> voice triggers (right hand), the
// panel's "heard" line and the log; its failures (no microphone, a device error, a malformed
// recording) -> the panel's "voice" status and the log, while the session goes on.
void DrapingSession::hear_live_voice(int64_t frame, double t,
                                     std::vector<tracking::Trigger>& trig) {
  if (auto status = live_voice_->status_change()) {
    feedback_.set_status("voice", *status);
    rep_.note("voice: " + (status->empty() ? "listening to " + live_voice_->name() : *status));
  }
  for (const VoiceInput::Heard& h : live_voice_->poll(frame)) {
    const tracking::VoiceResult& vr = h.result;
    char lat[128];
    std::snprintf(
        lat, sizeof lat,
        " (speech ended in frame %lld: %d frames, %.0f ms; VAD hangover and decoding %.0f "
        "ms)",
        static_cast<long long>(h.speech_end_frame), h.latency_frames, h.latency_ms,
        h.vad_decode_ms);
    rep_.note("voice: frame " + std::to_string(frame) + " heard '" + vr.hypothesis + "' -> " +
              (vr.command.empty() ? "(rejected: " + vr.reason + ")" : vr.command) + lat);
    feedback_.heard(frame, shown_phrase(vr), vr.command);
    if (h.latency_frames >= 0) rep_.r.voice_latency_frames.push_back(h.latency_frames);
    if (vr.command.empty()) continue;
    rep_.r.voice_commands.push_back(vr.command);
    trig.push_back({vr.command, "voice", t, tracking::Hand::Right, true});
  }
}

}  // namespace drape::app
