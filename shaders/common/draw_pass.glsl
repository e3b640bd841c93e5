// Push constants of the rasterized draws (the scene, the Marching Cubes mesh); mirrored by
// DrawConstants in frame_params.h.
layout(push_constant, std430) uniform Draw {
  Frame frame;
  Vec4s vertices;  // the mesh: position and normal per vertex, as mc_triangles.comp wrote them
} draw;
