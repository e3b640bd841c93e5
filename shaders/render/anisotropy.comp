#version 460
#extension GL_GOOGLE_include_directive : require
// SSFR's anisotropic kernels (Yu & Turk 2013): each particle becomes an ellipsoid shaped like the
// spread of its neighbours, flat along a surface and round inside, so that the surface the spheres
// make is a sheet rather than a field of bumps. One invocation per sorted slot of the renderer's
// grid over the particles (neighbours of consecutive slots are the same cells, and their
// positions, gathered by anisotropy_gather.comp, lie together), written per particle, where the
// draw reads them.
#include "common/core.glsl"
#include "common/grid.glsl"

#include "common/anisotropy_pass.glsl"

// Below this many neighbours a covariance says little about a surface: a sphere.
const uint kShapedFrom = 8u;

// One Jacobi rotation in the plane (p, q) of a symmetric 3×3 (diagonal app, aqq; off-diagonal
// apq, and arp, arq with the third index r), zeroing apq; vp and vq are columns p and q of the
// eigenvectors so far (Numerical Recipes' formulation).
void rotate(inout float app, inout float aqq, inout float apq, inout float arp, inout float arq,
            inout vec3 vp, inout vec3 vq) {
  if (abs(apq) < 1e-20) return;
  const float theta = (aqq - app) / (2.0 * apq);
  const float t = (theta >= 0.0 ? 1.0 : -1.0) / (abs(theta) + sqrt(theta * theta + 1.0));
  const float c = inversesqrt(t * t + 1.0), s = t * c;
  app -= t * apq;
  aqq += t * apq;
  apq = 0.0;
  const float rp = arp, rq = arq;
  arp = c * rp - s * rq;
  arq = s * rp + c * rq;
  const vec3 p = vp, q = vq;
  vp = c * p - s * q;
  vq = s * p + c * q;
}

// Eigenvalues (returned) and eigenvectors (V's columns) of the symmetric matrix with diagonal
// `diagonal` and off-diagonal (xy, xz, yz) `off`, by cyclic Jacobi sweeps: a 3×3 converges to
// float precision within four.
vec3 symmetric_eigen(vec3 diagonal, vec3 off, out mat3 V) {
  float a00 = diagonal.x, a11 = diagonal.y, a22 = diagonal.z;
  float a01 = off.x, a02 = off.y, a12 = off.z;
  vec3 v0 = vec3(1, 0, 0), v1 = vec3(0, 1, 0), v2 = vec3(0, 0, 1);
  for (int sweep = 0; sweep < 4; ++sweep) {
    if (abs(a01) + abs(a02) + abs(a12) <= 1e-7 * (abs(a00) + abs(a11) + abs(a22))) break;
    rotate(a00, a11, a01, a02, a12, v0, v1);
    rotate(a00, a22, a02, a01, a12, v0, v2);
    rotate(a11, a22, a12, a01, a02, v1, v2);
  }
  V = mat3(v0, v1, v2);
  return vec3(a00, a11, a22);
}

// How far p (at `offset` into its cell, along one axis) is from the cell `step` cells away.
float gap(float offset, int step, float cell_size) {
  if (step == 0) return 0.0;
  return step > 0 ? float(step) * cell_size - offset : offset - float(step + 1) * cell_size;
}

void main() {
  const uint k = invocation();
  if (k >= a.particle_count) return;
  const uint i = a.order.v[k];
  const vec3 p = a.sorted_position.v[k].xyz;
  const ivec3 dims = a.dims.xyz;
  const uint c = a.sorted_cell.v[k];
  const uint row = uint(dims.x), layer = row * uint(dims.y);
  const ivec3 cell = ivec3(c % row, (c % layer) / row, c / layer);
  const float inv_search2 = 1.0 / (a.search_radius * a.search_radius);
  const float inv_radius = 1.0 / a.radius;

  // Weighted by 1 − (d/R)³ (Yu & Turk); offsets in particle radii keep the sums near 1.
  float total = 0.0;
  vec3 mean = vec3(0.0);
  vec3 spread_diagonal = vec3(0.0), spread_off = vec3(0.0);  // Σ w d dᵀ: xx yy zz, xy xz yz
  uint found = 0u, examined = 0u;
  // The rows of cells (along x) within reach of p: one range of sorted slots each, those wholly
  // farther than the search radius across y and z left out; at most max_candidates slots in all.
  const float cell_size = 0.5 * a.search_radius, search2 = a.search_radius * a.search_radius;
  const vec3 in_cell = p - (a.origin.xyz + vec3(cell) * cell_size);  // 0 to cell_size inside
  const int x0 = max(cell.x - 2, 0), x1 = min(cell.x + 2, dims.x - 1);
  for (int dz = -2; dz <= 2 && examined < a.max_candidates; ++dz) {
    const int z = cell.z + dz;
    if (z < 0 || z >= dims.z) continue;
    const float gap_z = gap(in_cell.z, dz, cell_size);
    for (int dy = -2; dy <= 2 && examined < a.max_candidates; ++dy) {
      const int y = cell.y + dy;
      if (y < 0 || y >= dims.y) continue;
      const float gap_y = gap(in_cell.y, dy, cell_size);
      if (gap_y * gap_y + gap_z * gap_z >= search2) continue;
      const uint begin = a.cell_start.v[grid_cell_index(ivec3(x0, y, z), dims)];
      const uint end = min(a.cell_start.v[grid_cell_index(ivec3(x1, y, z), dims) + 1u],
                           begin + (a.max_candidates - examined));
      examined += end - begin;
      for (uint j = begin; j < end; ++j) {
        const vec3 d = a.sorted_position.v[j].xyz - p;
        const float x2 = dot(d, d) * inv_search2;
        if (!(x2 < 1.0)) continue;
        const float w = 1.0 - x2 * sqrt(x2);
        const vec3 scaled = d * inv_radius;
        total += w;
        mean += w * scaled;
        spread_diagonal += w * scaled * scaled;
        spread_off += w * scaled.xxy * scaled.yzz;
        ++found;
      }
    }
  }
  // The particle itself is among them, unless a clump filled the cap before its own cell.
  const uint neighbours = max(found, 1u) - 1u;
  const bool spray = neighbours < a.spray_below;
  if (total > 0.0) mean /= total;

  vec3 axes = vec3(1.0);  // in particle radii
  mat3 V = mat3(1.0);
  if (!spray && neighbours >= kShapedFrom) {
    vec3 sigma = symmetric_eigen(spread_diagonal / total - mean * mean,
                                 spread_off / total - mean.xxy * mean.yzz, V);
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
