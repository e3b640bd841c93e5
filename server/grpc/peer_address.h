// The client's address in a gRPC peer string ("ipv4:10.0.0.7:51234", "ipv6:[::1]:51234", or
// percent-encoded "ipv6:%5B::1%5D:51234"): what per-address limits count, without the port. An
// IPv4 client of a dual-stack port ("::ffff:10.0.0.7") as plain IPv4, as the WebSocket side
// counts it: the same client either way.
#pragma once

#include <string>
#include <string_view>

namespace fluidcast::server {

std::string peer_address(std::string_view peer);

}  // namespace fluidcast::server
