// The renderer's per-frame block (written with vkCmdUpdateBuffer), mirrored by FrameParams in
// core/render/frame_params.h. Loaded whole: see the lavapipe note in sim_kernels.glsl.
#extension GL_EXT_buffer_reference : require

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer Vec4s { vec4 v[]; };

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer Frame {
  mat4 view;
  mat4 projection;
  vec4 light_direction;  // view space, towards the light
  vec4 slow_colour;      // points mode: at rest
  vec4 fast_colour;      // points mode: at full_speed and above
  float particle_radius; // m
  float full_speed;      // m/s
};

layout(push_constant, std430) uniform Draw {
  Frame frame;
  Vec4s position;
  Vec4s velocity;
} draw;
