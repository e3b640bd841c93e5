// Which pages may open the WebSocket: the server's own (reached by a name it is known by), other
// sites' pages the operator allowed, and clients that are not browsers; not a site whose name was
// pointed at the server after its page loaded (DNS rebinding).
#include "web/websocket_origins.h"

#include <gtest/gtest.h>

namespace fluidcast::server {
namespace {

const WebSocketOrigins origins({"https://friend.example"}, {"fluid.example.org"}, "mybox");

bool opens(std::string_view origin, std::string_view host) {
  return !origins.refusal(origin, host).has_value();
}

TEST(WebSocketOrigins, TheServersOwnPageByAnyNameItIsKnownBy) {
  EXPECT_TRUE(opens("http://192.168.1.5:8080", "192.168.1.5:8080"));
  EXPECT_TRUE(opens("https://[fe80::1]:8080", "[fe80::1]:8080"));
  EXPECT_TRUE(opens("http://127.0.0.1:8080", "127.0.0.1:8080"));
  EXPECT_TRUE(opens("http://localhost:8080", "localhost:8080"));
  EXPECT_TRUE(opens("http://fluid.localhost:8080", "fluid.localhost:8080"));
  EXPECT_TRUE(opens("https://mybox.local:8080", "mybox.local:8080"));
  EXPECT_TRUE(opens("http://mybox:8080", "mybox:8080"));
  EXPECT_TRUE(opens("http://MyBox.lan:8080", "mybox.lan:8080"));
  EXPECT_TRUE(opens("http://mybox.fritz.box:8080", "mybox.fritz.box:8080"));
  const WebSocketOrigins full({}, {}, "gpu01.corp.example");
  EXPECT_FALSE(full.refusal("http://gpu01.corp.example:8080", "gpu01.corp.example:8080"));
  EXPECT_FALSE(full.refusal("http://gpu01:8080", "gpu01:8080"));
  EXPECT_FALSE(full.refusal("http://gpu01.home.arpa:8080", "gpu01.home.arpa:8080"));
  EXPECT_TRUE(opens("https://fluid.example.org", "fluid.example.org"));
  EXPECT_TRUE(opens("https://fluid.example.org.", "fluid.example.org."));
}

TEST(WebSocketOrigins, ClientsThatAreNotBrowsersAndAllowedSites) {
  EXPECT_FALSE(origins.refusal(std::nullopt, "evil.example:8080"));
  EXPECT_TRUE(opens("https://friend.example", "192.168.1.5:8080"));
  EXPECT_TRUE(opens("https://friend.example", "friend.example"));  // its Host passed on by a proxy
  const auto refused = origins.refusal("http://evil.example", "192.168.1.5:8080");
  ASSERT_TRUE(refused);
  EXPECT_NE(refused->find("--allow-origin http://evil.example"), std::string::npos) << *refused;
}

// A rebinding site's page sends its own name as both Origin and Host.
TEST(WebSocketOrigins, ASiteWhoseNameWasPointedHereIsRefused) {
  for (const char* host : {"evil.example:8080", "evil.example", "notmybox.lan:8080",
                           "mybox.evil.example:8080", "mybox.lan.evil.example:8080",
                           "192.168.1.5.evil.example:8080", "local:8080"}) {
    const auto refused = origins.refusal("http://" + std::string(host), host);
    ASSERT_TRUE(refused) << host;
    EXPECT_NE(refused->find("--server-name"), std::string::npos) << *refused;
  }
  const WebSocketOrigins nameless({}, {}, "");
  EXPECT_TRUE(nameless.refusal("http://anything:8080", "anything:8080"));
}

}  // namespace
}  // namespace fluidcast::server
