#include "peer_address.h"

namespace fluidcast::server {

std::string peer_address(std::string_view peer) {
  const auto scheme = peer.find(':');
  if (scheme == std::string_view::npos) return std::string(peer);
  std::string_view rest = peer.substr(scheme + 1);
  for (const auto& [open, close] : {std::pair{"[", "]"}, std::pair{"%5B", "%5D"}}) {
    if (rest.rfind(open, 0) == 0) {
      const auto end = rest.find(close);
      if (end != std::string_view::npos) {
        std::string_view address =
            rest.substr(std::string_view(open).size(), end - std::string_view(open).size());
        constexpr std::string_view kMappedIpv4 = "::ffff:";
        if (address.substr(0, kMappedIpv4.size()) == kMappedIpv4 &&
            address.find('.') != std::string_view::npos) {
          address.remove_prefix(kMappedIpv4.size());
        }
        return std::string(address);
      }
    }
  }
  if (peer.substr(0, scheme) != "ipv4") return std::string(peer);  // unix sockets and the like
  return std::string(rest.substr(0, rest.rfind(':')));
}

}  // namespace fluidcast::server
