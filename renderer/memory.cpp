// glibc's allocator told to keep freed memory for reuse (see memory.hpp).
#include "renderer/memory.hpp"

#include <climits>

#include <malloc.h>

namespace sb {

void keep_freed_memory() {
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, INT_MAX);
}

}  // namespace sb
