// The memory floor of one follower step's output: what B-follow's follower
// update must move however fast its arithmetic is. Per step, for N vertices:
// read the previous positions (for the finite-difference velocities), write
// the new positions in place, write the velocities. No arithmetic beyond the
// difference; the new positions come from registers.
//
// Modes: `store` (ordinary stores: the velocity lines are read for ownership
// first) and `stream` (velocities stored past the cache, non-temporal).
// Reports the best of 7 runs per mode and thread count, in ms per step.
//
// Usage: bench_output_memory [--vertices N]   (default 2.4M = 100k × 24)
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

namespace {

typedef float f4 __attribute__((vector_size(16)));

/// One step over floats [begin, end) of p (positions) and u (velocities).
void step(float* p, float* u, size_t begin, size_t end, float base, bool stream) {
    const f4 invDt = {50.f, 50.f, 50.f, 50.f};
    f4 next = {base, base + 1.f, base + 2.f, base + 3.f};
    for (size_t i = begin; i < end; i += 4) {
        const f4 old = *reinterpret_cast<const f4*>(p + i);
        const f4 velocity = (next - old) * invDt;
        *reinterpret_cast<f4*>(p + i) = next;
        if (stream) __builtin_ia32_movntps(u + i, velocity);
        else *reinterpret_cast<f4*>(u + i) = velocity;
        next += invDt;
    }
    if (stream) __builtin_ia32_sfence();
}

}  // namespace

int main(int argc, char** argv) {
    size_t vertices = 2400000;
    for (int a = 1; a < argc; ++a) {
        const std::string arg = argv[a];
        if (arg == "--vertices" && a + 1 < argc) vertices = std::strtoul(argv[++a], nullptr, 10);
        else {
            std::fprintf(stderr, "usage: bench_output_memory [--vertices N]\n");
            return 1;
        }
    }
    const size_t floats = (3 * vertices + 15) / 16 * 16;
    auto alloc = [&] {
        float* q = static_cast<float*>(std::aligned_alloc(64, floats * sizeof(float)));
        std::fill(q, q + floats, 0.f);
        return std::unique_ptr<float, decltype(&std::free)>(q, &std::free);
    };
    auto positions = alloc(), velocities = alloc();
    std::printf("# follower output memory floor: %zu vertices, %.1f MB read + %.1f MB written per step\n", vertices,
                floats * 4e-6, 2 * floats * 4e-6);
    std::printf("| velocity stores | threads | ms/step (best of 7) |\n|---|---:|---:|\n");
    for (const bool stream : {false, true})
        for (const int threads : {1, 2}) {
            tbb::task_arena arena(threads);
            double best = 1e30;
            for (int run = 0; run < 7; ++run) {
                const auto t0 = std::chrono::steady_clock::now();
                arena.execute([&] {
                    // Chunks of 64 KiB of floats, in order within each thread's share.
                    tbb::parallel_for(tbb::blocked_range<size_t>(0, floats / 16384 + 1, 1),
                                      [&](const tbb::blocked_range<size_t>& r) {
                                          const size_t b = r.begin() * 16384, e = std::min(floats, r.end() * 16384);
                                          if (b < e) step(positions.get(), velocities.get(), b, e, float(run), stream);
                                      },
                                      tbb::static_partitioner());
                });
                best = std::min(best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
            }
            std::printf("| %s | %d | %.2f |\n", stream ? "non-temporal" : "ordinary", threads, best);
        }
    return 0;
}
