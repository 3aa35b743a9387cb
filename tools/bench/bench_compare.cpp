// Cost of comparing one frame pair at the B-render resolution (1920×1080):
// SSIM, LDR-FLIP (67 PPD) and the whole compareImages (RMSE/PSNR through
// OpenImageIO, SSIM, FLIP, |A−B|), on 1 and 2 threads; median of 3 runs, the
// spread (max − min) and the process CPU time. Usage: bench_compare [runs]
#include "render/compare/compare.h"
#include "render/compare/ssim.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <random>

using namespace hp;

namespace {

/// A hair-like test frame: many thin bright curves on a dark background, with alpha.
Image frame(int w, int h, unsigned seed, float jitter) {
    Image img(w, h, {"R", "G", "B", "A"});
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    for (int s = 0; s < 3000; ++s) {
        float x = u(rng) * w, y = u(rng) * h * 0.6f;
        const float dx = (u(rng) - 0.5f) * 2.f, bright = 0.2f + 0.6f * u(rng);
        for (int k = 0; k < 300 && y < h; ++k, y += 1.f, x += dx + jitter * (u(rng) - 0.5f)) {
            const int px = int(x), py = int(y);
            if (px < 0 || px >= w) break;
            img.at(px, py, 0) = bright;
            img.at(px, py, 1) = 0.7f * bright;
            img.at(px, py, 2) = 0.45f * bright;
            img.at(px, py, 3) = 1.f;
        }
    }
    return img;
}

struct Stat {
    double median, spread, cpu;  ///< wall ms (median, max − min), median process CPU ms
};

/// Wall time, and process CPU time (all threads): on a machine shared with
/// other jobs the CPU time of a 1-thread run is the steadier figure.
Stat time(int runs, const std::function<void()>& f) {
    std::vector<double> ms, cpu;
    for (int i = 0; i < runs; ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::clock_t c0 = std::clock();
        f();
        cpu.push_back(1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC);
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    std::sort(ms.begin(), ms.end());
    std::sort(cpu.begin(), cpu.end());
    return {ms[ms.size() / 2], ms.back() - ms.front(), cpu[cpu.size() / 2]};
}

}  // namespace

int main(int argc, char** argv) {
    const int runs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
    const int w = 1920, h = 1080;
    const Image a = frame(w, h, 1, 0.f), b = frame(w, h, 1, 0.3f);
    std::printf("bench_compare: %dx%d RGBA frame pair, median of %d runs (spread)\n", w, h, runs);
    for (int threads : {1, 2}) {
        tbb::task_arena arena(threads);
        arena.execute([&] {
            ImagePlane x(w, h), y(w, h);
            for (size_t i = 0; i < x.size(); ++i) x.data[i] = a.pixels[4 * i + 1], y.data[i] = b.pixels[4 * i + 1];
            RgbPlanes pa{x, x, x}, pb{y, y, y};
            const Stat ssim = time(runs, [&] { ssimMap(x, y); });
            const Stat flip = time(runs, [&] { flipErrorMap(pa, pb); });
            CompareSettings s;
            s.mask = MaskMode::Hair;
            FrameMetrics m;
            const Stat all = time(runs, [&] { m = compareImages(a, b, s).metrics; });
            std::printf("threads %d: SSIM map %.0f ms (±%.0f, cpu %.0f), FLIP map %.0f ms (±%.0f, cpu %.0f), "
                        "compareImages %.0f ms (±%.0f, cpu %.0f)\n",
                        threads, ssim.median, ssim.spread, ssim.cpu, flip.median, flip.spread, flip.cpu, all.median,
                        all.spread, all.cpu);
            std::printf("  [mean FLIP %.4f, SSIM %.4f, PSNR %.2f dB over %ld hair pixels]\n", m.flip, m.ssim, m.psnr,
                        m.pixels);
        });
    }
    return 0;
}
