// The renderer's per-frame block (written with vkCmdUpdateBuffer), mirrored by FrameParams in
// core/render/frame_params.h. Loaded whole: see the lavapipe note in sim_kernels.glsl.
#extension GL_EXT_buffer_reference : require

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer Vec4s { vec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Uints { uint v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Floats { float v[]; };

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer Frame {
  mat4 view;
  mat4 projection;
  mat4 inverse_view;
  vec4 light_direction;  // view space, towards the light
  vec4 slow_colour;      // points mode: at rest
  vec4 fast_colour;      // points mode: at full_speed and above
  vec4 tank_min;         // m
  vec4 tank_max;
  vec4 absorption;       // SSFR: Beer–Lambert coefficients per metre of water, rgb
  float particle_radius; // m
  float full_speed;      // m/s
  float smoothing_radius;  // SSFR: of the depth filter, m (view-invariant)
  float depth_falloff;     // SSFR: depth difference that halves a neighbour's weight, m
  uint width;
  uint height;
  uint colour_by_density;  // points mode: 1 colours by ρ/ρ0 instead of speed
  float density_span;      // points mode: ρ/ρ0 = 1 ± span gets slow and fast colour
};
