// Push constants of the particle draws; mirrored by DrawConstants in frame_params.h.
layout(push_constant, std430) uniform Draw {
  Frame frame;
  Vec4s position;
  Vec4s velocity;
  Uints depth;      // MC: per pixel, the nearest surface's view distance (float bits)
  Uints thickness;  // MC: per pixel, the fluid crossed, in kThicknessUnit
  Floats density_ratio;  // points mode: ρ/ρ0 per particle, when colouring by density
} draw;
