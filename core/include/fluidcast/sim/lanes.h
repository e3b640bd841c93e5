// A block of floats processed as one, for the CPU solvers' inner loops over neighbours: GCC's and
// Clang's vector extensions, which compile to AVX (eight lanes) or SSE (four) on x86 and to
// SIMD128 (four) in the page's WebAssembly. The scalar overloads let one formula (Kernels) serve a
// single pair and a block.
// FLUIDCAST_LANES_GENERIC selects the portable path (any other target's: four lanes) on x86 and in
// WebAssembly too, so that the tests run it.
#pragma once

#include <cmath>
#include <concepts>
#include <cstdint>
#include <cstring>
#include <glm/glm.hpp>
#include <utility>
#if defined(__AVX__) && !defined(FLUIDCAST_LANES_GENERIC)
#define FLUIDCAST_LANES_AVX
#include <immintrin.h>
#elif defined(__SSE__) && !defined(FLUIDCAST_LANES_GENERIC)
#define FLUIDCAST_LANES_SSE
#include <xmmintrin.h>
#elif defined(__wasm_simd128__) && !defined(FLUIDCAST_LANES_GENERIC)
#define FLUIDCAST_LANES_SIMD128
#include <wasm_simd128.h>
#endif

namespace fluidcast::sim::lanes {

// The block's lanes are an inline namespace of their own: a program whose parts were built for
// different widths (a test of the portable path beside the library) cannot mix up their functions.
#if defined(FLUIDCAST_LANES_AVX)
inline namespace eight {
inline constexpr std::uint32_t kWidth = 8;
#else
inline namespace four {
inline constexpr std::uint32_t kWidth = 4;
#endif

using Floats = float __attribute__((vector_size(4 * kWidth)));
using Ints = decltype(Floats{} < Floats{});  // a comparison's lanes: −1 or 0

// One pair (float) or a block (Floats): what the kernels accept.
template <class F>
concept OneOrBlock = std::same_as<F, float> || std::same_as<F, Floats>;

namespace detail {
template <std::size_t... Lane>
constexpr Ints lane_index(std::index_sequence<Lane...>) {
  return Ints{static_cast<std::int32_t>(Lane)...};
}
}  // namespace detail
inline constexpr Ints kLaneIndex = detail::lane_index(std::make_index_sequence<kWidth>{});

inline Floats load(const float* from) {
  Floats v;
  std::memcpy(&v, from, sizeof v);
  return v;
}

// Bit b set where lane b of a comparison is true.
inline unsigned mask(Ints condition) {
#if defined(FLUIDCAST_LANES_AVX)
  return static_cast<unsigned>(_mm256_movemask_ps(reinterpret_cast<__m256>(condition)));
#elif defined(FLUIDCAST_LANES_SSE)
  return static_cast<unsigned>(_mm_movemask_ps(reinterpret_cast<__m128>(condition)));
#elif defined(FLUIDCAST_LANES_SIMD128)
  return static_cast<unsigned>(wasm_i32x4_bitmask(reinterpret_cast<v128_t>(condition)));
#else
  unsigned bits = 0;
  for (std::uint32_t lane = 0; lane < kWidth; ++lane) bits |= (condition[lane] & 1u) << lane;
  return bits;
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

inline float sum(Floats v) {
#if defined(FLUIDCAST_LANES_AVX)
  return ((v[0] + v[1]) + (v[2] + v[3])) + ((v[4] + v[5]) + (v[6] + v[7]));
#else
  return (v[0] + v[1]) + (v[2] + v[3]);
#endif
}

// A 3-vector per lane.
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
namespace detail {
template <std::size_t... Lane>
Floats gather(const float* data, const std::uint32_t* index, std::index_sequence<Lane...>) {
  return Floats{data[index[Lane]]...};
}
template <std::size_t... Lane>
Vec3 gather(const glm::vec3* data, const std::uint32_t* index, std::index_sequence<Lane...>) {
  return {Floats{data[index[Lane]].x...}, Floats{data[index[Lane]].y...},
          Floats{data[index[Lane]].z...}};
}
}  // namespace detail
inline Floats gather(const float* data, const std::uint32_t* index) {
  return detail::gather(data, index, std::make_index_sequence<kWidth>{});
}
inline Vec3 gather(const glm::vec3* data, const std::uint32_t* index) {
  return detail::gather(data, index, std::make_index_sequence<kWidth>{});
}

inline Floats sqrt(Floats x) {
#if defined(FLUIDCAST_LANES_AVX)
  return reinterpret_cast<Floats>(_mm256_sqrt_ps(reinterpret_cast<__m256>(x)));
#elif defined(FLUIDCAST_LANES_SSE)
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
#if defined(FLUIDCAST_LANES_SSE) || defined(FLUIDCAST_LANES_AVX)
  const float estimate = _mm_cvtss_f32(_mm_rsqrt_ss(_mm_set_ss(x)));
  return estimate * (1.5f - 0.5f * x * estimate * estimate);
#else
  return 1.0f / std::sqrt(x);
#endif
}
inline Floats inverse_sqrt(Floats x) {
#if defined(FLUIDCAST_LANES_AVX)
  const Floats estimate = reinterpret_cast<Floats>(_mm256_rsqrt_ps(reinterpret_cast<__m256>(x)));
  return estimate * (1.5f - 0.5f * x * estimate * estimate);
#elif defined(FLUIDCAST_LANES_SSE)
  const Floats estimate = reinterpret_cast<Floats>(_mm_rsqrt_ps(reinterpret_cast<__m128>(x)));
  return estimate * (1.5f - 0.5f * x * estimate * estimate);
#else
  return 1.0f / sqrt(x);
#endif
}

}  // namespace eight or four
}  // namespace fluidcast::sim::lanes
