// The process's memory, as the bench reports it beside its times.
#pragma once

#include <cstdint>

namespace tilesplat::cli {

// The process's peak resident memory since the last reset_peak_memory(), in bytes (Linux: VmHWM,
// reset through /proc/self/clear_refs after returning freed heap memory to the system; 0 where that
// cannot be read).
void reset_peak_memory();
uint64_t peak_memory_bytes();
uint64_t resident_memory_bytes();

}  // namespace tilesplat::cli
