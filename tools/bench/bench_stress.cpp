// B-sim-stress (docs/benchmarks.md): scenes/stress.yaml — the default head's
// "stress" clip (tips back 70° in 0.25 s and forward, turns 180° in 0.3 s,
// cuts at 2 s), hair rooted everywhere (head.scalp.method all), 300 guides,
// 30 000 followers, shoulders as a Bullet capsule. Runs the shot simulation
// frame by frame and reports steps/s (simulation only, measurements
// excluded), the worst segment stretch of guides and of followers against
// their lengths on the first frame, the deepest free vertex inside any
// collider (the pose's composite collider: head + Bullet world; on a head
// that folds into itself, without the parts the strand's root lies inside,
// docs/colliders.md) after any frame, pinned vertices (the most in one frame; rod only: the rope pins
// nothing) and NaN.
//
//   bench_stress [--scene scenes/stress.yaml] [--threads 2] [--set key=value ...] [--per-frame]
//
// --per-frame adds a line per frame: the deepest guide and follower vertex
// (and, on a head that folds into itself, the deepest vertex of a strand
// whose root lies inside another part),
// pinned guide vertices, and the followers' projected, bent, pinned and
// left-inside vertices (FollowerStats).
//
// --colliders: B-sim head-only (docs/benchmarks.md: sphere r = 0.1 m spinning
// 90°/s, 0.25 m guides of 24 vertices, 20 warm-up + 250 timed steps) with
// the head as the exact analytic sphere, as a distance grid (the head's fast
// path, sim/collision/level_set.h) and as a btSphereShape queried through the Bullet
// collision world (sim/collision/collision_world.h), in one run.
//
//   bench_stress --colliders [--guides 94,845] [--threads 2]
//
// --worst (a head that folds into itself): per frame, how many free vertices
// the collider puts outside while a part's winding number puts them inside
// (the definition's cross-check), the deepest guide and follower vertex, with each part's signed distance at it, at its parent
// and at its strand's root, the parts the strand ignores, and whether it is
// pinned (followers), the posed parts' winding numbers there; and how many
// vertices are more than 1 mm inside, how many of them on strands whose own
// root is more than 1 mm inside.
#include "pipeline/batch/strand_cache.h"
#include "pipeline/head/animated_head.h"
#include "pipeline/scene/scene.h"
#include "pipeline/stages/shot_simulation.h"
#include "sim/collision/collision_world.h"
#include "sim/strands/fibonacci.h"
#include "sim/guides/guides.h"
#include "sim/collision/mesh_collider.h"
#include "sim/collision/mesh_parts.h"
#include "sim/collision/winding_number.h"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>
#include <optional>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace hp;

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// Worst |segment / rest - 1| over strands [begin, end) of `f`, `rest` the
/// segment lengths of the first frame (same layout).
double worstStretch(const StrandFrame& f, const std::vector<float>& rest, size_t begin, size_t end) {
    double worst = 0;
    for (size_t s = begin; s < end; ++s)
        for (uint32_t i = f.first(s); i + 1 < f.offsets[s + 1]; ++i)
            worst = std::max(worst, std::abs(double((f.positions[i + 1] - f.positions[i]).norm()) / rest[i] - 1.0));
    return worst;
}

std::vector<float> segmentLengths(const StrandFrame& f) {
    std::vector<float> out(f.positions.size(), 1.f);
    for (size_t s = 0; s < f.strandCount(); ++s)
        for (uint32_t i = f.first(s); i + 1 < f.offsets[s + 1]; ++i) out[i] = (f.positions[i + 1] - f.positions[i]).norm();
    return out;
}

/// --worst: the deepest free vertex of strands [begin, end) of `f` by the
/// documented definition, and what holds it there: each part's signed
/// distance at the vertex, its parent and the strand's root, the parts the
/// strand ignores, whether it is a pinned follower vertex. Also how many
/// vertices are more than 1 mm inside, and how many of those belong to
/// strands whose root is itself more than 1 mm inside a part they collide
/// with (a collider that is not where the posed mesh is).
/// --worst's cross-check of the definition: free vertices of strands
/// [begin, end) that the collider puts outside every part the strand
/// collides with, while a part's generalized winding number (exact,
/// winding_number.h) puts them inside it; and the farthest of them from
/// that part's surface. 0 means the collider's side hides no vertex the
/// winding number counts inside.
void crossCheck(const char* what, const StrandFrame& f, size_t begin, size_t end, const PartsCollider& parts,
                const std::vector<TriangleMesh>& posedParts, const std::vector<std::unique_ptr<MeshCollider>>& posedExact,
                const std::vector<uint32_t>& ignore) {
    std::vector<size_t> count(end - begin, 0);
    std::vector<float> far(end - begin, 0.f);
    tbb::parallel_for(begin, end, [&](size_t s) {
        for (uint32_t i = f.first(s) + 1; i < f.offsets[s + 1]; ++i) {
            const Vec3f& p = f.positions[i];
            if (parts.signedDistanceIgnoring(p, nullptr, ignore[s]) < 0.f) continue;
            for (size_t k = 0; k < posedParts.size(); ++k) {
                if ((ignore[s] >> k) & 1u) continue;
                if (windingNumber(posedParts[k], posedExact[k]->query(), p, Vec3f::UnitY()) <= 0.5) continue;
                ++count[s - begin];
                far[s - begin] = std::max(far[s - begin], posedExact[k]->query().closest(p).distance);
                break;
            }
        }
    });
    size_t n = 0;
    float worst = 0.f;
    for (size_t k = 0; k < count.size(); ++k) n += count[k], worst = std::max(worst, far[k]);
    std::printf("  %s vertices outside by the collider but inside a part by its winding number: %zu (up to %.3f mm "
                "from its surface)\n",
                what, n, 1e3 * double(worst));
}

void explainWorst(const char* what, const StrandFrame& f, size_t begin, size_t end, const PartsCollider& parts,
                  const std::vector<TriangleMesh>& posedParts, const std::vector<uint32_t>& ignore,
                  const std::vector<FollowerPin>& pins, const MeshPartition& partition, const MeshCollider& posedMesh) {
    float worst = 0.f;
    size_t strand = 0, deep = 0, rootInside = 0;
    uint32_t vertex = 0;
    for (size_t s = begin; s < end; ++s) {
        // Is the root itself more than 1 mm inside a part the strand collides with?
        const float root = parts.signedDistanceIgnoring(f.positions[f.first(s)], nullptr, ignore[s]);
        for (uint32_t i = f.first(s) + 1; i < f.offsets[s + 1]; ++i) {
            const float d = -parts.signedDistanceIgnoring(f.positions[i], nullptr, ignore[s]);
            if (d > worst) worst = d, strand = s, vertex = i;
            if (d > 1e-3f) ++deep, rootInside += root < -1e-3f;
        }
    }
    if (worst <= 0.f) return;
    std::printf("  %s vertices more than 1 mm inside: %zu, %zu of them on strands whose root lies more than 1 mm "
                "inside a part they collide with\n",
                what, deep, rootInside);
    auto distances = [&](const Vec3f& p) {
        std::string out;
        for (size_t k = 0; k < parts.count(); ++k) out += cat(k ? " " : "", 1e3 * parts.part(k).signedDistance(p));
        return out;
    };
    auto windings = [&](const Vec3f& p) {
        std::string out;
        for (size_t k = 0; k < posedParts.size(); ++k)
            out += cat(k ? " " : "", std::round(100 * windingNumber(posedParts[k], p)) / 100);
        return out;
    };
    const uint32_t block = vertex - f.offsets[f.guideCount];
    const bool pinned = strand >= f.guideCount &&
                        std::any_of(pins.begin(), pins.end(), [&](const FollowerPin& p) { return p.vertex == block; });
    std::printf("  deepest %s: strand %zu vertex %u, %.3f mm; parts' distance mm at it [%s], parent [%s], root [%s]; "
                "ignores %#x%s\n",
                what, strand, vertex - f.first(strand), 1e3 * worst, distances(f.positions[vertex]).c_str(),
                distances(f.positions[vertex - 1]).c_str(), distances(f.positions[f.first(strand)]).c_str(),
                ignore[strand], pinned ? ", pinned" : "");
    // On the surface the number is ambiguous: taken 0.1 mm up the strand.
    const Vec3f root = f.positions[f.first(strand)], up = f.positions[f.first(strand) + 1] - root;
    std::printf("    posed parts' winding numbers at it [%s], parent [%s], 0.1 mm above the root [%s]\n",
                windings(f.positions[vertex]).c_str(), windings(f.positions[vertex - 1]).c_str(),
                windings(root + 1e-4f * up.normalized()).c_str());
    // The root's own part and whether its fold buries the root (mesh_parts.h buriedByOwnPart).
    const MeshPoint c = posedMesh.closest(root);
    const Tri& t = posedMesh.query().triangle(c.point.triangle);
    const Vec3f n = (posedMesh.query().vertex(t[1]) - posedMesh.query().vertex(t[0]))
                        .cross(posedMesh.query().vertex(t[2]) - posedMesh.query().vertex(t[0]))
                        .normalized();
    std::printf("    root on part %u (%.3f mm from it); winding numbers 0.1 mm along its face normal [%s]\n",
                partition.triangleParts[c.point.triangle], 1e3 * double(c.distance),
                windings(c.position + kBuriedRootOffset * n).c_str());
}

int stress(const std::string& path, const std::vector<std::string>& overrides, bool perFrame, bool worstVertex) {
    const Scene scene = Scene::load(path, overrides);
    const std::vector<int>& frames = scene.frames("frames");
    const double fps = scene.number("fps");
    Clock::time_point t = Clock::now();
    ShotSimulation sim(scene, fps, frames.front());
    std::printf("B-sim-stress: %s, %zu guides, %zu followers, frames %d-%d at %g fps; set-up %.1f s\n", path.c_str(),
                sim.guideCount(), sim.followerCount(), frames.front(), frames.back(), fps, since(t));
    const std::vector<float> rest = segmentLengths(sim.advanceTo(frames.front()));
    const size_t guides = sim.guideCount();
    double simSeconds = 0, guideWorst = 0, followerWorst = 0, depthWorst = 0;
    int guideFrame = 0, followerFrame = 0, depthFrame = 0, resets = 0;
    size_t steps = 0, nan = 0, pinnedWorst = 0, followerPinnedWorst = 0, followerBentWorst = 0;
    for (int frame : frames) {
        if (frame == frames.front()) continue;
        t = Clock::now();
        const StrandFrame& f = sim.advanceTo(frame);
        simSeconds += since(t);
        steps += sim.stats().guides.steps;
        resets += int(sim.stats().guides.cuts);
        pinnedWorst = std::max(pinnedWorst, sim.stats().guides.pinnedCount);
        followerPinnedWorst = std::max(followerPinnedWorst, sim.stats().followers.pinned);
        followerBentWorst = std::max(followerBentWorst, sim.stats().followers.bent);
        const double g = worstStretch(f, rest, 0, guides), fo = worstStretch(f, rest, guides, f.strandCount());
        if (g > guideWorst) guideWorst = g, guideFrame = frame;
        if (fo > followerWorst) followerWorst = fo, followerFrame = frame;
        std::atomic<size_t> bad{0};
        std::vector<float> depth(f.strandCount(), 0.f);
        const Collider* collider = sim.pose().collider.get();
        const std::vector<uint32_t>& ignore = sim.ignoredParts();  // a head that folds into itself
        tbb::parallel_for(size_t(0), f.strandCount(), [&](size_t s) {
            for (uint32_t i = f.first(s); i < f.offsets[s + 1]; ++i) {
                if (!f.positions[i].allFinite()) ++bad;
                else if (i > f.first(s) && collider)
                    depth[s] = std::max(depth[s], -collider->signedDistanceIgnoring(f.positions[i], nullptr, ignore[s]));
            }
        });
        nan += bad;
        const float d = *std::max_element(depth.begin(), depth.end());
        if (d > depthWorst) depthWorst = d, depthFrame = frame;
        if (perFrame) {
            const SimFrameStats& st = sim.stats();
            float grown = 0.f;  // strands grown inside another part
            for (size_t s = 0; s < depth.size(); ++s)
                if (ignore[s]) grown = std::max(grown, depth[s]);
            std::printf("frame %d: depth mm guides %.3f followers %.3f (grown inside another part %.3f); guides pinned "
                        "%zu; followers projected %zu, bent %zu, pinned %zu, left inside %zu (%.3f mm)\n",
                        frame, 1e3 * *std::max_element(depth.begin(), depth.begin() + long(guides)),
                        1e3 * *std::max_element(depth.begin() + long(guides), depth.end()), 1e3 * grown,
                        st.guides.pinnedCount,
                        st.followerProjected, st.followers.bent, st.followers.pinned, st.followers.penetrationCount,
                        1e3 * st.followers.maxPenetration);
        }
        const auto* parts = dynamic_cast<const PartsCollider*>(collider);
        if (worstVertex && parts) {
            const std::optional<CachedGuides> cached = sim.cachedGuides();
            const std::vector<FollowerPin> none;
            std::printf("frame %d:\n", frame);
            const MeshPartition& partition = sim.head().motion->partition();
            std::vector<TriangleMesh> posed;
            for (size_t k = 0; k < partition.count(); ++k) posed.push_back(partition.part(sim.pose().mesh, k));
            const MeshCollider posedMesh(sim.pose().mesh);
            std::vector<std::unique_ptr<MeshCollider>> posedExact;
            for (size_t k = 0; k < partition.count(); ++k)
                posedExact.push_back(std::make_unique<MeshCollider>(posed[k], partition.welds[k]));
            crossCheck("guide", f, 0, guides, *parts, posed, posedExact, ignore);
            crossCheck("follower", f, guides, f.strandCount(), *parts, posed, posedExact, ignore);
            explainWorst("guide", f, 0, guides, *parts, posed, ignore, none, partition, posedMesh);
            explainWorst("follower", f, guides, f.strandCount(), *parts, posed, ignore,
                         cached ? cached->current.pins : none, partition, posedMesh);
        }
    }
    std::printf("| steps/s | worst stretch guides (frame) | worst stretch followers (frame) | worst depth mm (frame) "
                "| pinned guides / followers (most in a frame) | followers bent (most in a frame) | NaN | cuts |\n"
                "|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    std::printf("| %.1f | %.2e (%d) | %.2e (%d) | %.3f (%d) | %zu / %zu | %zu | %zu | %d |\n", double(steps) / simSeconds,
                guideWorst, guideFrame, followerWorst, followerFrame, depthWorst * 1e3, depthFrame, pinnedWorst,
                followerPinnedWorst, followerBentWorst, nan, resets);
    return 0;
}

/// Steps/s of B-sim with the head's collider made by `collider(pose)`.
template <typename MakeCollider>
double headOnly(size_t count, MakeCollider&& collider, StepStats& stats) {
    const float radius = 0.1f;
    SpinningSphere head(radius, 90.f);
    const std::vector<Vec3f> dirs = fibonacciCap(count);
    auto posed = [&](double time, std::vector<SurfaceFrame>& roots) {
        HeadPose p = head.sample(time);
        p.collider = collider(p);
        roots.resize(dirs.size());
        for (size_t i = 0; i < dirs.size(); ++i) {
            const Vec3f n = p.transform.linear() * dirs[i];
            roots[i] = {p.transform * (radius * dirs[i]), n, n.unitOrthogonal()};
        }
        return p;
    };
    GuideSolver solver{GuideSettings{}};
    std::vector<SurfaceFrame> roots;
    HeadPose p = posed(0.0, roots);
    solver.initialize(roots, p);
    Clock::time_point start;
    for (int k = 1; k <= 270; ++k) {
        if (k == 21) start = Clock::now();
        p = posed(solver.nextTime(), roots);
        const StepStats& s = solver.step(roots, p);
        if (k == 21) stats = s;
        else if (k > 21) stats.accumulate(s);
    }
    return 250.0 / since(start);
}

int colliders(const std::vector<size_t>& counts) {
    const std::shared_ptr<const LevelSet> grid =
        std::make_shared<LevelSet>(makeSphereMesh(Vec3f::Zero(), 0.1f, 64, 128), LevelSetSettings{});
    ColliderShape ball;
    ball.kind = ColliderShape::Kind::Sphere;
    ball.radius = 0.1f;
    const CollisionWorld world({ball});
    std::printf("B-sim head-only (sphere r=0.1 m, 90 deg/s, rope, 250 timed steps): the head's collider\n\n"
                "| guides | collider | steps/s | max stretch | max penetration mm |\n|---:|---|---:|---:|---:|\n");
    for (size_t n : counts) {
        auto row = [&](const char* name, double sps, const StepStats& s) {
            std::printf("| %zu | %s | %.0f | %.2e | %.3f |\n", n, name, sps, s.maxLengthError, s.maxPenetration * 1e3);
        };
        StepStats s;
        double sps = headOnly(n, [](const HeadPose& p) {
            return std::make_shared<SphereCollider>(Vec3f(p.transform.translation()), 0.1f);
        }, s);
        row("analytic sphere (B-sim's own)", sps, s);
        sps = headOnly(n, [&](const HeadPose& p) { return std::make_shared<LevelSetCollider>(grid, p.transform); }, s);
        row("distance grid (fast path, 2 mm voxels)", sps, s);
        sps = headOnly(n, [&](const HeadPose& p) { return world.posed({p.transform}); }, s);
        row("Bullet world: btSphereShape, GJK/EPA", sps, s);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    std::string scenePath = "scenes/stress.yaml";
    std::vector<std::string> overrides;
    std::vector<size_t> counts{94, 845};
    int threads = 2;
    bool colliderMode = false, perFrame = false, worstVertex = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "bench_stress: %s needs a value\n", a.c_str());
                std::exit(1);
            }
            return argv[++i];
        };
        if (a == "--scene") scenePath = next();
        else if (a == "--set") overrides.push_back(next());
        else if (a == "--threads") threads = std::stoi(next());
        else if (a == "--colliders") colliderMode = true;
        else if (a == "--per-frame") perFrame = true;
        else if (a == "--worst") worstVertex = true;
        else if (a == "--guides") {
            counts.clear();
            const std::string list = next();
            for (size_t at = 0; at < list.size();) {
                const size_t comma = std::min(list.find(',', at), list.size());
                counts.push_back(std::stoul(list.substr(at, comma - at)));
                at = comma + 1;
            }
        } else {
            std::fprintf(stderr, "bench_stress: unknown option %s\n", a.c_str());
            return 1;
        }
    }
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    std::printf("threads: %d\n", threads);
    try {
        return colliderMode ? colliders(counts) : stress(scenePath, overrides, perFrame, worstVertex);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_stress: %s\n", e.what());
        return 1;
    }
}
