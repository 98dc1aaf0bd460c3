// Process-wide memory policy of the programs that render many frames in one process.
#pragma once

namespace sb {

/// Frame-sized buffers (eye images, G-buffers, warp buffers: ~100 MB per eye at 1920x1080) are
/// allocated for every render. glibc maps each such block afresh and unmaps it when freed, so every
/// render pays the kernel's page faults again — measured at 55 ms per 100 MB here, as much as a
/// whole stage. Keeping freed memory in the heap lets later renders (benchmark repetitions) reuse
/// it, as a real-time renderer keeps its frame buffers; every pipeline gains alike. Call once, at
/// the start of main, before any thread starts.
void keep_freed_memory();

}  // namespace sb
