// @brief What the benchmarks share: process CPU time, the median and range
// of repeated timings, and the digest of --digest columns. Benchmarks only;
// tests never time anything.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <ctime>
#include <vector>

namespace hp::bench {

/// CPU seconds of the whole process (all threads): on a machine shared with
/// other jobs it measures the work, where wall time also counts the contention.
inline double processCpuSeconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

/// The median (the upper middle one for an even count), smallest and largest
/// of repeated timings.
struct Stats {
    double median, min, max;
};

/// Stats of `v` (not empty).
inline Stats stats(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return {v[v.size() / 2], v.front(), v.back()};
}

/// FNV-1a (64 bit) of `bytes` bytes at `data`, continuing from `h` (the
/// offset basis by default): a --digest column, which an optimisation that
/// keeps the results bit for bit leaves unchanged.
inline uint64_t fnv1a(const void* data, size_t bytes, uint64_t h = 1469598103934665603ull) {
    const unsigned char* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

}  // namespace hp::bench
