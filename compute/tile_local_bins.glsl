// The tile-local sort's bin table (one uint buffer): how many bins are over the shared-memory
// capacity, the indirect dispatch of the big-bin variant (a workgroup per listed bin, up to the push
// constant's cap), then the key count of each bin, then each bin's end (the scan writes its start
// there and the scatter advances it past the bin's last key), then the list of the bins over the
// capacity.
const uint BINS_BIG = 0;
const uint BINS_BIG_ARGS = 1;  // 3 uints
const uint BINS_COUNTS = 4;  // bin_count uints; the ends and the big-bin list follow them
