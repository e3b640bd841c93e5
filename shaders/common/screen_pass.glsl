// Push constants of the screen-space compute passes; mirrored by ScreenConstants in
// frame_params.h.
layout(push_constant, std430) uniform Screen {
  Frame frame;
  Floats depth_in;    // view distance per pixel, +inf where there is no fluid
  Floats depth_out;
  Uints thickness;    // metres (float bits) or, when thickness_in_units, kThicknessUnit (int)
  Uints scene;        // the background, RGBA8 per pixel
  Uints image;        // the finished frame, RGBA8 per pixel
  uint axis;          // smoothing: 0 along x, 1 along y
  uint narrow_range;  // smoothing: 1 for Truong & Yuksel's narrow-range filter, 0 for bilateral
  uint thickness_in_units;  // 1: Marching Cubes' integer sums; 0: the spheres' blended metres
} screen;

#include "common/dispatch.glsl"
