// Process memory: the allocator policy of the programs that render many frames in one process,
// readings of what the process holds, and the check that refuses work the machine cannot hold
// before it is allocated (under Linux overcommit a too-large job is not refused by the allocator
// but killed by the kernel's OOM killer part-way, losing everything).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace sb {

/// Frame-sized buffers (eye images, G-buffers, warp buffers: ~100 MB per eye at 1920x1080) are
/// allocated for every render. glibc maps each such block afresh and unmaps it when freed, so every
/// render pays the kernel's page faults again — measured at 55 ms per 100 MB here, as much as a
/// whole stage. Keeping freed memory in the heap lets later renders (benchmark repetitions) reuse
/// it, as a real-time renderer keeps its frame buffers; every pipeline gains alike. Call once, at
/// the start of main, before any thread starts.
void keep_freed_memory();

/// A "Key:   123 kB" field of a /proc file (e.g. /proc/meminfo, /proc/self/status), in bytes;
/// nothing when the file or the field is missing.
[[nodiscard]] std::optional<uint64_t> proc_kib_field(const char* file, const std::string& key);

/// Bytes as GiB with two decimals, "20.54 GiB", as memory messages and tables print them.
[[nodiscard]] std::string gib(uint64_t bytes);

/// The process's resident size (VmRSS) and its peak (VmHWM), in bytes; 0 when unreadable.
[[nodiscard]] uint64_t resident_bytes();
[[nodiscard]] uint64_t peak_resident_bytes();

/// Share of the memory budget one piece of work may plan to use; the rest is left to the system,
/// to other processes and to the error of the estimate.
inline constexpr double kMemoryUsableShare = 0.9;

/// The bounds on what this process may still allocate, as the system reports them.
struct MemorySources {
  std::optional<uint64_t> mem_available;  ///< MemAvailable of /proc/meminfo
  std::optional<uint64_t> cgroup_limit;   ///< the memory cgroup's limit (v2 memory.max, v1 limit_in_bytes)
  uint64_t cgroup_usage = 0;              ///< and its usage (memory.current, usage_in_bytes)
  std::string cgroup_file;                ///< the file the limit was read from
  std::optional<uint64_t> address_limit;  ///< RLIMIT_AS (ulimit -v)
  uint64_t address_used = 0;              ///< VmSize
  /// Freed memory the process's heap keeps for reuse (keep_freed_memory): it is counted as used by
  /// every bound above, yet a new buffer can take it without asking the system for more.
  uint64_t heap_free = 0;
};

/// The tightest of the bounds: what may be allocated, and which bound says so.
struct MemoryBudget {
  uint64_t bytes = UINT64_MAX;  ///< UINT64_MAX: no bound could be read
  std::string bound;            ///< e.g. "MemAvailable", "the address-space limit (ulimit -v)"
};

/// The bounds of this process now.
[[nodiscard]] MemorySources read_memory_sources();

/// The least of the bounds in `sources`, each plus the heap's free memory.
[[nodiscard]] MemoryBudget memory_budget(const MemorySources& sources);

/// Whether work needing about `need` bytes more than the process holds fits: need <=
/// kMemoryUsableShare * budget (always, when no bound could be read).
[[nodiscard]] bool fits(uint64_t need, const MemoryBudget& budget);

/// Refuses work that does not fit (see fits): throws ResourceError (exit 4) "<what> needs about
/// X GiB of memory, but only Y GiB may be used: 90 % of the Z GiB left by <bound>; <advice>".
void require_memory(uint64_t need, const std::string& what, const std::string& advice, const MemoryBudget& budget);

/// The same against this process's budget now.
void require_memory(uint64_t need, const std::string& what, const std::string& advice);

/// Bytes per pixel (of one eye) that rendering a stereo pair with any registered pipeline, and
/// validating it, holds at its peak: both eyes with every AOV, G-buffers, warp and reprojection
/// state, the ground truth, metric maps and the encoded outputs. Measured as the slope of the peak
/// resident size between 1920x1080 and 3840x2160 (lit-plane; render and validate of each pipeline):
/// 197 (plain-rt) to 297 B (bidir-warp), rt-buffer 545 B with its reprojection buffer, which it
/// checks itself as it allocates it (t x 4 B per pixel; t = 83 there); `validate -p all` 622 B,
/// that buffer included (one pipeline's images are held at a time).
inline constexpr uint64_t kFrameBytesPerPixel = 320;

/// Refuses a render of width x height stereo pairs that would not fit (require_memory), naming
/// `what` (e.g. "validate at 16384x16384").
void require_frame_memory(int width, int height, const std::string& what);

}  // namespace sb
