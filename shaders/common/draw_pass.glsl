// Push constants of the particle draws; mirrored by DrawConstants in frame_params.h.
layout(push_constant, std430) uniform Draw {
  Frame frame;
  Vec4s position;
  Vec4s velocity;
  Floats density_ratio;  // points mode: ρ/ρ0 per particle, when colouring by density
  Vec4s shape;           // SSFR (its compute splat): two vec4 per particle, anisotropy.comp's
  uint ellipsoids;       // SSFR: 1 when `position` and `shape` are anisotropy.comp's
} draw;
