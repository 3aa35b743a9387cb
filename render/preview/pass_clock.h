// The clocks of the preview's per-pass profile (PreviewSettings::profile):
// process CPU time (all threads, llvmpipe's rasterizers included), the
// calling thread's (llvmpipe's vertex pipeline) and wall time, in ms.
#pragma once

#include <chrono>
#include <ctime>

namespace hp {

inline double cpuMilliseconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

inline double threadCpuMilliseconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

inline double wallMilliseconds() {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace hp
