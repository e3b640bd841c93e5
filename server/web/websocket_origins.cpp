#include "websocket_origins.h"

#include <arpa/inet.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>

namespace fluidcast::server {
namespace {

std::string lowercase(std::string_view text) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return lower;
}

bool same_text(std::string_view a, std::string_view b) { return lowercase(a) == lowercase(b); }

bool ends_with(std::string_view text, std::string_view end) {
  return text.size() > end.size() && text.substr(text.size() - end.size()) == end;
}

// A Host header's name, without its port and a DNS root's trailing dot, lowercase; an IPv6
// address without its brackets.
std::string name_of(std::string_view host) {
  if (host.starts_with('[')) {
    const auto close = host.find(']');
    return lowercase(host.substr(1, close == std::string_view::npos ? host.npos : close - 1));
  }
  if (const auto colon = host.rfind(':'); colon != std::string_view::npos) {
    host = host.substr(0, colon);
  }
  if (host.ends_with('.')) host.remove_suffix(1);
  return lowercase(host);
}

// Domains home routers give their network's machines (mybox.lan, mybox.fritz.box), which no one
// can register.
constexpr const char* kHomeDomains[] = {".lan", ".home", ".home.arpa", ".internal", ".localdomain",
                                        ".fritz.box"};

bool ip_address(const std::string& name) {
  std::array<unsigned char, 16> address{};
  return inet_pton(AF_INET, name.c_str(), address.data()) == 1 ||
         inet_pton(AF_INET6, name.c_str(), address.data()) == 1;
}

}  // namespace

WebSocketOrigins::WebSocketOrigins(std::vector<std::string> allowed_origins,
                                   std::vector<std::string> server_names, std::string machine_name)
    : allowed_origins_(std::move(allowed_origins)), machine_name_(lowercase(machine_name)) {
  for (const std::string& name : server_names) server_names_.push_back(name_of(name));
}

bool WebSocketOrigins::known_name(std::string_view name) const {
  const std::string given(name);
  if (ip_address(given) || given == "localhost" || ends_with(given, ".localhost") ||
      ends_with(given, ".local")) {
    return true;
  }
  if (std::find(server_names_.begin(), server_names_.end(), given) != server_names_.end()) {
    return true;
  }
  // The machine's name as it has it (a full one, gpu01.corp.example, too), its first label, and
  // that label under a home network's own domains; not under any domain, which anyone can buy
  // (mybox.attacker.example).
  if (machine_name_.empty()) return false;
  const std::string label = machine_name_.substr(0, machine_name_.find('.'));
  if (given == machine_name_ || given == label) return true;
  for (const char* domain : kHomeDomains) {
    if (given == label + domain) return true;
  }
  return false;
}

std::optional<std::string> WebSocketOrigins::refusal(std::optional<std::string_view> origin,
                                                     std::string_view host) const {
  if (!origin) return std::nullopt;
  // A site the operator allowed may, under whatever name (a proxy may pass its Host on).
  const bool allowed =
      std::any_of(allowed_origins_.begin(), allowed_origins_.end(),
                  [&](const std::string& other) { return same_text(other, *origin); });
  if (allowed) return std::nullopt;
  const auto scheme_end = origin->find("://");
  const std::string_view authority =
      scheme_end == std::string_view::npos ? *origin : origin->substr(scheme_end + 3);
  if (same_text(authority, host)) {
    const std::string name = name_of(host);
    if (known_name(name)) return std::nullopt;
    return "a page reached as " + name + " may not open the WebSocket: the server's own page is "
           "one reached by an IP address, localhost, a .local name or this machine's name, and "
           "another site whose name was pointed at this machine would look the same; if the "
           "server is " + name + ", start it with --server-name " + name;
  }
  return "a page from " + std::string(*origin) +
         " may not open the WebSocket; to let that site's pages drive this server, start it with "
         "--allow-origin " + std::string(*origin);
}

std::string this_machine_name() {
  std::array<char, 256> name{};
  if (gethostname(name.data(), name.size() - 1) != 0) return "";
  return lowercase(name.data());
}

}  // namespace fluidcast::server
