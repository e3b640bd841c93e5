#version 460
#extension GL_GOOGLE_include_directive : require
// PBF, in sorted order: the velocity from the corrected position, v = (x* − x) / Δt, with the
// corrections' part of it capped at max_acceleration · Δt; as PbfSolver::update_velocities. The
// uncorrected prediction is still in P.predicted, in state order.
#include "common/core.glsl"
#include "common/sim_params.glsl"

void main() {
  const uint k = invocation();
  if (k >= P.particle_count) return;
  Vec4s x = P.iterate;
  const vec3 start = P.sorted_position.v[k].xyz;
  const vec3 uncorrected_position = P.predicted.v[P.order.v[k]].xyz;
  const float inv_dt = 1.0 / pass.dt;
  const vec3 uncorrected = (uncorrected_position - start) * inv_dt;
  const vec3 change = (x.v[k].xyz - uncorrected_position) * inv_dt;
  const float most = P.max_acceleration * pass.dt;
  const float change_length = length(change);
  const vec3 v = uncorrected + (change_length > most ? change * (most / change_length) : change);
  P.sorted_velocity.v[k] = vec4(v, 0.0);
}
