// Which browsers' pages may open the WebSocket (/ws). A browser sends the site of the page that
// opens it as Origin; the server's own page, fetched from whatever name the browser reached it
// by, has that name and port, the request's Host, as its Origin. So has a page of any site whose
// name its owner pointed at this machine after the page loaded (DNS rebinding): equal Origin and
// Host are the server's own page only where the Host is a name the server is known by. Clients
// that are not browsers send no Origin and are served.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fluidcast::server {

class WebSocketOrigins {
 public:
  // `allowed_origins`: other sites' pages that may open it (--allow-origin, scheme://host[:port]).
  // `server_names`: names it is known by besides those every server is (--server-name): an IP
  // address, localhost and names under .localhost, names under .local (mDNS), and
  // `machine_name` (and its first label, alone or under a home router's domain: mybox.lan,
  // mybox.fritz.box, mybox.home.arpa).
  WebSocketOrigins(std::vector<std::string> allowed_origins, std::vector<std::string> server_names,
                   std::string machine_name);

  // Why a request whose Origin is `origin` (none: not a browser) and Host `host` may not open the
  // WebSocket, in a sentence for the operator naming the flag that would let it; nothing when it
  // may.
  std::optional<std::string> refusal(std::optional<std::string_view> origin,
                                     std::string_view host) const;

 private:
  bool known_name(std::string_view name) const;

  std::vector<std::string> allowed_origins_;
  std::vector<std::string> server_names_;
  std::string machine_name_;
};

// This machine's name (gethostname), lowercase; empty when it has none.
std::string this_machine_name();

}  // namespace fluidcast::server
