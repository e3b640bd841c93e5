// Kernels, walls, boundaries and the neighbour loop, as the CPU solvers have them (kernels.h,
// cpu_solver.h): the same formulas, so that the two backends agree.
// Vectors behind a buffer reference are always loaded whole, never one component through the
// reference: Mesa 22.3's lavapipe read the .w of a vec4 member of the parameter block as 0.
#include "common/grid.glsl"

// What the inner loops read, loaded once per invocation by load_constants() (first thing in
// main), so that the loops do not reload it through the parameter block's reference.
float K_h, K_h2, K_poly6, K_spiky, K_viscosity_laplacian, K_rest_volume;
ivec3 K_grid_dims;
uint K_max_candidates;
Uints K_cell_start;
Uints K_sorted_cell;
uint K_particle_count;
Uvec4s K_neighbours;
Uints K_neighbour_count;

void load_constants() {
  K_h = P.h;
  K_h2 = P.h2;
  K_poly6 = P.poly6;
  K_spiky = P.spiky;
  K_viscosity_laplacian = P.viscosity_laplacian;
  K_rest_volume = P.rest_volume;
  const ivec4 dims = P.grid_dims;
  K_grid_dims = dims.xyz;
  K_max_candidates = P.max_candidates;
  K_cell_start = P.cell_start;
  K_sorted_cell = P.sorted_cell;
  K_particle_count = P.particle_count;
  K_neighbours = P.neighbours;
  K_neighbour_count = P.neighbour_count;
}

float poly6(float r2) {
  if (!(r2 < K_h2)) return 0.0;
  const float x = K_h2 - r2;
  return K_poly6 * x * x * x;
}

vec3 spiky_gradient(vec3 r, float r2) {
  if (!(r2 < K_h2) || r2 <= 1e-24) return vec3(0.0);
  const float inv_r = inversesqrt(r2);
  const float x = K_h - r2 * inv_r;
  return (-3.0 * K_spiky * x * x * inv_r) * r;
}

float viscosity_laplacian(float r) { return r < K_h ? K_viscosity_laplacian * (K_h - r) : 0.0; }

float wall_antiderivative(float z) {
  const float z2 = z * z, h2 = K_h2, h4 = h2 * h2;
  return z * (h4 * h4 - z2 * (4.0 / 3.0 * h4 * h2 -
                              z2 * (6.0 / 5.0 * h4 - z2 * (4.0 / 7.0 * h2 - z2 / 9.0))));
}

float wall_volume(float s) {
  if (!(s < K_h)) return 0.0;
  s = max(s, 0.0);
  return 0.25 * 3.14159265358979 * K_poly6 * (wall_antiderivative(K_h) - wall_antiderivative(s));
}

float wall_gradient(float s) {
  if (!(s < K_h)) return 0.0;
  s = max(s, 0.0);
  const float x = K_h - s;
  const float h3 = K_h2 * K_h;
  return 1.5 * x * x * x * x * (K_h + 4.0 * s) / (h3 * h3);
}

// What the six walls add at p: density (x) and its gradient (yzw), their overlaps along edges and
// in corners taken as for a kernel that is a product over the axes (Kernels::walls).
vec4 walls(vec3 p) {
  const vec3 near = p - P.wall_fluid_min.xyz, far = P.wall_fluid_max.xyz - p;
  vec3 in_front, pushed;
  for (int axis = 0; axis < 3; ++axis) {
    in_front[axis] = 1.0 - wall_volume(near[axis]) - wall_volume(far[axis]);
    pushed[axis] = wall_gradient(far[axis]) - wall_gradient(near[axis]);
  }
  const vec3 in_front_of_the_others = in_front.yxx * in_front.zzy;
  return P.rest_density *
         vec4(1.0 - in_front.x * in_front_of_the_others.x, pushed * in_front_of_the_others);
}

// As the CPU's held_to_max_speed (solver.h).
vec3 held_to_max_speed(vec3 v) {
  const float speed2 = dot(v, v);
  return speed2 > P.max_speed * P.max_speed ? v * (P.max_speed / sqrt(speed2)) : v;
}

// How fast p, moving at v, closes on a wall it would reach within P.wall_reach seconds at that
// speed; 0 if on none (substeps.h, wall_approach, for the CPU and the loaded particles).
float wall_approach(vec3 p, vec3 v) {
  float fastest = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    const float toward_min = -v[axis], toward_max = v[axis];
    if (toward_min > 0.0 && p[axis] - P.inner_min[axis] < toward_min * P.wall_reach) {
      fastest = max(fastest, toward_min);
    }
    if (toward_max > 0.0 && P.inner_max[axis] - p[axis] < toward_max * P.wall_reach) {
      fastest = max(fastest, toward_max);
    }
  }
  return fastest;
}

// Moves p out of every collider (at time_into_step) and into the tank; when `velocity` is given
// (SPH), removes its component into each surface p was pushed out of.
vec3 constrain(vec3 p, inout vec3 v, bool adjust_velocity) {
  for (uint c = 0; c < P.collider_count; ++c) {
    const vec4 sphere = P.collider_sphere[c];
    const vec3 centre = sphere.xyz + pass.time_into_step * P.collider_velocity[c].xyz;
    const vec3 d = p - centre;
    const float reach = sphere.w + P.particle_radius;
    const float dist2 = dot(d, d);
    if (!(dist2 < reach * reach)) continue;
    const float dist = sqrt(dist2);
    const vec3 normal = dist > 1e-6 * reach ? d / dist : vec3(0, 1, 0);
    p = centre + normal * reach;
    if (adjust_velocity) {
      const float approach = dot(v - P.collider_velocity[c].xyz, normal);
      if (approach < 0.0) v -= approach * normal;
    }
  }
  const vec4 inner_min = P.inner_min, inner_max = P.inner_max;
  if (adjust_velocity) {
    for (int axis = 0; axis < 3; ++axis) {
      if (p[axis] < inner_min[axis]) {
        p[axis] = inner_min[axis];
        v[axis] = max(v[axis], 0.0);
      } else if (p[axis] > inner_max[axis]) {
        p[axis] = inner_max[axis];
        v[axis] = min(v[axis], 0.0);
      }
    }
    return p;
  }
  return clamp(p, inner_min.xyz, inner_max.xyz);
}

// The cell slot k was sorted into: its candidate window (symmetric: j is a candidate of k exactly
// when k is one of j).
ivec3 sorted_cell(uint k) {
  const uint c = K_sorted_cell.v[k];
  const uint row = uint(K_grid_dims.x), layer = row * uint(K_grid_dims.y);
  return ivec3(c % row, (c % layer) / row, c / layer);
}

// for every sorted slot j in the 5×5 rows of 5 cells around `cell` (grid.glsl):
//   const ivec3 cell = sorted_cell(k);
//   FOR_EACH_CANDIDATE(cell, j) { ... }
#define FOR_EACH_CANDIDATE(cell, j) \
  FOR_EACH_CANDIDATE_IN(K_cell_start, K_grid_dims, cell, j, K_max_candidates)

// This substep's neighbours of sorted slot k, as neighbours.comp listed them from the positions
// the substep began with (the CPU solvers' lists, NeighbourList, are the same), four at a time:
//   const uint count = neighbour_count(k);
//   for (uint g = 0u; 4u * g < count; ++g) {
//     const vec4 others[4] = gather(x, neighbour_group(k, g));
//     [[unroll]] for (uint l = 0u; l < 4u; ++l) {
//       if (4u * g + l == count) break;
//       ... others[l] ...
// A gather pass waits on memory, one neighbour's loads after another's: a group's four entries
// come in one 16-byte load, and its four neighbours' loads are all issued before the first is
// used. Entries past the count repeat k, so that all four may be loaded. Slot-major, so that
// the invocations of a workgroup read one group each from one row.
uint neighbour_count(uint k) { return K_neighbour_count.v[k]; }
uvec4 neighbour_group(uint k, uint g) { return K_neighbours.v[k + g * K_particle_count]; }
vec4[4] gather(Vec4s values, uvec4 j) {
  return vec4[4](values.v[j.x], values.v[j.y], values.v[j.z], values.v[j.w]);
}
// glslang takes every buffer reference for one type in an overload.
vec2[4] gather_pairs(Vec2s values, uvec4 j) {
  return vec2[4](values.v[j.x], values.v[j.y], values.v[j.z], values.v[j.w]);
}

// The largest value over the dispatch, into P.stats.v[slot]: one global atomic per workgroup.
// Every invocation must call it (no early return before).
shared uint group_largest;
void record_largest(uint slot, float value) {
  if (gl_LocalInvocationIndex == 0) group_largest = 0u;
  barrier();
  atomicMax(group_largest, floatBitsToUint(value));  // value ≥ 0; NaN sorts above +inf
  barrier();
  if (gl_LocalInvocationIndex == 0) atomicMax(P.stats.v[slot], group_largest);
}

// A PBF substep's end for sorted slot k (where `in_range`): position p and velocity v become the
// state (sorted order becomes state order), and the speed and wall approach count toward the
// next step's substeps (their largest over the step). The finish pass ends a step's last
// substep, the last correction pass the others. Every invocation must call it.
void end_pbf_substep(uint k, bool in_range, vec3 p, vec3 v) {
  float speed2 = 0.0, approach = 0.0;
  if (in_range) {
    P.position.v[k] = vec4(p, 0.0);
    P.velocity.v[k] = vec4(v, 0.0);
    P.id.v[k] = P.sorted_id.v[k];
    speed2 = dot(v, v);
    approach = wall_approach(p, v);
  }
  record_largest(0u, speed2);
  record_largest(4u, approach);
}

// Adds the sum of `value` over the dispatch into the 64-bit counter P.stats.v[slot] (low word) and
// [slot + 1] (high word), in units of 2^-20: each invocation's value at most 16 (NaN counted as
// 16), so that a workgroup's sum (at most 128 invocations) fits in 32 bits; one global atomic per
// workgroup, and a carry into the high word when the low one wraps. The host divides by the
// particle count: no rounding beyond each value's 2^-20. Every invocation must call it.
shared uint group_sum;
void record_sum(uint slot, float value) {
  if (gl_LocalInvocationIndex == 0) group_sum = 0u;
  barrier();
  const float counted = isnan(value) ? 16.0 : clamp(value, 0.0, 16.0);
  atomicAdd(group_sum, uint(round(counted * 1048576.0)));
  barrier();
  if (gl_LocalInvocationIndex == 0 && group_sum != 0u) {
    const uint before = atomicAdd(P.stats.v[slot], group_sum);
    if (before + group_sum < before) atomicAdd(P.stats.v[slot + 1u], 1u);
  }
}
