#pragma once
// This process's memory as the kernel counts it (Linux /proc/self/status), bytes; 0 if unknown.
#include <cstdint>

namespace femto {

uint64_t current_rss_bytes();  ///< VmRSS: resident now
uint64_t peak_rss_bytes();     ///< VmHWM: the highest resident size so far

}  // namespace femto
