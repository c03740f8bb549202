// The light cull's outputs, written the same way by both of its paths (docs/OCCLUSION.md): the
// four-dispatch path's scatter (light_cull_scatter.comp) and top scan (light_cull_scan.comp), and
// the one-workgroup cull (light_cull.comp built with GLINT_CULL_ONE_GROUP). The includer declares
// the buffers it writes before including: `instance_words` (GlintFlareInstance[] as uvec4 words,
// bits stored as they are) for cull_store_instance, `indirect` (GlintFlareIndirect) and `stats`
// (GlintFlareStats) for cull_store_arguments.
#ifndef GLINT_LIGHT_CULL_OUTPUTS_GLSL
#define GLINT_LIGHT_CULL_OUTPUTS_GLSL

#ifdef GLINT_CULL_STORES_INSTANCES
// Instance `slot` for light i: its record (centre.xy, fraction, ndc z) and its light words
// l0 = (position, intensity), l1 = (colour, size_px), element from (element, enabled, reserved x2).
// GlintFlareInstance: (centre, size_px, fraction), (colour, intensity),
// (light_index, element, ndc_depth, reserved).
void cull_store_instance(uint slot, uint i, vec4 record, vec4 l0, vec4 l1, uint element) {
  instance_words[3u * slot] = floatBitsToUint(vec4(record.xy, l1.w, record.z));
  instance_words[3u * slot + 1u] = floatBitsToUint(vec4(l1.xyz, l0.w));
  instance_words[3u * slot + 2u] = uvec4(i, element, floatBitsToUint(record.w), 0u);
}
#endif

#ifdef GLINT_CULL_STORES_ARGUMENTS
// The indirect arguments and statistics of a cull of `total` lights, `visible` of them visible
// (at most `capacity` written), with the counts of the other states.
void cull_store_arguments(uint total, uint visible, uint frustum, uint occluded, uint disabled, uint capacity,
                          uint vertex_count, uint groups_per_instance, uint max_group_count_x) {
  const uint written = min(visible, capacity);
  indirect.vertex_count = vertex_count;
  indirect.instance_count = written;
  indirect.first_vertex = 0u;
  indirect.first_instance = 0u;
  // instances x groups_per_instance workgroups, as rows of at most maxComputeWorkGroupCount[0]
  // (GlintFlareIndirect says how a kernel recovers its linear workgroup index).
  const uint groups = written * groups_per_instance;
  indirect.group_count_x = min(groups, max_group_count_x);
  indirect.group_count_y = max(1u, (groups + max_group_count_x - 1u) / max_group_count_x);
  indirect.group_count_z = 1u;
  indirect.reserved = 0u;
  stats.total = total;
  stats.frustum_culled = frustum;
  stats.occluded = occluded;
  stats.visible = visible;
  stats.overflow = visible - written;
  stats.disabled = disabled;
  stats.reserved0 = 0u;
  stats.reserved1 = 0u;
}
#endif

#endif
