// B-sim (docs/benchmarks.md) for the curly/wet strand model (Kim 2023): curly
// guides of 24 particles, 0.25 m, on a 0.1 m sphere head spinning 90°/s
// about Y, roots on a Fibonacci lattice over the upper hemisphere, 0.02 s
// steps, 20 warm-up + 250 timed steps. Reports steps/s (median of 3 runs and
// the spread), the largest edge stretch and the deepest penetration over the
// timed steps, NaN count, the fitted curl radius/pitch at the end, threads,
// and the process CPU time per step (all threads; a steadier figure than wall
// time on a machine shared with other jobs).
//
// Modes: dry (σ = 0), wet (σ = 1, cohesion off), cohesion (σ = 1, cohesion on).
//
//   bench_curly                      the full matrix (94 and 845 guides, all
//                                    modes, 1 and 2 threads)
//   bench_curly --guides 94 --mode cohesion --threads 2 --runs 1
#include "sim/curly/curly_wet.h"
#include "sim/strands/fibonacci.h"
#include "sim/strands/head.h"
#include "sim/strands/sphere_roots.h"
#include "tools/bench/bench_support.h"

#include <tbb/global_control.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

namespace {

using namespace hp;

struct Result {
    double stepsPerSecond = 0;
    double cpuMsPerStep = 0;  ///< process CPU time (all threads) per timed step
    StepStats stats;
    Eigen::Vector2f curl = Eigen::Vector2f::Zero();
};

Result run(size_t guides, const std::string& mode, int threads, int warmup, int timed) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    const float radius = 0.1f;
    SpinningSphere head(radius, 90.f);
    CurlyWetSettings s;
    s.threads = threads;
    s.saturation = mode == "dry" ? 0.f : 1.f;
    s.cohesion = mode == "cohesion";
    const std::vector<Vec3f> dirs = fibonacciCap(guides);
    CurlyWetSolver solver(s);
    HeadPose pose = head.sample(0.0);
    solver.initialize(sphereRootFrames(dirs, radius, pose, Vec3f::UnitX()), pose);
    Result r;
    StepStats acc;
    bool first = true;
    double ms = 0, cpu = 0;
    for (int k = 1; k <= warmup + timed; ++k) {
        if (k == warmup + 1) cpu = bench::processCpuSeconds();
        pose = head.sample(k * double(s.timeStep));
        const StepStats& st = solver.step(sphereRootFrames(dirs, radius, pose, Vec3f::UnitX()), pose);
        if (k <= warmup) continue;
        ms += st.msPerStep;
        if (first) acc = st, first = false;
        else acc.accumulate(st);
    }
    r.cpuMsPerStep = 1000.0 * (bench::processCpuSeconds() - cpu) / timed;
    r.stepsPerSecond = 1000.0 * timed / ms;
    r.stats = acc;
    r.curl = solver.measureCurl();
    return r;
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<size_t> counts = {94, 845};
    std::vector<std::string> modes = {"dry", "wet", "cohesion"};
    std::vector<int> threads = {1, 2};
    int runs = 3, warmup = 20, timed = 250;
    for (int i = 1; i < argc; ++i) {
        auto next = [&]() -> const char* {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "bench_curly: %s needs a value\n", argv[i]);
                std::exit(2);
            }
            return argv[++i];
        };
        if (!std::strcmp(argv[i], "--guides")) counts = {size_t(std::stoul(next()))};
        else if (!std::strcmp(argv[i], "--mode")) modes = {next()};
        else if (!std::strcmp(argv[i], "--threads")) threads = {std::stoi(next())};
        else if (!std::strcmp(argv[i], "--runs")) runs = std::stoi(next());
        else if (!std::strcmp(argv[i], "--steps")) timed = std::stoi(next());
        else {
            std::fprintf(stderr, "usage: bench_curly [--guides N] [--mode dry|wet|cohesion] [--threads T] "
                                 "[--runs R] [--steps S]\n");
            return 2;
        }
    }
    std::printf("B-sim, curly/wet model: sphere r=0.1 m spinning 90 deg/s about Y, 24 particles x 0.25 m, "
                "0.02 s steps (1 Bullet step, 8 link iterations), %d warm-up + %d timed steps, median of %d\n",
                warmup, timed, runs);
    std::printf("%7s %9s %7s %10s %16s %11s %10s %12s %5s %14s\n", "guides", "mode", "threads", "steps/s", "spread",
                "CPU ms/step", "max strain", "max pen. mm", "NaN", "curl r/p mm");
    for (size_t n : counts)
        for (const std::string& mode : modes)
            for (int t : threads) {
                std::vector<Result> rs;
                for (int k = 0; k < runs; ++k) rs.push_back(run(n, mode, t, warmup, timed));
                std::vector<double> sps, cpu;
                for (const Result& r : rs) {
                    sps.push_back(r.stepsPerSecond);
                    cpu.push_back(r.cpuMsPerStep);
                }
                std::sort(sps.begin(), sps.end());
                std::sort(cpu.begin(), cpu.end());
                const Result& r = rs.back();
                char spread[64];
                std::snprintf(spread, sizeof spread, "%.1f-%.1f", sps.front(), sps.back());
                std::printf("%7zu %9s %7d %10.1f %16s %11.2f %9.3f%% %12.3f %5zu %6.1f/%-6.1f\n", n, mode.c_str(), t,
                            sps[sps.size() / 2], spread, cpu[cpu.size() / 2], 100.0 * r.stats.maxLengthError,
                            1000.0 * r.stats.maxPenetration, r.stats.nanCount, 1000.0 * r.curl.x(),
                            1000.0 * r.curl.y());
                std::fflush(stdout);
            }
    return 0;
}
