// Fuzz target: any bytes as the headless client's gesture script (JSON). A std::runtime_error
// naming what is wrong is the answer to a bad script; anything else escaping is a defect.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "gesture_script.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    fluidcast::client::parse_gesture_script(std::string(reinterpret_cast<const char*>(data), size),
                                            "fuzz");
  } catch (const std::runtime_error&) {
  }
  return 0;
}
