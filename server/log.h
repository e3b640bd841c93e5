// The server's log: one line per event on stdout, with its time and level, as text or as JSON (an
// object a line, for a log shipper). Events are logged with spdlog's functions (spdlog::info, ...)
// anywhere in the server once configure_log has run.
#pragma once

#include <string>

namespace fluidcast::server {

enum class LogFormat { text, json };

// Throws std::invalid_argument for a name that is not "text" or "json".
LogFormat parse_log_format(const std::string& name);
void configure_log(LogFormat format);

}  // namespace fluidcast::server
