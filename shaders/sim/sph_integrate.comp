#version 460
#extension GL_GOOGLE_include_directive : require
// SPH: symplectic Euler, then the boundaries; the particles written back as state, and the
// largest |v|² recorded.
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/sim_kernels.glsl"

void main() {
  load_constants();
  const uint k = invocation();
  float speed2 = 0.0;
  if (k < P.particle_count) {
    vec3 v = held_to_max_speed(P.sorted_velocity.v[k].xyz + pass.dt * P.acceleration.v[k].xyz);
    vec3 x = P.sorted_position.v[k].xyz + pass.dt * v;
    x = constrain(x, v, true);
    // After the colliders, which may add speed: a finger's into a particle's own across it.
    v = held_to_max_speed(v);
    P.position.v[k] = vec4(x, 0.0);
    P.velocity.v[k] = vec4(v, 0.0);
    P.id.v[k] = P.sorted_id.v[k];
    speed2 = dot(v, v);
  }
  record_largest(0u, speed2);
}
