// The pairing key of the UDP skeleton stream on the executable's side (docs/tracking.md): where
// the key file lives by default (the user's config folder, from the environment, which only the
// executable reads) and --hands-key of `drape run` / `drape xr`. Defined in cmd_hands.cpp, whose
// `drape hands pair` writes that file.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace CLI {
class App;
}  // namespace CLI

namespace drape::app {

// $XDG_CONFIG_HOME/drape/hands.key, else $HOME/.config/drape/hands.key ("" when neither is set).
std::string default_hands_key_path();

// --hands-key FILE (the pairing key for --hands udp).
void add_hands_key_option(CLI::App& cli, std::string& key_file);

// After parsing, with `udp` true when --hands is udp (bound to `address`): `key` from --hands-key
// (`given`) or, when not given, the default key file when it exists (a key authenticates the
// stream on any address, loopback included). Without a key a non-loopback address is refused
// with how to pair. --hands-key without --hands udp, or a key file that does not load, is
// refused too. A refusal prints "<command>: --hands-key: ..." and returns false (exit 2).
bool resolve_hands_key(const char* command, bool udp, const std::string& given,
                       const std::string& address, std::vector<uint8_t>& key);

}  // namespace drape::app
