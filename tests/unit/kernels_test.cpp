#include "fluidcast/sim/kernels.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>

namespace fluidcast::sim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr float kH = 0.05f;

// ∫ 4π r² f(r) dr over [0, h], midpoint rule.
template <class F>
double radial_integral(F f, double h, int n = 20000) {
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    const double r = (k + 0.5) * h / n;
    sum += 4.0 * kPi * r * r * f(r);
  }
  return sum * h / n;
}

// Müller 2003's viscosity kernel itself; only its Laplacian is in Kernels.
double viscosity_kernel(double r, double h) {
  if (r >= h) return 0.0;
  return 15.0 / (2.0 * kPi * h * h * h) *
         (-r * r * r / (2 * h * h * h) + r * r / (h * h) + h / (2 * r) - 1.0);
}

TEST(Kernels, Poly6IntegratesToOne) {
  const Kernels k(kH);
  EXPECT_NEAR(radial_integral([&](double r) { return k.poly6(float(r * r)); }, kH), 1.0, 1e-4);
}

TEST(Kernels, SpikyIntegratesToOne) {
  const Kernels k(kH);
  EXPECT_NEAR(radial_integral([&](double r) { return k.spiky(float(r)); }, kH), 1.0, 1e-4);
}

TEST(Kernels, ViscosityKernelIntegratesToOne) {
  EXPECT_NEAR(radial_integral([](double r) { return viscosity_kernel(r, kH); }, kH), 1.0, 1e-4);
}

TEST(Kernels, VanishOutsideTheSupport) {
  const Kernels k(kH);
  EXPECT_EQ(k.poly6(kH * kH), 0.0f);
  EXPECT_EQ(k.spiky(kH), 0.0f);
  EXPECT_EQ(k.spiky_gradient(glm::vec3(kH, 0, 0), kH * kH), glm::vec3(0.0f));
  EXPECT_EQ(k.viscosity_laplacian(1.5f * kH), 0.0f);
}

TEST(Kernels, SpikyGradientMatchesFiniteDifferences) {
  const Kernels k(kH);
  const double step = 1e-6;
  for (const glm::dvec3 x : {glm::dvec3(0.01, 0.02, -0.005), glm::dvec3(-0.03, 0.001, 0.02),
                             glm::dvec3(0.0, 0.0, 0.045)}) {
    const glm::vec3 analytic = k.spiky_gradient(glm::vec3(x), float(glm::dot(x, x)));
    for (int axis = 0; axis < 3; ++axis) {
      glm::dvec3 plus = x, minus = x;
      plus[axis] += step;
      minus[axis] -= step;
      const double numeric =
          (k.spiky(float(glm::length(plus))) - k.spiky(float(glm::length(minus)))) / (2 * step);
      EXPECT_NEAR(analytic[axis], numeric, 2e-3 * std::abs(k.spiky(0.0f)) / kH) << "axis " << axis;
    }
  }
}

TEST(Kernels, SpikyGradientIsZeroForCoincidentParticles) {
  const Kernels k(kH);
  const glm::vec3 g = k.spiky_gradient(glm::vec3(0.0f), 0.0f);
  EXPECT_EQ(g, glm::vec3(0.0f));
}

// The lanes' own operations, on whichever path this build compiled (AVX or SSE in kernels_test,
// SSE in kernels_sse_lanes_test, the portable one in kernels_generic_lanes_test).
TEST(Lanes, MaskSetsTheBitOfEachTrueLane) {
  for (unsigned pattern = 0; pattern < (1u << lanes::kWidth); ++pattern) {
    lanes::Floats v{};
    for (std::uint32_t lane = 0; lane < lanes::kWidth; ++lane) v[lane] = (pattern >> lane) & 1u;
    EXPECT_EQ(lanes::mask(v > 0.5f), pattern);
  }
}

TEST(Lanes, SquareRootsAgreeWithTheScalarOnes) {
  lanes::Floats x{};
  const float values[] = {1e-30f, 0.25f, 2.0f, 3e10f, 1e-5f, 7.0f, 1e20f, 0.5f};
  for (std::uint32_t lane = 0; lane < lanes::kWidth; ++lane) x[lane] = values[lane];
  const lanes::Floats root = lanes::sqrt(x);
  const lanes::Floats inverse = lanes::inverse_sqrt(x);
  for (std::uint32_t lane = 0; lane < lanes::kWidth; ++lane) {
    EXPECT_EQ(root[lane], std::sqrt(x[lane]));
    const double exact = 1.0 / std::sqrt(double(x[lane]));
    EXPECT_NEAR(inverse[lane], exact, 3e-7 * exact) << x[lane];
    EXPECT_EQ(lanes::inverse_sqrt(x[lane]), inverse[lane]) << x[lane];
  }
}

TEST(Lanes, GatherAndSelectPickTheirLanes) {
  const float data[] = {10.0f, 11.0f, 12.0f, 13.0f, 14.0f};
  const std::uint32_t index[] = {4, 0, 2, 2, 1, 3, 3, 0};
  const lanes::Floats gathered = lanes::gather(data, index);
  const lanes::Floats chosen = lanes::select(lanes::kLaneIndex < 2, gathered, lanes::Floats{});
  EXPECT_EQ(chosen[0], 14.0f);
  EXPECT_EQ(chosen[1], 10.0f);
  EXPECT_EQ(chosen[2], 0.0f);
  EXPECT_EQ(chosen[3], 0.0f);
  float expected_sum = 0.0f;
  for (std::uint32_t lane = 0; lane < lanes::kWidth; ++lane) {
    EXPECT_EQ(gathered[lane], data[index[lane]]);
    expected_sum += data[index[lane]];
  }
  EXPECT_EQ(lanes::sum(gathered), expected_sum);
}

// The solvers' loops evaluate a block of pairs at a time: each lane must be what one pair gives,
// zero included (coincident, at h, beyond, NaN: a NaN neighbour must give 0, not NaN).
TEST(Kernels, EveryLaneGivesWhatOnePairGives) {
  const Kernels k(kH);
  const float distances[] = {0.0f,        1e-15f, 0.3f * kH, 0.7f * kH,
                             0.999f * kH, kH,     1.5f * kH, std::nanf("")};
  for (std::size_t first = 0; first + lanes::kWidth <= std::size(distances); ++first) {
    lanes::Vec3 r{};
    for (std::uint32_t lane = 0; lane < lanes::kWidth; ++lane) {
      r.x[lane] = 0.6f * distances[first + lane];
      r.y[lane] = 0.8f * distances[first + lane];
    }
    const lanes::Floats r2 = lanes::dot(r, r);
    const lanes::Floats w = k.poly6(r2);
    const lanes::Vec3 g = k.spiky_gradient(r, r2);
    const lanes::Floats laplacian = k.viscosity_laplacian(lanes::sqrt(r2));
    for (std::uint32_t lane = 0; lane < lanes::kWidth; ++lane) {
      const glm::vec3 one_r(r.x[lane], r.y[lane], 0.0f);
      const float one_r2 = r2[lane];
      const glm::vec3 one_g = k.spiky_gradient(one_r, one_r2);
      EXPECT_EQ(w[lane], k.poly6(one_r2)) << "r² = " << one_r2;
      EXPECT_NEAR(g.x[lane], one_g.x, 1e-6f * std::abs(one_g.x)) << one_r2;
      EXPECT_NEAR(g.y[lane], one_g.y, 1e-6f * std::abs(one_g.y)) << one_r2;
      EXPECT_EQ(g.z[lane], 0.0f) << one_r2;
      EXPECT_EQ(laplacian[lane], k.viscosity_laplacian(std::sqrt(one_r2))) << one_r2;
      EXPECT_FALSE(std::isnan(g.x[lane]) || std::isnan(g.y[lane]) || std::isnan(w[lane]) ||
                   std::isnan(laplacian[lane]))
          << one_r2;
    }
  }
  const glm::vec3 nan(std::nanf(""), 0.0f, 0.0f);
  EXPECT_EQ(k.spiky_gradient(nan, glm::dot(nan, nan)), glm::vec3(0.0f));
  EXPECT_LT(k.spiky_gradient(glm::vec3(0.5f * kH, 0.0f, 0.0f), 0.25f * kH * kH).x, 0.0f);
}

TEST(Kernels, ViscosityLaplacianMatchesFiniteDifferences) {
  const Kernels k(kH);
  // ∇²W = W'' + 2 W' / r for a radial function.
  const double step = 1e-5;
  for (double r : {0.01, 0.02, 0.035, 0.045}) {
    const double w0 = viscosity_kernel(r, kH), wp = viscosity_kernel(r + step, kH),
                 wm = viscosity_kernel(r - step, kH);
    const double laplacian = (wp - 2 * w0 + wm) / (step * step) + (wp - wm) / (step * r);
    EXPECT_NEAR(k.viscosity_laplacian(float(r)), laplacian, 1e-3 * k.viscosity_laplacian(0.0f))
        << "r = " << r;
  }
}

// ∫ f(√(ρ² + z²)) over the plane at distance z, in polar coordinates.
template <class F>
double plane_integral(F f, double z, double h, int m = 2000) {
  const double reach = std::sqrt(h * h - z * z);
  double sum = 0.0;
  for (int j = 0; j < m; ++j) {
    const double rho = (j + 0.5) * reach / m;
    sum += 2 * kPi * rho * f(std::sqrt(rho * rho + z * z)) * reach / m;
  }
  return sum;
}

TEST(Kernels, WallTermsVanishAtTheKernelRadius) {
  const Kernels k(kH);
  EXPECT_NEAR(k.wall_volume(0.0f), 0.5f, 1e-5f);
  EXPECT_EQ(k.wall_volume(kH), 0.0f);
  EXPECT_EQ(k.wall_gradient(kH), 0.0f);
}

TEST(Kernels, WallVolumeIsPoly6IntegratedOverTheHalfSpace) {
  const Kernels k(kH);
  for (float s : {0.0f, 0.005f, 0.02f, 0.04f}) {
    const int n = 2000;
    double volume = 0.0;
    for (int i = 0; i < n; ++i) {
      const double z = s + (i + 0.5) * (kH - s) / n;
      volume += plane_integral([&](double r) { return k.poly6(float(r * r)); }, z, kH, 400) *
                (kH - s) / n;
    }
    EXPECT_NEAR(k.wall_volume(s), volume, 1e-4) << "s = " << s;
  }
}

TEST(Kernels, WallGradientIsSpikyIntegratedOverThePlane) {
  const Kernels k(kH);
  for (float s : {0.0f, 0.005f, 0.02f, 0.04f}) {
    const double expected = plane_integral([&](double r) { return k.spiky(float(r)); }, s, kH);
    EXPECT_NEAR(k.wall_gradient(s), expected, 1e-3 * k.wall_gradient(0.0f)) << "s = " << s;
  }
}

}  // namespace
}  // namespace fluidcast::sim
