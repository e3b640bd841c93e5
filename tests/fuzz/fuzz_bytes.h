// Any bytes as a fuzz target's choices, and the exception that reports a broken promise.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <stdexcept>
#include <string>

#include "fluidcast/sim/particles.h"

namespace fluidcast::fuzzing {

// The input's bytes read front to back; past its end every read gives 0.
class Bytes {
 public:
  Bytes(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool done() const { return at_ >= size_; }
  std::uint8_t byte() { return at_ < size_ ? data_[at_++] : 0; }
  // In [0, 1].
  float unit() { return static_cast<float>(byte()) / 255.0f; }
  float between(double low, double high) {
    return static_cast<float>(low + (high - low) * static_cast<double>(unit()));
  }
  // Three of between(low, high), read x, y, z in that order (a function's arguments are read in
  // an order each compiler chooses: an input found under clang would mean another under GCC).
  glm::vec3 triple(double low, double high) {
    const float x = between(low, high);
    const float y = between(low, high);
    const float z = between(low, high);
    return {x, y, z};
  }
  // From `low` to `high` on a log scale: small values as often as large ones.
  float scaled(double low, double high) {
    return static_cast<float>(low * std::pow(high / low, static_cast<double>(unit())));
  }
  int up_to(int most) { return byte() % (most + 1); }
  // A length within `limit`, at it, an ulp past it or up to a quarter past it, and now and then
  // not a number at all.
  float around(float limit) {
    switch (byte() % 16) {
      case 0:
        return std::numeric_limits<float>::quiet_NaN();
      case 1:
        return std::numeric_limits<float>::infinity();
      case 2:
        return limit;
      case 3:
        return std::nextafter(limit, 2.0f * limit);
      case 4:
        return 0.0f;
      default:
        return static_cast<float>(limit * 1.25 * static_cast<double>(unit()));
    }
  }
  glm::vec3 direction() {
    const glm::vec3 d = triple(-1, 1);
    const float length = glm::length(d);
    return length > 1e-3f ? d / length : glm::vec3(0.0f, -1.0f, 0.0f);
  }
  // A point in the box grown by a quarter of its size each way: some outside it.
  glm::vec3 point_around(const sim::Box& box) {
    const glm::vec3 size = box.max - box.min;
    return box.min - 0.25f * size + 1.5f * size * triple(0, 1);
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

// A run that broke a promise of the code under test.
struct Defect : std::logic_error {
  using std::logic_error::logic_error;
};

[[noreturn]] inline void defect(const std::string& what) { throw Defect(what); }

}  // namespace fluidcast::fuzzing
