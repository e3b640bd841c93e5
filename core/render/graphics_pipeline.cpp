#include "graphics_pipeline.h"

#include "fluidcast/gpu/shader_module.h"
#include "fluidcast/gpu/vk_check.h"

namespace fluidcast::render {
namespace {

// Every pipeline's layout: the DrawConstants as push constants, nothing else.
gpu::UniquePipelineLayout draw_constants_layout(VkDevice device) {
  const VkPushConstantRange range{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                                  sizeof(DrawConstants)};
  VkPipelineLayoutCreateInfo info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  info.pushConstantRangeCount = 1;
  info.pPushConstantRanges = &range;
  VkPipelineLayout layout;
  FLUIDCAST_VK_CHECK(vkCreatePipelineLayout(device, &info, nullptr, &layout));
  return gpu::UniquePipelineLayout(device, layout);
}

VkPipelineShaderStageCreateInfo stage_info(VkShaderStageFlagBits stage, VkShaderModule module) {
  VkPipelineShaderStageCreateInfo info{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  info.stage = stage;
  info.module = module;
  info.pName = "main";
  return info;
}

std::vector<VkPipelineColorBlendAttachmentState> blend_attachments(const PipelineOptions& options) {
  std::vector<VkPipelineColorBlendAttachmentState> attachments;
  for (const Blend kind : options.attachments) {
    VkPipelineColorBlendAttachmentState attachment{};
    attachment.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                                VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    if (kind != Blend::replace) {
      // Factors of one: a sum, or (ignored by the minimum) what min compares.
      attachment.blendEnable = VK_TRUE;
      attachment.srcColorBlendFactor = attachment.dstColorBlendFactor = VK_BLEND_FACTOR_ONE;
      attachment.srcAlphaBlendFactor = attachment.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
      attachment.colorBlendOp = attachment.alphaBlendOp =
          kind == Blend::add ? VK_BLEND_OP_ADD : VK_BLEND_OP_MIN;
    }
    attachments.push_back(attachment);
  }
  return attachments;
}

}  // namespace

GraphicsPipeline::GraphicsPipeline(gpu::Context& context, VkRenderPass render_pass,
                                   std::span<const std::uint32_t> vertex_spirv,
                                   std::span<const std::uint32_t> fragment_spirv,
                                   PipelineOptions options) {
  const VkDevice device = context.device();
  layout_ = draw_constants_layout(device);
  const auto vertex = gpu::make_shader_module(device, vertex_spirv);
  const auto fragment = gpu::make_shader_module(device, fragment_spirv);
  const VkPipelineShaderStageCreateInfo stages[2] = {
      stage_info(VK_SHADER_STAGE_VERTEX_BIT, vertex.get()),
      stage_info(VK_SHADER_STAGE_FRAGMENT_BIT, fragment.get())};

  VkPipelineVertexInputStateCreateInfo vertex_input{
      VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  VkPipelineInputAssemblyStateCreateInfo assembly{
      VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  VkPipelineViewportStateCreateInfo viewport{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  viewport.viewportCount = 1;
  viewport.scissorCount = 1;
  VkPipelineRasterizationStateCreateInfo raster{
      VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  raster.polygonMode = VK_POLYGON_MODE_FILL;
  raster.cullMode = VK_CULL_MODE_NONE;
  raster.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo multisample{
      VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  const std::vector<VkPipelineColorBlendAttachmentState> attachments = blend_attachments(options);
  VkPipelineColorBlendStateCreateInfo blend{
      VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  blend.attachmentCount = static_cast<std::uint32_t>(attachments.size());
  blend.pAttachments = attachments.data();
  const VkDynamicState dynamic_states[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  const VkPipelineDynamicStateCreateInfo dynamic{
      VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO, nullptr, 0, 2, dynamic_states};

  VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  info.stageCount = 2;
  info.pStages = stages;
  info.pVertexInputState = &vertex_input;
  info.pInputAssemblyState = &assembly;
  info.pViewportState = &viewport;
  info.pRasterizationState = &raster;
  info.pMultisampleState = &multisample;
  info.pColorBlendState = &blend;
  info.pDynamicState = &dynamic;
  info.layout = layout_.get();
  info.renderPass = render_pass;
  VkPipeline raw_pipeline;
  FLUIDCAST_VK_CHECK(
      vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &raw_pipeline));
  pipeline_ = gpu::UniquePipeline(device, raw_pipeline);
}

void GraphicsPipeline::draw(VkCommandBuffer commands, const DrawConstants& draw,
                            std::uint32_t vertices) const {
  if (vertices == 0) return;
  vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_.get());
  vkCmdPushConstants(commands, layout_.get(),
                     VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(draw),
                     &draw);
  vkCmdDraw(commands, vertices, 1, 0, 0);
}

void GraphicsPipeline::draw_indirect(VkCommandBuffer commands, const DrawConstants& constants,
                                     VkBuffer indirect) const {
  vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_.get());
  vkCmdPushConstants(commands, layout_.get(),
                     VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                     sizeof(constants), &constants);
  vkCmdDrawIndirect(commands, indirect, 0, 1, sizeof(VkDrawIndirectCommand));
}

}  // namespace fluidcast::render
