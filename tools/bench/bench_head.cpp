// bench_head: the head stage's costs.
//  1. Evaluating a skinned head of ~100k triangles at one frame (the issue's
//     target: ≤ 10 ms on 2 cores): morphs + linear blend skinning with 4
//     influences per vertex + rigid fit, 1 and 2 threads.
//  2. The collider: building the rest-pose distance grid, and the cost of a
//     query (grid and exact) near the head.
//  3. Root placement: guides and 10k / 100k / 400k followers, both methods.
//  4. The default scene's head for a shot: load, grid, 24 frames, groom roots.
// Usage: bench_head [--quick]   (run from the repository root for part 4)
#include "pipeline/head/animated_head.h"
#include "pipeline/head/default_head.h"
#include "pipeline/head/head_setup.h"
#include "pipeline/head/scalp.h"
#include "sim/strands/roots.h"
#include "tools/bench/bench_support.h"

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <random>
#include <time.h>

using namespace hp;

namespace {

using Clock = std::chrono::steady_clock;

double secondsOf(const std::function<void()>& f) {
    const auto t0 = Clock::now();
    f();
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// CPU time of the calling thread: single-threaded figures that do not
/// count the time the (shared) machine gave to other processes.
double threadSecondsOf(const std::function<void()>& f) {
    timespec a{}, b{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &a);
    f();
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &b);
    return double(b.tv_sec - a.tv_sec) + 1e-9 * double(b.tv_nsec - a.tv_nsec);
}

using bench::Stats;

Stats repeat(int n, const std::function<void()>& f, bool cpuTime = false) {
    std::vector<double> t;
    for (int i = 0; i < n; ++i) t.push_back(cpuTime ? threadSecondsOf(f) : secondsOf(f));
    return bench::stats(t);
}

/// The default head at ~100k triangles with every vertex weighted to four
/// bones (the two real joints twice, at half weight: the same arithmetic as
/// four distinct bones) and two morph targets that are always active.
std::shared_ptr<const HeadRig> bigSkinnedHead() {
    HeadRig rig = makeDefaultHead({224, 224, 30});
    for (RigMesh& m : rig.meshes) {
        const size_t bones = m.boneNodes.size();
        for (size_t b = 0; b < bones; ++b) {
            m.boneNodes.push_back(m.boneNodes[b]);
            m.boneOffsets.push_back(m.boneOffsets[b]);
        }
        std::vector<uint32_t> start{0}, bone;
        std::vector<float> weight;
        for (size_t v = 0; v + 1 < m.influenceStart.size(); ++v) {
            for (int copy = 0; copy < 2; ++copy)
                for (uint32_t i = m.influenceStart[v]; i < m.influenceStart[v + 1]; ++i) {
                    bone.push_back(m.influenceBone[i] + uint32_t(copy * bones));
                    weight.push_back(0.5f * m.influenceWeight[i]);
                }
            // Pad to four influences (a weight-0 entry costs the same).
            while (bone.size() - start.back() < 4) bone.push_back(0), weight.push_back(0.f);
            start.push_back(uint32_t(bone.size()));
        }
        m.influenceStart = start;
        m.influenceBone = bone;
        m.influenceWeight = weight;
        for (int t = 0; t < 2; ++t) {
            m.morphNames.push_back("swell" + std::to_string(t));
            std::vector<Vec3f> d(m.positions.size());
            for (size_t v = 0; v < d.size(); ++v) d[v] = 0.002f * m.normals[v];
            m.morphPositions.push_back(d);
            m.morphNormals.emplace_back();
            m.morphDefaults.push_back(0.5f);
        }
    }
    return std::make_shared<const HeadRig>(std::move(rig));
}

}  // namespace

int main(int argc, char** argv) {
    const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
    const int runs = quick ? 5 : 21;
    std::printf("bench_head (%s; medians of %d runs, [min, max])\n\n", quick ? "quick" : "full", runs);

    // 1. One frame of a ~100k-triangle skinned head.
    {
        const auto rig = bigSkinnedHead();
        HeadAnimationSettings a;
        a.clip = 0;
        a.collider = ColliderMethod::None;
        AnimatedHead head(rig, a);
        ScalpSettings scalp;
        scalp.method = ScalpMethod::Material;
        scalp.materials = {"scalp"};
        head.setFitTriangles(selectScalp(*rig, head.rest(), scalp));
        std::printf("1. skinned head: %zu triangles, %zu vertices, 4 influences + 2 morphs per vertex\n",
                    rig->triangleCount(), rig->vertexCount());
        for (int threads : {1, 2}) {
            tbb::task_arena arena(threads);
            double t = 0.0;
            Stats s{};
            arena.execute([&] {
                s = repeat(runs, [&] {
                    t += 0.37;
                    const HeadPose p = head.sample(std::fmod(t, kDefaultHeadClipSeconds));
                    if (p.mesh.positions.empty()) std::abort();
                });
            });
            std::printf("   sample(t) with %d thread%s: %.2f ms [%.2f, %.2f] (target <= 10 ms on 2 cores)\n", threads,
                        threads == 1 ? " " : "s", 1e3 * s.median, 1e3 * s.min, 1e3 * s.max);
        }
        TriangleMesh m = head.rest();
        const Stats pose = repeat(runs, [&] { rig->pose(0, 1.234, m); });
        std::printf("   of which posing (morph + skin, default threads): %.2f ms [%.2f, %.2f]\n\n", 1e3 * pose.median,
                    1e3 * pose.min, 1e3 * pose.max);
    }

    // 2. The collider of the default head (5k triangles).
    {
        const auto rig = std::make_shared<const HeadRig>(makeDefaultHead());
        std::printf("2. collider, default head (%zu triangles)\n", rig->triangleCount());
        for (float voxel : {0.002f, 0.001f}) {
            HeadAnimationSettings a;
            a.clip = 0;
            a.levelSet.voxelSize = voxel;
            const AnimatedHead head(rig, a);
            std::shared_ptr<const LevelSet> grid;
            const double build = secondsOf([&] { grid = head.restLevelSet(); });
            std::printf("   grid %.0f mm voxels, %.0f mm bands: built in %.2f s, %zu active voxels, %.1f MB\n",
                        voxel * 1e3, a.levelSet.exteriorBand * 1e3, build, grid->activeVoxelCount(),
                        grid->memoryBytes() / 1e6);
            const HeadPose pose = head.sample(2.0);
            // Query points near the surface: in the band (|d| < 6 mm, where
            // strand vertices colliding with the head are) and outside it
            // (strand vertices away from the head: the cheap bound).
            const MeshCollider exact(pose.mesh);
            std::mt19937 rng(1);
            std::uniform_real_distribution<float> u(-1.f, 1.f);
            std::vector<Vec3f> near, far;
            while (near.size() < 100000 || far.size() < 100000) {
                const Vec3f& p = pose.mesh.positions[rng() % pose.mesh.positions.size()];
                const Vec3f q = p + 0.03f * Vec3f(u(rng), u(rng), u(rng));
                const float d = exact.signedDistance(q);
                if (std::abs(d) < 0.006f && near.size() < 100000) near.push_back(q);
                if (d > 0.012f && far.size() < 100000) far.push_back(q);
            }
            // Strand-like query order: 24 vertices 5 mm apart from each of
            // 845 surface points, as a solver visits them (coherent in memory).
            std::vector<Vec3f> strands;
            for (int s = 0; s < 845; ++s) {
                const size_t v = rng() % pose.mesh.positions.size();
                const Vec3f dir = (pose.mesh.normals[v] + 0.8f * Vec3f(u(rng), u(rng), u(rng))).normalized();
                for (int k = 0; k < 24; ++k) strands.push_back(pose.mesh.positions[v] + 0.005f * float(k) * dir - 0.003f * pose.mesh.normals[v]);
            }
            float sink = 0.f;
            {
                const Stats q = repeat(quick ? 3 : 5, [&] {
                    Vec3f n;
                    for (const Vec3f& p : strands) sink += pose.collider->signedDistance(p, &n) + n.x();
                }, true);
                std::printf("   grid query (distance + normal) along strands, thread CPU time: %.0f ns [%.0f, %.0f]\n",
                            1e9 * q.median / strands.size(), 1e9 * q.min / strands.size(), 1e9 * q.max / strands.size());
            }
            for (const auto* set : {&near, &far}) {
                const Stats q = repeat(quick ? 3 : 5, [&] {
                    Vec3f n;
                    for (const Vec3f& p : *set) sink += pose.collider->signedDistance(p, &n) + n.x();
                }, true);
                std::printf("   grid query (distance + normal) %s, thread CPU time: %.0f ns [%.0f, %.0f]\n",
                            set == &near ? "random, in the band    " : "random, beyond the band", 1e9 * q.median / set->size(),
                            1e9 * q.min / set->size(), 1e9 * q.max / set->size());
            }
            std::vector<Vec3f>& points = near;
            if (voxel == 0.001f) continue;
            const Stats e = repeat(3, [&] {
                Vec3f n;
                for (size_t i = 0; i < points.size(); i += 4) sink += exact.signedDistance(points[i], &n);
            }, true);
            std::printf("   exact query (closest triangle, Embree BVH), thread CPU time: %.0f ns (%g)\n",
                        1e9 * e.median / (points.size() / 4), double(sink > 0 ? 0 : 0));
        }
        std::printf("\n");
    }

    // 3. Root placement on the default head's scalp.
    {
        const HeadRig rig = makeDefaultHead();
        const TriangleMesh rest = rig.restMesh();
        ScalpSettings scalp;
        scalp.method = ScalpMethod::Material;
        scalp.materials = {"scalp"};
        const std::vector<uint8_t> mask = selectScalp(rig, rest, scalp);
        std::printf("3. root placement on the default head's scalp (%.0f cm²), default threads\n",
                    surfaceArea(rest, mask) * 1e4);
        std::vector<size_t> counts = {845, 10000, 100000, 400000};
        if (quick) counts.pop_back();
        for (RootMethod method : {RootMethod::Fibonacci, RootMethod::BlueNoise})
            for (size_t n : counts) {
                RootSettings rs;
                rs.method = method;
                rs.count = n;
                const Stats s = repeat(n >= 100000 ? (quick ? 1 : 3) : 5, [&] { placeRoots(rest, mask, rs); });
                std::printf("   %-10s %7zu roots: %.3f s [%.3f, %.3f]\n",
                            method == RootMethod::Fibonacci ? "fibonacci" : "blue-noise", n, s.median, s.min, s.max);
            }
        std::printf("\n");
    }

    // 4. What the head costs a shot of the default scene (wall time).
    if (std::filesystem::exists("scenes/default.yaml")) {
        const Scene scene = Scene::load("scenes/default.yaml");
        HeadSetup head;
        const double load = secondsOf([&] { head = loadHead(scene); });
        const double grid = secondsOf([&] { head.motion->restLevelSet(); });
        const double frames = secondsOf([&] {
            for (int f = 1; f <= 24; ++f) head.motion->sample(f / 24.0);
        });
        GroomRoots roots;
        const double groom = secondsOf([&] { roots = placeGroomRoots(scene, head); });
        std::printf("4. default scene: load %.3f s, rest grid %.3f s, 24 frames %.3f s (%.2f ms each), roots "
                    "(%zu guides + %zu followers, %s) %.3f s\n",
                    load, grid, frames, 1e3 * frames / 24, roots.guides.size(), roots.followers.size(),
                    scene.text("hair.roots.method").c_str(), groom);
    }
    return 0;
}
