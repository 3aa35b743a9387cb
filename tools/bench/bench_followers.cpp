// B-follow (docs/benchmarks.md): milliseconds per follower update for Gomes 2024's
// case (94 guides, 751 followers) and 845 guides with 10k, 100k and 400k
// followers × 24 vertices, modes varied / cluster / interpolate, on 1 and 2
// threads; medians of 3 runs with their spread.
//
// Guides: docs/benchmarks.md asks for the 845 guides of B-sim after its 250 steps.
// The guide solver is not on this branch, so a GuideSource drives them with
// sim/strands/synthetic_groom.h's deterministic motion (drooping, swaying guides on the
// sphere r = 0.1 m spinning 90°/s about +Y) from t = (20 + 250) × 0.02 s on.
// To time against real guides, replace makeSyntheticSource by a source that
// steps the solver (or reads its frames) — only GuideSource::next changes.
//
// Usage: bench_followers [--quick] [--sizes 751,10000,...] [--steps N]
//        [--modes varied,cluster,interpolate,barycentric] [--threads 1,2] [--no-collide]
//        [--angle] [--length-variation X] [--clump X] [--clumps N]
//        [--wave M] [--wave-length M] [--curl X] [--frizz M] [--digest]
// --digest adds a column: FNV-1a (64 bit) of the last step's positions and
// velocities, to check that a change of the follower code keeps the bits.
// --angle adds a column: the median angle between mid-strand tangents of
// root-neighbouring followers (sim/followers/follower_metrics.h) after the last step;
// the modifier options apply sim/strands/groom_modifiers.h to the groom first.
#include "core/errors.h"
#include "sim/followers/follower_metrics.h"
#include "sim/followers/followers.h"
#include "sim/strands/groom_modifiers.h"
#include "sim/strands/synthetic_groom.h"
#include "tools/bench/bench_support.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <functional>
#include <ctime>
#include <sstream>
#include <string>
#include <vector>

using namespace hp;
using Clock = std::chrono::steady_clock;

namespace {

/// What a follower update needs each step, from whatever moves the guides.
struct GuideSource {
    FollowerGroom groom;
    std::shared_ptr<const Collider> head;
    /// Fills the guides, their root frames and the followers' root frames of step `i`.
    std::function<void(int i, StrandFrame& guides, std::vector<SurfaceFrame>& guideRoots,
                       std::vector<SurfaceFrame>& followerRoots)>
        next;
    double dt = 0.02;
};

GuideSource makeSyntheticSource(size_t guides, size_t followers, const GroomModifiers& modifiers) {
    GuideSource src;
    SphereGroomSettings s;
    s.guides = guides;
    s.followers = followers;
    src.groom = makeSphereGroom(s);
    applyGroomModifiers(src.groom, modifiers);
    src.head = std::make_shared<SphereCollider>(Vec3f::Zero(), s.headRadius);
    auto motion = std::make_shared<SyntheticGuides>(src.groom, SyntheticGuideSettings{});
    const std::vector<SurfaceFrame> restRoots = src.groom.followerRoots;
    src.next = [motion, restRoots](int i, StrandFrame& g, std::vector<SurfaceFrame>& gr, std::vector<SurfaceFrame>& fr) {
        const double t = (20 + 250 + i) * 0.02;  // after B-sim's warm-up and timed steps
        motion->sample(t, g, gr);
        rotateRoots(restRoots, motion->headRotation(t), fr);
    };
    return src;
}

struct Result {
    double median = 0, spread = 0, buildMs = 0;
    double cpu = 0;  ///< median CPU ms per step, all threads together
    double projected = 0, queries = 0;
    double angle = 0;  ///< median neighbour angle after the last step, degrees
    uint64_t digest = 0;  ///< FNV-1a of the last step's positions and velocities
};

const char* modeName(FollowerMode m) {
    return m == FollowerMode::Varied ? "varied" : m == FollowerMode::Cluster ? "cluster"
           : m == FollowerMode::Barycentric ? "barycentric" : "interpolate";
}

Result measure(const GuideSource& src, FollowerMode mode, int threads, int steps, bool collide) {
    FollowerSettings settings;
    settings.mode = mode;
    settings.collide = collide;
    Result r;
    tbb::task_arena arena(threads);
    std::vector<double> runs, cpu;
    arena.execute([&] {
        const auto b0 = Clock::now();
        Followers followers(src.groom, settings);
        r.buildMs = std::chrono::duration<double, std::milli>(Clock::now() - b0).count();
        StrandFrame guides, frame;
        std::vector<SurfaceFrame> guideRoots, followerRoots;
        int i = 0;
        // Warm-up: the first update lays out the frame (allocation, radii, ids).
        for (int w = 0; w < 2; ++w, ++i) {
            src.next(i, guides, guideRoots, followerRoots);
            followers.update({guides, guideRoots, followerRoots, src.head.get(), w ? src.dt : 0.0}, frame);
        }
        for (int run = 0; run < 3; ++run) {
            double total = 0, totalCpu = 0;
            for (int s = 0; s < steps; ++s, ++i) {
                src.next(i, guides, guideRoots, followerRoots);  // not timed: the guides' side
                const auto t0 = Clock::now();
                const double c0 = bench::processCpuSeconds();
                const FollowerStats st =
                    followers.update({guides, guideRoots, followerRoots, src.head.get(), src.dt}, frame);
                totalCpu += 1e3 * (bench::processCpuSeconds() - c0);
                total += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
                r.projected += double(st.projected);
                r.queries += double(st.collisionQueries);
                if (!st.differenceVelocities) throw Error("bench: expected finite-difference velocities");
            }
            runs.push_back(total / steps);
            cpu.push_back(totalCpu / steps);
        }
        frame.validate();
        r.angle = medianNeighbourAngle(frame, frame.guideCount);
        r.digest = bench::fnv1a(frame.velocities.data(), frame.velocities.size() * sizeof(Vec3f),
                                bench::fnv1a(frame.positions.data(), frame.positions.size() * sizeof(Vec3f)));
    });
    std::sort(runs.begin(), runs.end());
    r.median = runs[1];
    r.spread = runs[2] - runs[0];
    std::sort(cpu.begin(), cpu.end());
    r.cpu = cpu[1];
    r.projected /= 3.0 * steps;
    r.queries /= 3.0 * steps;
    return r;
}

template <typename T, typename Parse>
std::vector<T> parseList(const char* text, Parse parse) {
    std::vector<T> out;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) out.push_back(parse(item));
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    struct Scene { size_t guides, followers; };
    std::vector<Scene> scenes = {{94, 751}, {845, 10000}, {845, 100000}, {845, 400000}};
    std::vector<FollowerMode> modes = {FollowerMode::Varied, FollowerMode::Cluster, FollowerMode::Interpolate};
    std::vector<int> threads = {1, 2};
    int steps = 0;  // 0: by size
    bool collide = true, angle = false, digest = false;
    GroomModifiers modifiers;
    for (int a = 1; a < argc; ++a) {
        const std::string arg = argv[a];
        auto value = [&]() -> const char* {
            if (a + 1 >= argc) { std::fprintf(stderr, "%s needs a value\n", arg.c_str()); std::exit(1); }
            return argv[++a];
        };
        if (arg == "--quick") scenes = {{94, 751}, {845, 10000}};
        else if (arg == "--sizes") {
            scenes.clear();
            for (size_t n : parseList<size_t>(value(), [](const std::string& s) { return std::stoul(s); }))
                scenes.push_back({n == 751 ? 94u : 845u, n});
        } else if (arg == "--steps") steps = std::atoi(value());
        else if (arg == "--modes") {
            modes = parseList<FollowerMode>(value(), [](const std::string& s) {
                if (s == "varied") return FollowerMode::Varied;
                if (s == "cluster") return FollowerMode::Cluster;
                if (s == "interpolate") return FollowerMode::Interpolate;
                if (s == "barycentric") return FollowerMode::Barycentric;
                std::fprintf(stderr, "unknown mode %s\n", s.c_str());
                std::exit(1);
            });
        } else if (arg == "--threads") threads = parseList<int>(value(), [](const std::string& s) { return std::stoi(s); });
        else if (arg == "--no-collide") collide = false;
        else if (arg == "--angle") angle = true;
        else if (arg == "--digest") digest = true;
        else if (arg == "--length-variation") modifiers.lengthVariation = std::stof(value());
        else if (arg == "--clump") modifiers.clump = std::stof(value());
        else if (arg == "--clumps") modifiers.clumps = uint32_t(std::stoul(value()));
        else if (arg == "--wave") modifiers.wave = std::stof(value());
        else if (arg == "--wave-length") modifiers.waveLength = std::stof(value());
        else if (arg == "--curl") modifiers.curl = std::stof(value());
        else if (arg == "--frizz") modifiers.frizz = std::stof(value());
        else { std::fprintf(stderr, "unknown option %s\n", arg.c_str()); return 1; }
    }

    std::printf("# B-follow: follower update, ms per step (median of 3 runs, spread = max - min)\n");
    std::printf("# guides: synthetic drooping/swaying guides on the 90 deg/s spinning sphere (no solver on this branch)\n");
    std::printf("# head collision: %s; velocities: finite differences; 24 vertices per strand\n", collide ? "on" : "off");
    std::printf("# cpu ms/step: CPU time of all threads per step (on a shared machine, wall time includes waiting)\n\n");
    if (modifiers.active())
        std::printf("# groom modifiers: length variation %g, clump %g (%u centres), wave %g m / %g m, curl %g, frizz %g m\n",
                    modifiers.lengthVariation, modifiers.clump, modifiers.clumps, modifiers.wave, modifiers.waveLength,
                    modifiers.curl, modifiers.frizz);
    std::printf("| guides | followers | mode | threads | ms/step | spread | cpu ms/step | build ms | queries/step | projected/step |%s%s\n",
                angle ? " neighbour angle deg |" : "", digest ? " digest |" : "");
    std::printf("|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|%s%s\n", angle ? "---:|" : "", digest ? "---|" : "");
    for (const Scene& sc : scenes) {
        const GuideSource src = makeSyntheticSource(sc.guides, sc.followers, modifiers);
        const int n = steps > 0 ? steps : sc.followers >= 400000 ? 5 : sc.followers >= 100000 ? 10 : 30;
        for (FollowerMode mode : modes)
            for (int t : threads) {
                const Result r = measure(src, mode, t, n, collide);
                std::printf("| %zu | %zu | %s | %d | %.3f | %.3f | %.3f | %.1f | %.0f | %.0f |", sc.guides,
                            sc.followers, modeName(mode), t, r.median, r.spread, r.cpu, r.buildMs, r.queries,
                            r.projected);
                if (angle) std::printf(" %.2f |", r.angle);
                if (digest) std::printf(" %016llx |", static_cast<unsigned long long>(r.digest));
                std::printf("\n");
                std::fflush(stdout);
            }
    }
    return 0;
}
