#version 460
#extension GL_GOOGLE_include_directive : require
// The first level of the ordered compaction's two-level scan (the light cull's; the object cull
// runs its own, object_cull_scan.comp): workgroup k scans the bit counts of the tile of `threads`
// consecutive 64-item groups into each group's z and writes the tile's total into its first
// group's w (compact.glsl, compact_tile_scan). The user's top-level scan then scans the tile totals.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#define COMPACT_GROUPS_BINDING 0
#include "compact.glsl"

layout(push_constant) uniform Push { GlintCompactPush pc; };

void main() { compact_tile_scan(pc.count); }
