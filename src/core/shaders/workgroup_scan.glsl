// Inclusive prefix sum of one value per invocation over a workgroup, in shared memory
// (Hillis & Steele 1986, ping-pong arrays): the ordered compaction's scans (compact.glsl) and the
// flare split plan (flare_split_plan.comp). Before including, define
// GLINT_WORKGROUP_SCAN_MAX_THREADS, the most invocations the including kernel's workgroup has.
shared uint s_workgroup_scan[2][GLINT_WORKGROUP_SCAN_MAX_THREADS];

// Inclusive prefix sum of `n` over the workgroup's invocations (all must call it); returns this
// invocation's sum, `total` the workgroup's.
uint workgroup_scan(uint n, out uint total) {
  const uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  const uint t = gl_LocalInvocationIndex;
  s_workgroup_scan[0][t] = n;
  barrier();
  uint src = 0u;
  for (uint d = 1u; d < threads; d <<= 1u) {
    uint v = s_workgroup_scan[src][t];
    if (t >= d) v += s_workgroup_scan[src][t - d];
    s_workgroup_scan[src ^ 1u][t] = v;
    barrier();
    src ^= 1u;
  }
  const uint mine = s_workgroup_scan[src][t];
  total = s_workgroup_scan[src][threads - 1u];
  barrier();  // the arrays are rewritten by the next call
  return mine;
}
