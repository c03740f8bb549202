// Lens-flare raster path: the graphics pipeline (dynamic rendering, additive blending) and
// LensFlare::record_raster(), one instanced indirect draw. docs/FLARE.md, "Raster (record_raster)".
#include "flare/flare_impl.h"

namespace glint {

using namespace flare_detail;
using detail::concat;

void LensFlare::Impl::make_raster_pipeline() {
  if (!context->state().dynamic_rendering) {
    raster_unavailable = "VkPhysicalDeviceVulkan13Features::dynamicRendering is not enabled on the device";
    return;
  }
  if (!context->state().graphics_queue) {
    raster_unavailable = concat("queue family ", context->queue_family_index(), " has no graphics capability");
    return;
  }
  if (!(detail::format_features(*context, format) & VK_FORMAT_FEATURE_2_COLOR_ATTACHMENT_BLEND_BIT)) {
    raster_unavailable = concat("the device cannot blend into ", detail::format_name(format));
    return;
  }
  auto& s = context->state();
  VkDescriptorSetLayoutBinding b[2] = {
      {0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr},
      {1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr},
  };
  VkDescriptorSetLayoutCreateInfo sl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  sl.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;  // pushed with each draw
  sl.bindingCount = 2;
  sl.pBindings = b;
  detail::vk_check(vkCreateDescriptorSetLayout(device, &sl, nullptr, &raster_set_layout),
                   "vkCreateDescriptorSetLayout");
  s.count_object();
  VkPushConstantRange range{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(GlintFlarePush)};
  VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pl.setLayoutCount = 1;
  pl.pSetLayouts = &raster_set_layout;
  pl.pushConstantRangeCount = 1;
  pl.pPushConstantRanges = &range;
  detail::vk_check(vkCreatePipelineLayout(device, &pl, nullptr, &raster_layout), "vkCreatePipelineLayout");
  s.count_object();

  VkShaderModule modules[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
  const char* ids[2] = {"flare_vert_main", "flare_frag_main"};
  try {
    for (int i = 0; i < 2; ++i) {
      const detail::KernelBinary* bin = detail::find_kernel(ids[i]);
      if (!bin) throw Error(ErrorCode::vulkan_failure, concat("kernel '", ids[i], "' is not embedded in this build"));
      VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
      sm.codeSize = bin->size_bytes;
      sm.pCode = bin->code;
      detail::vk_check(vkCreateShaderModule(device, &sm, nullptr, &modules[i]), "vkCreateShaderModule");
    }
    VkPipelineShaderStageCreateInfo stages[2] = {{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
                                                 {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = modules[0];
    stages[0].pName = "main";
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = modules[1];
    stages[1].pName = "main";
    VkPipelineVertexInputStateCreateInfo vertex_input{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    VkPipelineInputAssemblyStateCreateInfo assembly{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo viewport{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = VK_CULL_MODE_NONE;  // billboards: both windings
    raster.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    // Premultiplied colour, additive: dst.rgb += src.rgb (ONE, ONE). Alpha is not written: flares
    // add light and leave whatever the image keeps in alpha.
    VkPipelineColorBlendAttachmentState blend{};
    blend.blendEnable = VK_TRUE;
    blend.srcColorBlendFactor = VK_BLEND_FACTOR_ONE;
    blend.dstColorBlendFactor = VK_BLEND_FACTOR_ONE;
    blend.colorBlendOp = VK_BLEND_OP_ADD;
    blend.srcAlphaBlendFactor = VK_BLEND_FACTOR_ZERO;
    blend.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    blend.alphaBlendOp = VK_BLEND_OP_ADD;
    blend.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT;
    VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    cb.attachmentCount = 1;
    cb.pAttachments = &blend;
    VkDynamicState dyn[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamic.dynamicStateCount = 2;
    dynamic.pDynamicStates = dyn;
    VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
    rendering.colorAttachmentCount = 1;
    rendering.pColorAttachmentFormats = &format;
    VkGraphicsPipelineCreateInfo gp{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    gp.pNext = &rendering;
    gp.stageCount = 2;
    gp.pStages = stages;
    gp.pVertexInputState = &vertex_input;
    gp.pInputAssemblyState = &assembly;
    gp.pViewportState = &viewport;
    gp.pRasterizationState = &raster;
    gp.pMultisampleState = &ms;
    gp.pColorBlendState = &cb;
    gp.pDynamicState = &dynamic;
    gp.layout = raster_layout;
    detail::vk_check(vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &gp, nullptr, &raster_pipeline),
                     "vkCreateGraphicsPipelines (flare)");
    s.count_object();
  } catch (...) {
    for (VkShaderModule m : modules) {
      if (m) vkDestroyShaderModule(device, m, nullptr);
    }
    throw;
  }
  for (VkShaderModule m : modules) vkDestroyShaderModule(device, m, nullptr);
}
void LensFlare::record_raster(VkCommandBuffer cmd, Image& color, Buffer& instances, Buffer& indirect,
                              const FlareConfig& config, Profiler* profiler) {
  detail::check_command_buffer("LensFlare::record_raster", cmd);
  Impl& m = *impl_;
  m.check_inputs("LensFlare::record_raster", color, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT,
                 "VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT", instances, indirect, config);
  if (!m.raster_unavailable.empty()) {
    throw Error(
        m.raster_unavailable.find("blend") != std::string::npos ? ErrorCode::unsupported_format : ErrorCode::no_device,
        concat("LensFlare::record_raster: ", m.raster_unavailable, "; use record_compute"));
  }
  if (!config.enabled || config.intensity == 0.0f) return;  // adds nothing: record nothing
  const detail::Bindings bindings{instances, m.atlas_binding()};
  detail::check_bindings(m.raster_types, bindings, "flare raster");  // before anything is recorded
  m.record_setup(cmd);

  detail::Barriers b;
  b.use(instances, VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
  b.use(indirect, kIndirect, VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
  b.use(m.atlas_image.state, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
        VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, GLINT_FLARE_ATLAS_LEVELS);
  b.use(color, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
        VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
  b.flush(cmd);

  VkRenderingAttachmentInfo attachment{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  attachment.imageView = color.view;
  attachment.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  attachment.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
  attachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  VkRenderingInfo rendering{VK_STRUCTURE_TYPE_RENDERING_INFO};
  rendering.renderArea = {{0, 0}, m.extent};
  rendering.layerCount = 1;
  rendering.colorAttachmentCount = 1;
  rendering.pColorAttachments = &attachment;
  vkCmdBeginRendering(cmd, &rendering);
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, m.raster_pipeline);
  VkViewport viewport{0.0f, 0.0f, float(m.extent.width), float(m.extent.height), 0.0f, 1.0f};
  VkRect2D scissor{{0, 0}, m.extent};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &scissor);
  detail::push_descriptors(m.context->state().cmd_push_descriptor_set, cmd, VK_PIPELINE_BIND_POINT_GRAPHICS,
                           m.raster_layout, m.raster_types, bindings, "flare raster");
  const GlintFlarePush p = m.push(config);
  vkCmdPushConstants(cmd, m.raster_layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(p), &p);
  vkCmdDrawIndirect(cmd, indirect.buffer, indirect.offset + offsetof(GlintFlareIndirect, vertex_count), 1,
                    sizeof(VkDrawIndirectCommand));
  vkCmdEndRendering(cmd);
  if (profiler) profiler->mark(cmd, "flare raster");
}
}  // namespace glint
