// The page's self-signed certificate in the state folder: servers sharing the folder (one per GPU,
// started together) serve one certificate, made once.
#include "web/tls_certificate.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace fluidcast::server {
namespace {

std::string contents(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(TlsCertificateTest, ServersStartingTogetherServeOneCertificate) {
  std::string folder = (std::filesystem::temp_directory_path() / "fluidcast-tls-XXXXXX").string();
  ASSERT_TRUE(mkdtemp(folder.data()));
  constexpr int kServers = 4;
  std::vector<std::string> served(kServers);
  std::vector<std::thread> servers;
  for (int k = 0; k < kServers; ++k) {
    servers.emplace_back([&, k] {
      // As a server does: the files, then what they hold at once.
      const TlsFiles files = self_signed_certificate(folder, {"192.0.2.7"});
      served[k] = contents(files.certificate);
    });
  }
  for (auto& server : servers) server.join();
  for (int k = 0; k < kServers; ++k) {
    EXPECT_NE(served[k].find("BEGIN CERTIFICATE"), std::string::npos);
    EXPECT_EQ(served[k], served[0]) << "server " << k << " serves another certificate";
  }
  // A later start with the same addresses keeps it.
  EXPECT_EQ(contents(self_signed_certificate(folder, {"192.0.2.7"}).certificate), served[0]);
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace fluidcast::server
