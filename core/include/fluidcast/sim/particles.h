// Particle state as structure-of-arrays, and the axis-aligned box the fluid lives in.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

namespace fluidcast::sim {

// The most particles a scene, a solver and so a session hold: every flag and field that asks for
// a count keeps within it.
inline constexpr std::uint32_t kMostParticles = 1u << 24;

struct Box {
  glm::vec3 min{0.0f};
  glm::vec3 max{0.0f};
  glm::vec3 size() const { return max - min; }
  bool contains(glm::vec3 p) const {
    return p.x >= min.x && p.y >= min.y && p.z >= min.z && p.x <= max.x && p.y <= max.y &&
           p.z <= max.z;
  }
};

inline bool is_finite(glm::vec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Everything that survives a step. `id` follows a particle through every reordering.
struct ParticleSet {
  std::vector<glm::vec3> position;  // m
  std::vector<glm::vec3> velocity;  // m/s
  std::vector<std::uint32_t> id;

  std::size_t size() const { return position.size(); }
  void append(glm::vec3 p, glm::vec3 v, std::uint32_t particle_id) {
    position.push_back(p);
    velocity.push_back(v);
    id.push_back(particle_id);
  }
};

}  // namespace fluidcast::sim
