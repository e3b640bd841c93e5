// Push constants of the screen-space compute passes; mirrored by ScreenConstants in
// frame_params.h.
layout(push_constant, std430) uniform Screen {
  Frame frame;
  Floats depth_in;    // view distance per pixel, +inf where there is no fluid
  Floats depth_out;
  Floats thickness;   // the water crossed, m
  Floats spray;       // the spray crossed, in particle diameters
  Uints scene;        // the background, RGBA8 per pixel
  Uints image;        // the finished frame, RGBA8 per pixel
  uint axis;          // smoothing: 0 along x, 1 along y
  uint narrow_range;  // smoothing: 1 for Truong & Yuksel's narrow-range filter, 0 for bilateral
} screen;

#include "common/dispatch.glsl"
