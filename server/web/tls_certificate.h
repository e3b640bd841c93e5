// The page's HTTPS without a step from the operator: browsers give motion sensors (tilt), wake
// locks and the like only to secure pages, and a phone reaches the server by a LAN address. With
// no certificate given, the server makes a self-signed one for its addresses, kept in its state
// folder and made again when an address is new.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace fluidcast::server {

struct TlsFiles {
  std::filesystem::path certificate, key;  // PEM
};

// The certificate and key in `folder` (made with its parents when missing), valid for localhost,
// 127.0.0.1 and every address in `addresses`. Throws std::runtime_error naming the folder or the
// file that cannot be written or read.
TlsFiles self_signed_certificate(const std::filesystem::path& folder,
                                 const std::vector<std::string>& addresses);

// Where the server keeps what it makes: $STATE_DIRECTORY (systemd), else
// $XDG_STATE_HOME/fluidcast, else ~/.local/state/fluidcast.
std::filesystem::path default_state_folder();

}  // namespace fluidcast::server
