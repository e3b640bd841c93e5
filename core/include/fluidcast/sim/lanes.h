// Four floats processed as one, for the CPU solvers' inner loops over neighbours: GCC's and
// Clang's vector extensions, which compile to SSE on x86 and to SIMD128 in the page's WebAssembly.
// The scalar overloads let one formula (Kernels) serve a single pair and a block of four.
// FLUIDCAST_LANES_GENERIC selects the portable path (any other target's) on x86 and in
// WebAssembly too, so that the tests run it.
#pragma once

#include <cmath>
#include <concepts>
#include <cstdint>
#include <cstring>
#include <glm/glm.hpp>
#if defined(__SSE__) && !defined(FLUIDCAST_LANES_GENERIC)
#define FLUIDCAST_LANES_SSE
#include <xmmintrin.h>
#elif defined(__wasm_simd128__) && !defined(FLUIDCAST_LANES_GENERIC)
#define FLUIDCAST_LANES_SIMD128
#include <wasm_simd128.h>
#endif

namespace fluidcast::sim::lanes {

inline constexpr std::uint32_t kWidth = 4;

using Floats = float __attribute__((vector_size(16)));
using Ints = decltype(Floats{} < Floats{});  // a comparison's lanes: −1 or 0

// One pair (float) or four (Floats): what the kernels accept.
template <class F>
concept OneOrFour = std::same_as<F, float> || std::same_as<F, Floats>;

inline constexpr Ints kLaneIndex = {0, 1, 2, 3};

inline Floats load(const float* from) {
  Floats v;
  std::memcpy(&v, from, sizeof v);
  return v;
}

// Bit b set where lane b of a comparison is true.
inline unsigned mask(Ints condition) {
#if defined(FLUIDCAST_LANES_SSE)
  return static_cast<unsigned>(_mm_movemask_ps(reinterpret_cast<__m128>(condition)));
#elif defined(FLUIDCAST_LANES_SIMD128)
  return static_cast<unsigned>(wasm_i32x4_bitmask(reinterpret_cast<v128_t>(condition)));
#else
  return static_cast<unsigned>((condition[0] & 1) | (condition[1] & 2) | (condition[2] & 4) |
                               (condition[3] & 8));
#endif
}

inline float select(bool condition, float if_true, float if_false) {
  return condition ? if_true : if_false;
}
inline Floats select(Ints condition, Floats if_true, Floats if_false) {
  const Ints chosen = (condition & reinterpret_cast<Ints>(if_true)) |
                      (~condition & reinterpret_cast<Ints>(if_false));
  return reinterpret_cast<Floats>(chosen);
}

inline float sum(Floats v) { return (v[0] + v[1]) + (v[2] + v[3]); }

// Four 3-vectors, one per lane.
struct Vec3 {
  Floats x, y, z;
};
inline Vec3 operator-(glm::vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator-(Vec3 a, glm::vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator*(Floats s, Vec3 v) { return {s * v.x, s * v.y, s * v.z}; }
inline Floats dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline Vec3& operator+=(Vec3& a, Vec3 b) {
  a.x += b.x;
  a.y += b.y;
  a.z += b.z;
  return a;
}
inline glm::vec3 select(bool condition, glm::vec3 if_true, glm::vec3 if_false) {
  return condition ? if_true : if_false;
}
inline Vec3 select(Ints condition, Vec3 if_true, Vec3 if_false) {
  return {select(condition, if_true.x, if_false.x), select(condition, if_true.y, if_false.y),
          select(condition, if_true.z, if_false.z)};
}
// The sum over the lanes.
inline glm::vec3 sum(Vec3 v) { return {sum(v.x), sum(v.y), sum(v.z)}; }

// data[index[lane]] in each lane.
inline Floats gather(const float* data, const std::uint32_t* index) {
  return Floats{data[index[0]], data[index[1]], data[index[2]], data[index[3]]};
}
inline Vec3 gather(const glm::vec3* data, const std::uint32_t* index) {
  const glm::vec3 &a = data[index[0]], &b = data[index[1]], &c = data[index[2]],
                  &d = data[index[3]];
  return {Floats{a.x, b.x, c.x, d.x}, Floats{a.y, b.y, c.y, d.y}, Floats{a.z, b.z, c.z, d.z}};
}

inline Floats sqrt(Floats x) {
#if defined(FLUIDCAST_LANES_SSE)
  return reinterpret_cast<Floats>(_mm_sqrt_ps(reinterpret_cast<__m128>(x)));
#elif defined(FLUIDCAST_LANES_SIMD128)
  return reinterpret_cast<Floats>(wasm_f32x4_sqrt(reinterpret_cast<v128_t>(x)));
#else
  Floats result{};
  for (std::uint32_t lane = 0; lane < kWidth; ++lane) result[lane] = std::sqrt(x[lane]);
  return result;
#endif
}

// 1/√x to about 1e-7 relative: the hardware estimate and one Newton step, several times faster than
// sqrt followed by a division. x must be positive and finite for a finite result.
inline float inverse_sqrt(float x) {
#if defined(FLUIDCAST_LANES_SSE)
  const float estimate = _mm_cvtss_f32(_mm_rsqrt_ss(_mm_set_ss(x)));
  return estimate * (1.5f - 0.5f * x * estimate * estimate);
#else
  return 1.0f / std::sqrt(x);
#endif
}
inline Floats inverse_sqrt(Floats x) {
#if defined(FLUIDCAST_LANES_SSE)
  const Floats estimate = reinterpret_cast<Floats>(_mm_rsqrt_ps(reinterpret_cast<__m128>(x)));
  return estimate * (1.5f - 0.5f * x * estimate * estimate);
#else
  return 1.0f / sqrt(x);
#endif
}

}  // namespace fluidcast::sim::lanes
