#include "process_memory.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <cstdlib>
#include <fstream>
#include <string>

namespace tilesplat::cli {

namespace {

uint64_t proc_status_kib(const char* field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  const std::string prefix = std::string(field) + ":";
  while (std::getline(status, line))
    if (line.starts_with(prefix)) return std::strtoull(line.c_str() + prefix.size(), nullptr, 10);
  return 0;
}

}  // namespace

void reset_peak_memory() {
#if defined(__GLIBC__)
  // Heap memory freed by earlier work goes back to the system first: otherwise the next step could
  // reuse it without the resident size growing, and its peak would read low.
  malloc_trim(0);
#endif
  std::ofstream("/proc/self/clear_refs") << "5";
}
uint64_t peak_memory_bytes() {
  return proc_status_kib("VmHWM") * 1024;
}
uint64_t resident_memory_bytes() {
  return proc_status_kib("VmRSS") * 1024;
}

}  // namespace tilesplat::cli
