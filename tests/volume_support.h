// Shared by the hair-hair grid's tests (test_hair_grid.cpp, test_hair_volume.cpp, test_wisp_contact.cpp):
// the ways of running a volume kernel's chunks that its determinism tests compare.
#pragma once

#include "sim/volume/wisp_contact.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <functional>

namespace hp::test {

/// Runs f over [0, count) in `threads` threads, chunks of `grain`.
inline volume::ParallelFor arenaFor(int threads, size_t grain) {
    return [threads, grain](size_t count, const std::function<void(size_t, size_t)>& f) {
        tbb::task_arena arena(threads);
        arena.execute([&] {
            tbb::parallel_for(tbb::blocked_range<size_t>(0, count, grain),
                              [&](const tbb::blocked_range<size_t>& r) { f(r.begin(), r.end()); },
                              tbb::simple_partitioner());
        });
    };
}

/// Runs the chunks one at a time, last first: any order-dependent sum shows.
inline void reversedFor(size_t count, const std::function<void(size_t, size_t)>& f) {
    for (size_t e = count; e > 0; --e) f(e - 1, e);
}

}  // namespace hp::test
