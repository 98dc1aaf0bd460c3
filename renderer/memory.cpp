// glibc's allocator told to keep freed memory for reuse, the process's memory readings, and the
// memory check (see memory.hpp).
#include "renderer/memory.hpp"

#include <climits>
#include <fstream>
#include <sstream>
#include <vector>

#include <fmt/format.h>
#include <malloc.h>
#include <sys/resource.h>

#include "renderer/error.hpp"

namespace sb {

namespace {

/// Limits at or above this are "no limit" (cgroup v1 writes 2^63 rounded down to a page).
constexpr uint64_t kUnlimited = uint64_t{1} << 62;

/// The first line of a file, or nothing.
std::optional<std::string> first_line(const std::string& file) {
  std::ifstream in(file);
  std::string line;
  if (!in || !std::getline(in, line)) return std::nullopt;
  return line;
}

/// A whole decimal number as a file's first line; nothing for "max", a missing file or other text.
std::optional<uint64_t> number_file(const std::string& file) {
  const std::optional<std::string> line = first_line(file);
  if (!line || line->empty() || line->find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
  try {
    return std::stoull(*line);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

/// The memory cgroup of this process as /proc/self/cgroup names it: the v2 path ("0::/path") or
/// the v1 memory controller's ("N:memory:/path").
void read_cgroup(MemorySources& s) {
  std::ifstream in("/proc/self/cgroup");
  std::string v2_path, v1_path;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("0::", 0) == 0) v2_path = line.substr(3);
    const size_t at = line.find(":memory:");
    if (at != std::string::npos) v1_path = line.substr(at + 8);
  }
  // Inside a cgroup namespace (containers) the process's own group is mounted at the root, and the
  // path /proc names may not exist there: try the named group first, then the root.
  struct Candidate {
    std::string limit, usage;
  };
  std::vector<Candidate> candidates;
  if (!v1_path.empty()) {
    for (const std::string& dir : {"/sys/fs/cgroup/memory" + v1_path, std::string("/sys/fs/cgroup/memory")})
      candidates.push_back({dir + "/memory.limit_in_bytes", dir + "/memory.usage_in_bytes"});
  }
  if (!v2_path.empty()) {
    for (const std::string& dir : {"/sys/fs/cgroup" + v2_path, std::string("/sys/fs/cgroup")})
      candidates.push_back({dir + "/memory.max", dir + "/memory.current"});
  }
  for (const Candidate& c : candidates) {
    const std::optional<uint64_t> limit = number_file(c.limit);
    if (!limit) continue;
    if (*limit < kUnlimited) {
      s.cgroup_limit = limit;
      s.cgroup_usage = number_file(c.usage).value_or(0);
      s.cgroup_file = c.limit;
    }
    return;
  }
}

}  // namespace

std::string gib(uint64_t bytes) {
  return fmt::format("{:.2f} GiB", static_cast<double>(bytes) / (1024.0 * 1024.0 * 1024.0));
}

void keep_freed_memory() {
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, INT_MAX);
}

std::optional<uint64_t> proc_kib_field(const char* file, const std::string& key) {
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    if (line.compare(0, key.size() + 1, key + ":") != 0) continue;
    std::istringstream fields(line.substr(key.size() + 1));
    uint64_t kib = 0;
    if (fields >> kib) return kib * 1024;
  }
  return std::nullopt;
}

uint64_t resident_bytes() { return proc_kib_field("/proc/self/status", "VmRSS").value_or(0); }
uint64_t peak_resident_bytes() { return proc_kib_field("/proc/self/status", "VmHWM").value_or(0); }

MemorySources read_memory_sources() {
  MemorySources s;
  s.mem_available = proc_kib_field("/proc/meminfo", "MemAvailable");
  read_cgroup(s);
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY && limit.rlim_cur < kUnlimited) {
    s.address_limit = static_cast<uint64_t>(limit.rlim_cur);
    s.address_used = proc_kib_field("/proc/self/status", "VmSize").value_or(0);
  }
  const struct mallinfo2 heap = mallinfo2();
  s.heap_free = heap.fordblks;
  return s;
}

MemoryBudget memory_budget(const MemorySources& s) {
  MemoryBudget b;
  const auto consider = [&](uint64_t limit, uint64_t used, std::string bound) {
    const uint64_t left = (limit > used ? limit - used : 0) + s.heap_free;
    if (left < b.bytes) b = {left, std::move(bound)};
  };
  if (s.mem_available) consider(*s.mem_available, 0, "the system's available memory (MemAvailable)");
  if (s.cgroup_limit)
    consider(*s.cgroup_limit, s.cgroup_usage, fmt::format("the memory cgroup's limit of {} ({})", gib(*s.cgroup_limit),
                                                          s.cgroup_file));
  if (s.address_limit)
    consider(*s.address_limit, s.address_used,
             fmt::format("the address-space limit of {} (ulimit -v)", gib(*s.address_limit)));
  return b;
}

bool fits(uint64_t need, const MemoryBudget& budget) {
  return budget.bytes == UINT64_MAX ||
         static_cast<double>(need) <= kMemoryUsableShare * static_cast<double>(budget.bytes);
}

void require_memory(uint64_t need, const std::string& what, const std::string& advice, const MemoryBudget& budget) {
  if (fits(need, budget)) return;
  const double usable = kMemoryUsableShare * static_cast<double>(budget.bytes);
  throw ResourceError(fmt::format("{} needs about {} of memory, but only {} may be used: {:.0f} % of the {} left by {}; {}",
                                  what, gib(need), gib(static_cast<uint64_t>(usable)), kMemoryUsableShare * 100.0,
                                  gib(budget.bytes), budget.bound, advice));
}

void require_memory(uint64_t need, const std::string& what, const std::string& advice) {
  require_memory(need, what, advice, memory_budget(read_memory_sources()));
}

void require_frame_memory(int width, int height, const std::string& what) {
  const uint64_t pixels = static_cast<uint64_t>(width) * static_cast<uint64_t>(height);
  require_memory(pixels * kFrameBytesPerPixel, fmt::format("{} at {}x{}", what, width, height),
                 "lower the resolution, or run on a machine with more memory");
}

}  // namespace sb
