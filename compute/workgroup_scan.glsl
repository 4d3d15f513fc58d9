// A workgroup-wide exclusive scan built from subgroup scans. Works for any subgroup size from 4
// to 128 because it only relies on gl_SubgroupID / gl_NumSubgroups, never on a fixed width.
const uint SCAN_THREADS = 256;
const uint SCAN_ITEMS = 4;
const uint SCAN_BLOCK = SCAN_THREADS * SCAN_ITEMS;

layout(local_size_x = 256) in;

shared uint s_subgroup_sums[SCAN_THREADS / 4];  // enough for the smallest subgroup size (4)
shared uint s_workgroup_total;

// Returns the exclusive prefix of `value` over the workgroup in (subgroup id, lane) order and the
// workgroup total. Must be called by every invocation in uniform control flow.
uint workgroup_exclusive_scan(uint value, out uint total) {
  uint inclusive = subgroupInclusiveAdd(value);
  if (gl_SubgroupInvocationID == gl_SubgroupSize - 1) s_subgroup_sums[gl_SubgroupID] = inclusive;
  barrier();
  if (gl_LocalInvocationIndex == 0) {
    uint running = 0;
    for (uint s = 0; s < gl_NumSubgroups; ++s) {
      uint t = s_subgroup_sums[s];
      s_subgroup_sums[s] = running;
      running += t;
    }
    s_workgroup_total = running;
  }
  barrier();
  total = s_workgroup_total;
  return s_subgroup_sums[gl_SubgroupID] + inclusive - value;
}
