// SPH smoothing kernels of Müller, Charypar & Gross (2003), normalised in 3D so that ∫W dV = 1.
// poly6 for densities, spiky for pressure gradients, viscosity kernel for its Laplacian.
#pragma once

#include <cmath>
#include <glm/glm.hpp>
#include <numbers>

#include "fluidcast/sim/lanes.h"

namespace fluidcast::sim {

class Kernels {
 public:
  explicit Kernels(float radius)
      : h_(radius),
        h2_(radius * radius),
        poly6_(315.0f / (64.0f * std::numbers::pi_v<float> * pow9(radius))),
        spiky_(15.0f / (std::numbers::pi_v<float> * pow6(radius))),
        viscosity_laplacian_(45.0f / (std::numbers::pi_v<float> * pow6(radius))) {}

  float radius() const { return h_; }
  float radius_squared() const { return h2_; }
  // The normalisation constants, for the GPU solvers' copy of these formulas.
  float poly6_coefficient() const { return poly6_; }
  float spiky_coefficient() const { return spiky_; }
  float viscosity_laplacian_coefficient() const { return viscosity_laplacian_; }

  // poly6 W(r) from r², so the density loop needs no square root; of one pair (float) or of a
  // block (lanes::Floats). 0 beyond h and for NaN.
  template <lanes::OneOrBlock F>
  F poly6(F r2) const {
    const F x = h2_ - r2;
    return lanes::select(r2 < h2_, poly6_ * x * x * x, F{});
  }

  float spiky(float r) const {
    if (!(r < h_)) return 0.0f;
    const float x = h_ - r;
    return spiky_ * x * x * x;
  }

  // ∇W_spiky at offset r_vec = p_i − p_j with |r_vec|² = r2, of one pair (glm::vec3, float) or of
  // a block (lanes::Vec3, lanes::Floats); zero beyond h, for NaN and at r = 0, where its direction is
  // undefined (coincident particles must not produce a NaN). The zero is selected, not multiplied
  // in: 0 · NaN would let a NaN neighbour through.
  template <class V, lanes::OneOrBlock F>
  V spiky_gradient(V r_vec, F r2) const {
    const F inv_r = lanes::inverse_sqrt(r2);
    const F x = h_ - r2 * inv_r;
    return lanes::select((r2 < h2_) & (r2 > 1e-24f), (-3.0f * spiky_ * x * x * inv_r) * r_vec, V{});
  }

  // A half-space full of fluid at rest, its plane at distance s from a particle (the walls' fluid,
  // FluidConstants::wall_offset behind each wall).
  // wall_volume(s) = ∫ W_poly6 over that half-space (½ at s = 0, 0 at s ≥ h): the wall adds
  // ρ0 · wall_volume(s) to the particle's density. wall_gradient(s) = ∫ W_spiky over the wall plane
  // = |∫ ∇W_spiky| over the half-space: the magnitude of the gradient that the pressure terms,
  // which use spiky gradients between particles, see from the wall. Closed forms: π K6/4 ∫_s^h (h²
  // − z²)⁴ dz and 1.5 (h − s)⁴ (h + 4s) / h⁶.
  float wall_volume(float s) const {
    if (!(s < h_)) return 0.0f;
    s = s > 0.0f ? s : 0.0f;
    return 0.25f * std::numbers::pi_v<float> * poly6_ * (antiderivative(h_) - antiderivative(s));
  }
  float wall_gradient(float s) const {
    if (!(s < h_)) return 0.0f;
    s = s > 0.0f ? s : 0.0f;
    const float x = h_ - s;
    return 1.5f * x * x * x * x * (h_ + 4.0f * s) / pow6(h_);
  }

  // The walls' fluid at rest behind the six faces of a box, around a particle `near` and `far`
  // from those faces on each axis: its share of the particle's kernel (ρ0 times it is the density
  // the walls add) and that share's gradient as the pressure terms see it. Where walls meet,
  // their half-spaces overlap, and the union is taken as for a kernel that is a product over the
  // axes: the share in front of every wall is the product of each axis's 1 − wall_volume(near) −
  // wall_volume(far), and an axis's gradient is its walls' times the share in front of the other
  // axes' walls. Exact on a wall's plane, where the overlap is half of the other half-space by
  // symmetry; a lattice's edge and corner sites read 0.6 and 1.4 % under ρ0 at h = 2d, where the
  // half-spaces summed read them 3.0 and 8.8 % over (FluidConstants tests).
  struct WallShare {
    float volume = 0.0f;
    glm::vec3 gradient{0.0f};  // 1/m, pointing into the walls
  };
  WallShare walls(glm::vec3 near, glm::vec3 far) const {
    glm::vec3 in_front(0.0f), pushed(0.0f);  // every lane is set below; GCC 12 cannot tell
    for (int axis = 0; axis < 3; ++axis) {
      in_front[axis] = 1.0f - wall_volume(near[axis]) - wall_volume(far[axis]);
      pushed[axis] = wall_gradient(far[axis]) - wall_gradient(near[axis]);
    }
    const glm::vec3 in_front_of_the_others(in_front.y * in_front.z, in_front.x * in_front.z,
                                           in_front.x * in_front.y);
    return {1.0f - in_front.x * in_front_of_the_others.x, pushed * in_front_of_the_others};
  }

  // ∇²W_viscosity(r) = 45 / (π h⁶) · (h − r), of one pair or of a block; 0 beyond h and for NaN.
  template <lanes::OneOrBlock F>
  F viscosity_laplacian(F r) const {
    return lanes::select(r < h_, viscosity_laplacian_ * (h_ - r), F{});
  }

 private:
  // ∫ (h² − z²)⁴ dz
  float antiderivative(float z) const {
    const float z2 = z * z, h4 = h2_ * h2_;
    return z * (h4 * h4 - z2 * (4.0f / 3.0f * h4 * h2_ -
                                z2 * (6.0f / 5.0f * h4 - z2 * (4.0f / 7.0f * h2_ - z2 / 9.0f))));
  }
  static constexpr float pow6(float x) { return x * x * x * x * x * x; }
  static constexpr float pow9(float x) { return pow6(x) * x * x * x; }

  float h_, h2_, poly6_, spiky_, viscosity_laplacian_;
};

}  // namespace fluidcast::sim
