// Push constants of SSFR's anisotropy passes (anisotropy_gather.comp, anisotropy.comp); mirrored
// by AnisotropyConstants in core/render/frame_params.h.
layout(push_constant, std430) uniform Anisotropy {
  vec4 origin;         // the grid's, xyz
  ivec4 dims;          // the grid's cells per axis, xyz
  Vec4s position;      // the particles as drawn
  Uints order;         // the grid: sorted slot → particle
  Uints cell_start;
  Uints sorted_cell;
  Vec4s sorted_position;  // per sorted slot, its particle's position
  Vec4s centre;        // out, per particle: the smoothed centre; w: 1 for spray, else 0
  Vec4s shape;         // out, two per particle: G (the inverse shape, world → unit sphere) xx, xy,
                       // xz, yy, then yz, zz, the longest semi-axis, 0
  uint particle_count;
  float radius;        // of a particle, m
  float search_radius; // of the neighbourhood, m
  float max_stretch;   // the largest ratio of the longest to the shortest axis
  float centre_smoothing;  // λ: how far each centre moves to its neighbours' weighted mean
  uint spray_below;    // fewer neighbours than this: spray
  uint max_candidates; // candidates examined per particle, at most (a clump's cost stays bounded)
} a;
