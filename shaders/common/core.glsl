// Included first by the simulation's compute shaders: buffer reference types and invocation
// indexing. Buffers are reached through device addresses (push constants or the parameter
// block), so no shader has descriptor sets.
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_control_flow_attributes : require

#include "common/dispatch.glsl"

layout(buffer_reference, std430, buffer_reference_align = 16) buffer Vec4s { vec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) buffer Vec2s { vec2 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Floats { float v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Uints { uint v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Uvec4s { uvec4 v[]; };
