#version 460
#extension GL_GOOGLE_include_directive : require
// PBF: the position correction Δp with s_corr (tensile instability), pushed off the walls by
// the particle's own λ, weighted (pbf_correction_weight: the first and last iterations'), then
// constrained; as PbfSolver::apply_position_corrections. The last iteration also sets the
// velocity from the corrected position, as PbfSolver::velocity_from; on a substep that is not its
// step's last, no filter follows, and it ends the substep itself (end_pbf_substep).
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/sim_kernels.glsl"

// In sorted order: v = (x* − x) / Δt, with the corrections' part of it capped at
// max_acceleration · Δt. The uncorrected prediction is still in P.predicted, in state order.
vec3 velocity_from(uint k, vec3 corrected) {
  const vec3 start = P.sorted_position.v[k].xyz;
  const vec3 uncorrected_position = P.predicted.v[P.order.v[k]].xyz;
  const float inv_dt = 1.0 / pass.dt;
  const vec3 uncorrected = (uncorrected_position - start) * inv_dt;
  const vec3 change = (corrected - uncorrected_position) * inv_dt;
  const float most = P.max_acceleration * pass.dt;
  const float change_length = length(change);
  return held_to_max_speed(uncorrected +
                           (change_length > most ? change * (most / change_length) : change));
}

// Particle k's position after this iteration's correction.
vec3 correct(uint k) {
  Vec4s x = P.iterate_scalar;
  const vec4 own = x.v[k];
  const vec3 p = own.xyz;
  const float lambda_i = own.w;
  // s_corr at the step's stiffness, as λ is (write_lambda).
  const float scorr_scale = P.stiffness_share * P.scorr_scale;
  const float inv_w_dq = P.inv_w_dq, exponent = P.scorr_exponent;
  const bool exponent_is_four = exponent == 4.0;
  vec3 delta = vec3(0.0);
  const uint count = neighbour_count(k);
  for (uint g = 0u; 4u * g < count; ++g) {
    const vec4 others[4] = gather(x, neighbour_group(k, g));
    [[unroll]] for (uint l = 0u; l < 4u; ++l) {
      if (4u * g + l == count) break;
      const vec3 r = p - others[l].xyz;
      const float r2 = dot(r, r);
      if (!(r2 < K_h2)) continue;
      const float s = poly6(r2) * inv_w_dq;
      const float s2 = s * s;
      const float scorr = -scorr_scale * (exponent_is_four ? s2 * s2 : pow(s, exponent));
      delta += (lambda_i + others[l].w + scorr) * spiky_gradient(r, r2);
    }
  }
  const vec3 wall_push = lambda_i * P.inv_rest_density * walls(p).yzw;
  vec3 unused;
  const vec3 correction = pass.correction_weight * (P.rest_volume * delta + wall_push);
  return constrain(p + correction, unused, false);
}

void main() {
  load_constants();
  const uint k = invocation();
  const bool in_range = k < P.particle_count;
  const bool ends_substep = pass.write_velocity != 0u && pass.last_substep == 0u;
  vec3 corrected = vec3(0.0), velocity = vec3(0.0);
  if (in_range) corrected = correct(k);
  if (in_range && pass.write_velocity != 0u) velocity = velocity_from(k, corrected);
  if (ends_substep) {
    end_pbf_substep(k, in_range, corrected, velocity);
  } else if (in_range) {
    P.iterate.v[k] = vec4(corrected, 0.0);
    if (pass.write_velocity != 0u) P.sorted_velocity.v[k] = vec4(velocity, 0.0);
  }
}
