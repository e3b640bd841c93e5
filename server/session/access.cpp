#include "access.h"

#include <sys/random.h>

#include <array>
#include <cerrno>
#include <cstdint>
#include <system_error>

namespace fluidcast::server {

std::string new_key() {
  std::array<std::uint8_t, 16> bytes;
  std::size_t filled = 0;
  while (filled < bytes.size()) {
    const ssize_t got = getrandom(bytes.data() + filled, bytes.size() - filled, 0);
    if (got < 0) {
      if (errno == EINTR) continue;
      throw std::system_error(errno, std::generic_category(), "getrandom");
    }
    filled += static_cast<std::size_t>(got);
  }
  std::string key(2 * bytes.size(), '0');
  static constexpr char kDigits[] = "0123456789abcdef";
  for (std::size_t k = 0; k < bytes.size(); ++k) {
    key[2 * k] = kDigits[bytes[k] >> 4];
    key[2 * k + 1] = kDigits[bytes[k] & 15];
  }
  return key;
}

bool same_key(const std::string& given, const std::string& key) {
  // Every key has the same length, so the length tells nothing.
  if (given.size() != key.size()) return false;
  unsigned char differ = 0;
  for (std::size_t k = 0; k < key.size(); ++k) {
    differ |= static_cast<unsigned char>(given[k] ^ key[k]);
  }
  return differ == 0;
}

std::optional<Access> SessionKeys::opens(const std::string& given) const {
  // Both compared, whichever matches: the time is the same for either key and for none.
  const bool viewing = same_key(given, view);
  const bool controlling = same_key(given, control);
  if (controlling) return Access::control;
  if (viewing) return Access::view;
  return std::nullopt;
}

}  // namespace fluidcast::server
