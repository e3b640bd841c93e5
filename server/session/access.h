// Who may do what in a session: its keys, random secrets told only in Welcome.access (the model is
// documented at the top of proto/fluidcast/v1/fluidcast.proto). Ids name; keys open.
#pragma once

#include <optional>
#include <string>

namespace fluidcast::server {

enum class Access { view, control };

// 128 random bits from the kernel's generator, as 32 lowercase hex digits.
std::string new_key();

// Compares in time that does not depend on where the two differ, so that timing a refused key
// tells nothing about the right one.
bool same_key(const std::string& given, const std::string& key);

struct SessionKeys {
  std::string view = new_key();
  std::string control = new_key();

  // What `given` opens in this session, if anything.
  std::optional<Access> opens(const std::string& given) const;
};

}  // namespace fluidcast::server
