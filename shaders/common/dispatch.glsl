// Invocation indexing of every compute shader. The workgroup size is specialisation constant 0,
// set by the host (ComputePipeline); it is declared here, before anything reads gl_WorkGroupSize,
// which means (1, 1, 1) until it is.
layout(local_size_x_id = 0) in;

// Large dispatches spill from x into y (see ComputePipeline::dispatch).
uint linear_group() { return gl_WorkGroupID.x + gl_NumWorkGroups.x * gl_WorkGroupID.y; }
uint invocation() { return linear_group() * gl_WorkGroupSize.x + gl_LocalInvocationID.x; }
