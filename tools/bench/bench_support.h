// @brief What the benchmarks share: process CPU time and the median and
// range of repeated timings. Benchmarks only; tests never time anything.
#pragma once

#include <algorithm>
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

}  // namespace hp::bench
