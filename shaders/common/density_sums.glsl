// What a substep first computes from each particle's neighbours: PBF's λ and SPH's density with
// its pressure. neighbours.comp adds them up as it lists the neighbours (the same positions, the
// same order), which spares the substep a pass over the list; pbf_lambda.comp adds up λ for the
// later iterations. Included after sim_kernels.glsl.

// PBF: the density constraint's λ (Macklin & Müller 2013), unilateral (only compression), with
// the walls as fluid at rest, at the step's stiffness (more where the particle is pressed:
// particle_stiffness_share in substeps.h); as PbfSolver::compute_lambdas.
struct LambdaSum {
  float density;  // Σ W, the particle's own included
  vec3 gradient;  // ∇_i C
  float sum_squares;  // Σ |∇_j C|²
};

LambdaSum lambda_sum_start() { return LambdaSum(poly6(0.0), vec3(0.0), 0.0); }

void lambda_sum_add(inout LambdaSum sum, vec3 r, float r2) {
  sum.density += poly6(r2);
  const vec3 g = K_rest_volume * spiky_gradient(r, r2);
  sum.gradient += g;
  sum.sum_squares += dot(g, g);
}

// λ into iterate_scalar beside the position it was computed at, and ρ/ρ0 for the renderer.
void write_lambda(uint k, vec3 p, LambdaSum sum) {
  const vec4 wall = walls(p);
  const vec3 gradient_i = sum.gradient + P.inv_rest_density * wall.yzw;
  const float ratio = (P.mass * sum.density + wall.x) * P.inv_rest_density;
  P.density_ratio.v[k] = ratio;  // sorted slot k is state index k once the substep ends
  const float constraint = max(ratio - 1.0, 0.0);
  const float pressed = clamp((constraint - P.pressed_from) / P.pressed_span, 0.0, 1.0);
  const float stiffness = P.stiffness_share + (1.0 - P.stiffness_share) * pressed;
  const float lambda = constraint == 0.0 ? 0.0
      : -stiffness * constraint
          / (sum.sum_squares + dot(gradient_i, gradient_i) + P.relaxation_epsilon);
  P.iterate_scalar.v[k] = vec4(p, lambda);
}

// SPH: density (Σ W, walls as fluid at rest) and Tait pressure, clamped at 0; as
// SphSolver::compute_densities_and_pressures.
void write_sph_density(uint k, vec3 p, float sum) {
  const float density = P.mass * sum + walls(p).x;
  const float pressure =
      max(0.0, P.tait_stiffness * (pow(density / P.rest_density, P.tait_exponent) - 1.0));
  P.density.v[k] = vec2(density, pressure);
  P.density_ratio.v[k] = density * P.inv_rest_density;  // state index k once the substep ends
}
