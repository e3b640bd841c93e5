#version 460
#extension GL_GOOGLE_include_directive : require
// The finished frame (RGBA8 per pixel) into the planes a JPEG holds: Y, and Cb and Cr averaged over
// 2×2 pixels (4:2:0), full-range BT.601 as JFIF defines it: what TurboJPEG would do on the CPU,
// done here so that 1.5 bytes a pixel come back instead of 4 and the encoder only compresses.
// One invocation per block of 8×2 pixels: its Y rows are two words each, its Cb and Cr one word,
// so every store is a whole word. Pixels beyond the frame repeat its edge (codec::ImageYuv420).
#include "common/core.glsl"

layout(push_constant, std430) uniform Convert {
  Uints image;        // RGBA8 per pixel, `width` per row
  Uints planes;       // Y, then Cb, then Cr (codec::ImageYuv420's layout)
  uint width;
  uint height;
  uint luma_stride;   // bytes per Y row, a multiple of 8
  uint chroma_rows;   // rows of Cb and of Cr; Y has twice as many
} pass;

vec3 rgb_at(uint x, uint y) {
  const uint cx = min(x, pass.width - 1), cy = min(y, pass.height - 1);
  return unpackUnorm4x8(pass.image.v[cy * pass.width + cx]).rgb * 255.0;
}

float luma(vec3 c) { return dot(c, vec3(0.299, 0.587, 0.114)); }
float blue_difference(vec3 c) { return 128.0 + dot(c, vec3(-0.168736, -0.331264, 0.5)); }
float red_difference(vec3 c) { return 128.0 + dot(c, vec3(0.5, -0.418688, -0.081312)); }

// Four values, rounded and clamped to bytes, in one word (the first in the lowest byte).
uint pack_bytes(vec4 values) {
  const uvec4 b = uvec4(clamp(floor(values + 0.5), 0.0, 255.0));
  return b.x | (b.y << 8) | (b.z << 16) | (b.w << 24);
}

void main() {
  const uint blocks_per_row = pass.luma_stride / 8;
  const uint block = invocation();
  if (block >= blocks_per_row * pass.chroma_rows) return;
  const uint bx = block % blocks_per_row, by = block / blocks_per_row;
  const uint x0 = 8 * bx, y0 = 2 * by;

  vec3 c[2][8];
  for (uint r = 0; r < 2; ++r) {
    for (uint k = 0; k < 8; ++k) c[r][k] = rgb_at(x0 + k, y0 + r);
  }
  const uint luma_words = pass.luma_stride / 4;
  for (uint r = 0; r < 2; ++r) {
    for (uint half_block = 0; half_block < 2; ++half_block) {
      const uint k = 4 * half_block;
      const vec4 y = vec4(luma(c[r][k]), luma(c[r][k + 1]), luma(c[r][k + 2]), luma(c[r][k + 3]));
      pass.planes.v[(y0 + r) * luma_words + 2 * bx + half_block] = pack_bytes(y);
    }
  }
  vec3 mean[4];
  for (uint k = 0; k < 4; ++k) {
    mean[k] = 0.25 * (c[0][2 * k] + c[0][2 * k + 1] + c[1][2 * k] + c[1][2 * k + 1]);
  }
  const uint chroma_words = luma_words / 2;
  const uint luma_plane = luma_words * 2 * pass.chroma_rows;
  const uint chroma_plane = chroma_words * pass.chroma_rows;
  const uint at = by * chroma_words + bx;
  pass.planes.v[luma_plane + at] =
      pack_bytes(vec4(blue_difference(mean[0]), blue_difference(mean[1]),
                      blue_difference(mean[2]), blue_difference(mean[3])));
  pass.planes.v[luma_plane + chroma_plane + at] =
      pack_bytes(vec4(red_difference(mean[0]), red_difference(mean[1]), red_difference(mean[2]),
                      red_difference(mean[3])));
}
