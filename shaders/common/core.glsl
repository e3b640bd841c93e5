// Included first by every compute shader: buffer reference types and invocation indexing.
// Buffers are reached through device addresses (push constants or the parameter block), so no
// shader has descriptor sets. The workgroup size is specialisation constant 0, set by the host.
#extension GL_EXT_buffer_reference : require

layout(local_size_x_id = 0) in;

layout(buffer_reference, std430, buffer_reference_align = 16) buffer Vec4s { vec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) buffer Vec2s { vec2 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Floats { float v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Uints { uint v[]; };

// Large dispatches spill from x into y (see ComputePipeline::dispatch).
uint linear_group() { return gl_WorkGroupID.x + gl_NumWorkGroups.x * gl_WorkGroupID.y; }
uint invocation() { return linear_group() * gl_WorkGroupSize.x + gl_LocalInvocationID.x; }
