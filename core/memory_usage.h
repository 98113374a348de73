#pragma once
// This process's memory as the kernel counts it (Linux /proc/self/status), bytes; 0 if unknown.
#include <cstdint>

namespace femto {

uint64_t current_rss_bytes();  ///< VmRSS: resident now
uint64_t peak_rss_bytes();     ///< VmHWM: the highest resident size so far

/// Keeps the memory the program frees for its next allocations (glibc malloc: no trimming, and
/// fresh mappings only above 32 MiB). On virtual machines a page fault costs 10-20 us, and a
/// render's per-pass lists (light paths' beams, photons, the beam tree) would take fresh pages
/// every pass. For programs (the femto command, benchmarks), not for a library inside another
/// process (the Python module).
void reuse_freed_memory();

}  // namespace femto
