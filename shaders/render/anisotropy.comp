#version 460
#extension GL_GOOGLE_include_directive : require
// SSFR's anisotropic kernels (Yu & Turk 2013): each particle becomes an ellipsoid shaped like the
// spread of its neighbours, flat along a surface and round inside, so that the surface the spheres
// make is a sheet rather than a field of bumps. One invocation per sorted slot of the renderer's
// grid over the particles (neighbours of consecutive slots are the same cells), written per
// particle, where the draw reads them.
#include "common/core.glsl"
#include "common/grid.glsl"

layout(push_constant, std430) uniform Anisotropy {
  Vec4s position;      // the particles as drawn
  Uints order;         // the grid: sorted slot → particle
  Uints cell_start;
  Uints sorted_cell;
  Vec4s centre;        // out, per particle: the smoothed centre; w: 1 for spray, else 0
  Vec4s shape;         // out, two per particle: G (below) xx, xy, xz, yy, then yz, zz, the
                       // longest semi-axis, 0
  ivec4 dims;          // the grid's cells per axis
  uint particle_count;
  float radius;        // of a particle, m
  float search_radius; // of the neighbourhood, m
  float max_stretch;   // the largest ratio of the longest to the shortest axis
  float centre_smoothing;  // λ: how far each centre moves to its neighbours' weighted mean
  uint spray_below;    // fewer neighbours than this: spray
} a;

// Below this many neighbours a covariance says little about a surface: a sphere.
const uint kShapedFrom = 8u;

// Eigenvalues of the symmetric A (returned), eigenvectors in V's columns, by cyclic Jacobi
// rotations: six sweeps bring a 3×3 to float precision.
vec3 symmetric_eigen(mat3 A, out mat3 V) {
  V = mat3(1.0);
  for (int sweep = 0; sweep < 6; ++sweep) {
    for (int pair = 0; pair < 3; ++pair) {
      const int p = pair == 2 ? 1 : 0;
      const int q = pair == 0 ? 1 : 2;
      const float apq = A[q][p];  // column q, row p
      if (abs(apq) < 1e-20) continue;
      const float theta = (A[q][q] - A[p][p]) / (2.0 * apq);
      const float t = (theta >= 0.0 ? 1.0 : -1.0) / (abs(theta) + sqrt(theta * theta + 1.0));
      const float c = inversesqrt(t * t + 1.0), s = t * c;
      mat3 J = mat3(1.0);
      J[p][p] = c;
      J[q][q] = c;
      J[q][p] = s;   // row p, column q
      J[p][q] = -s;  // row q, column p
      A = transpose(J) * A * J;
      V = V * J;
    }
  }
  return vec3(A[0][0], A[1][1], A[2][2]);
}

void main() {
  const uint k = invocation();
  if (k >= a.particle_count) return;
  const uint i = a.order.v[k];
  const vec3 p = a.position.v[i].xyz;
  const ivec3 dims = a.dims.xyz;
  const uint c = a.sorted_cell.v[k];
  const uint row = uint(dims.x), layer = row * uint(dims.y);
  const ivec3 cell = ivec3(c % row, (c % layer) / row, c / layer);
  const float inv_search2 = 1.0 / (a.search_radius * a.search_radius);
  const float inv_radius = 1.0 / a.radius;

  // Weighted by 1 − (d/R)³ (Yu & Turk); offsets in particle radii keep the sums near 1.
  float total = 0.0;
  vec3 mean = vec3(0.0);
  mat3 spread = mat3(0.0);
  uint found = 0u;
  FOR_EACH_CANDIDATE_IN(a.cell_start, dims, cell, j) {
    const vec3 d = a.position.v[a.order.v[j]].xyz - p;
    const float x2 = dot(d, d) * inv_search2;
    if (!(x2 < 1.0)) continue;
    const float w = 1.0 - x2 * sqrt(x2);
    const vec3 scaled = d * inv_radius;
    total += w;
    mean += w * scaled;
    spread += w * outerProduct(scaled, scaled);
    ++found;
  }
  const uint neighbours = found - 1u;  // the particle itself is among them
  const bool spray = neighbours < a.spray_below;
  mean /= total;

  vec3 axes = vec3(1.0);  // in particle radii
  mat3 V = mat3(1.0);
  if (!spray && neighbours >= kShapedFrom) {
    const mat3 covariance = spread / total - outerProduct(mean, mean);
    vec3 sigma = symmetric_eigen(covariance, V);
    const float largest = max(max(sigma.x, sigma.y), max(sigma.z, 1e-12));
    sigma = max(sigma, vec3(largest / a.max_stretch));
    // The sphere's volume, so that the water's thickness stays what it was.
    axes = sigma / pow(sigma.x * sigma.y * sigma.z, 1.0 / 3.0);
  }
  const vec3 inverse_axes = inv_radius / axes;
  // G maps a world offset from the centre to the unit sphere: V diag(1/axes) Vᵀ.
  const mat3 G = V * mat3(inverse_axes.x, 0, 0, 0, inverse_axes.y, 0, 0, 0, inverse_axes.z) *
                 transpose(V);
  const vec3 centre = spray ? p : p + a.centre_smoothing * a.radius * mean;
  a.centre.v[i] = vec4(centre, spray ? 1.0 : 0.0);
  const float longest = a.radius * max(max(axes.x, axes.y), axes.z);
  a.shape.v[2u * i] = vec4(G[0][0], G[0][1], G[0][2], G[1][1]);
  a.shape.v[2u * i + 1u] = vec4(G[1][2], G[2][2], longest, 0.0);
}
