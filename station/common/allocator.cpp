#include "station/common/allocator.hpp"

#include <malloc.h>

namespace station {

void keep_freed_memory_for_reuse() {
  constexpr int kMmapThreshold = 32 << 20;  // glibc's largest dynamic threshold (mallopt(3))
  constexpr int kTrimThreshold = 64 << 20;
  mallopt(M_MMAP_THRESHOLD, kMmapThreshold);
  mallopt(M_TRIM_THRESHOLD, kTrimThreshold);
}

}  // namespace station
