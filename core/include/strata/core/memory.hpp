#pragma once
// How much memory this process may still take: what the kernel reports as available (MemAvailable
// in /proc/meminfo: free memory plus caches it can drop), bounded by the address-space and data
// limits (ulimit -v, -d). Work that allocates in proportion to user input (a scenario's cells)
// compares its estimate with this before allocating, and refuses with the size asked for.

#include <cstdint>
#include <string>

namespace strata {

/// Bytes this process can expect to allocate now (0 when nothing can be read: no bound known).
uint64_t availableMemoryBytes();

/// "1.3 GB", "512 MB", "12 kB" (decimal units).
std::string formatBytes(double bytes);

}  // namespace strata
