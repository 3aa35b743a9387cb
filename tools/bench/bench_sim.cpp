// B-sim (docs/benchmarks.md): guide simulation on a sphere head.
//
// Head: sphere r = 0.1 m at the origin spinning about +Y at 90°/s for the
// whole run. Guides: N = 94 and 845, roots on a Fibonacci lattice over the
// upper hemisphere, straight along the normal, 0.25 m, 24 vertices, collision
// radius 1 mm; gravity -9.81; one step = 0.02 s. 20 warm-up steps, then 250
// timed steps. Reports steps/s (median of --runs runs, with min-max), the
// largest segment stretch |len/rest - 1| and the deepest vertex penetration
// over the timed steps, NaN count, threads — for every formulation (rod,
// rope, rigid), with and without strand-strand collision, with the hair-hair
// grid off and on (--volume off,on,contact: on is the hair-hair grid alone,
// the scene's default; contact the grid with the wisp contact at 1.5 wisp
// diameters; the library's default is off; the settings' runs interleave),
// on 1 and 2 threads.
//
// --collider picks how the head collides, so one run compares them:
//   sphere  the analytic sphere (the benchmark's own head, the default);
//   grid    the distance-grid fast path a mesh head uses (head.collider.method
//           rigid: the rest mesh's narrow-band level set, 2 mm voxels, moved
//           by the head's rotation);
//   bullet  Bullet contact queries: the head's mesh as a rigid GImpact mesh in
//           the collision world of head.colliders (sim/collision/collision_world.h),
//           every vertex asking Bullet's broadphase and the mesh's BVH;
//   grid+box  the fast path plus a Bullet world holding a shoulder box under
//           the head (the default scene's case: the head on its grid, the
//           body through Bullet).
//
//   bench_sim [--guides 94,845] [--formulation rod,rope,rigid] [--strand-collision off,on] [--volume off,on,contact]
//             [--threads 1,2] [--runs 3] [--warmup 20] [--steps 250]
//             [--substeps 1] [--iterations 20] [--rod-substeps 2] [--rod-integrator bdf2,euler]
//             [--per-world 16] [--rate 90]
//             [--preload on|off] [--collider sphere,grid,bullet,grid+box] [--range 0.05] [--digest]
//
// --range: how far the Bullet mesh measures (the query range of
// CollisionWorld::posed; beyond it a lower bound), metres.
//
// --digest adds a column: an FNV-1a hash of the final state bytes
// (GuideSolver::saveState; rod and rope), the same for every run and thread
// count when the solver is deterministic, and unchanged by an optimisation
// that keeps the results bit for bit.
#include "sim/collision/collision_world.h"
#include "sim/collision/level_set.h"
#include "sim/collision/mesh_collider.h"
#include "sim/strands/fibonacci.h"
#include "sim/strands/sphere_roots.h"
#include "tools/bench/bench_support.h"
#include "sim/guides/guides.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

using namespace hp;

namespace {

std::vector<std::string> split(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream in(s);
    for (std::string item; std::getline(in, item, ',');) out.push_back(item);
    return out;
}

struct RunResult {
    double stepsPerSecond = 0;
    double cpuMsPerStep = 0;
    StepStats stats;
    uint64_t digest = 0;
};

/// How far a Bullet mesh collider measures (beyond: a lower bound), m.
float kRange = 0.05f;

/// The head's collider at a pose, per --collider mode (see the file comment).
class HeadColliders {
  public:
    HeadColliders(const std::string& mode, const SpinningSphere& head) : mode_(mode) {
        if (mode == "sphere") return;
        const TriangleMesh rest = head.sample(0.0).mesh;
        if (mode == "grid" || mode == "grid+box") {
            grid_ = std::make_shared<const LevelSet>(rest, LevelSetSettings{});
            exact_ = std::make_shared<const MeshCollider>(rest);
        }
        ColliderShape shape;
        if (mode == "bullet") {
            shape.kind = ColliderShape::Kind::Mesh;
            shape.points = rest.positions;
            shape.triangles = rest.triangles;
        } else if (mode == "grid+box") {
            shape.kind = ColliderShape::Kind::Box;  // shoulders: 40 x 10 x 24 cm, top 2 cm under the head
            shape.halfExtents = Vec3f(0.2f, 0.05f, 0.12f);
            boxPlace_.translation() = Vec3f(0.f, -0.17f, 0.f);
        } else if (mode != "grid") {
            std::fprintf(stderr, "bench_sim: --collider expects sphere, grid, bullet or grid+box, not %s\n", mode.c_str());
            std::exit(1);
        }
        if (mode != "grid") world_ = std::make_unique<CollisionWorld>(std::vector<ColliderShape>{shape});
    }

    /// Replaces pose.collider (the analytic sphere) by this mode's.
    void apply(HeadPose& pose) const {
        if (mode_ == "bullet") pose.collider = world_->posed({pose.transform}, kRange);
        if (grid_) pose.collider = std::make_shared<LevelSetCollider>(grid_, pose.transform, exact_);
        if (mode_ == "grid+box")
            pose.collider = std::make_shared<CompositeCollider>(pose.collider, world_->posed({boxPlace_}));
    }

  private:
    std::string mode_;
    std::shared_ptr<const LevelSet> grid_;
    std::shared_ptr<const MeshCollider> exact_;
    std::unique_ptr<CollisionWorld> world_;
    Eigen::Isometry3f boxPlace_ = Eigen::Isometry3f::Identity();
};

RunResult runOnce(const GuideSettings& settings, size_t guides, float rate, int warmup, int steps,
                  const std::string& collider, bool digest) {
    const float radius = 0.1f;
    SpinningSphere head(radius, rate);
    const HeadColliders colliders(collider, head);
    const std::vector<Vec3f> dirs = fibonacciCap(guides);
    GuideSolver solver(settings);
    HeadPose pose = head.sample(0.0);
    colliders.apply(pose);
    solver.initialize(sphereRootFrames(dirs, radius, pose), pose);
    RunResult r;
    std::chrono::steady_clock::time_point start;
    double cpu0 = 0;
    for (int k = 1; k <= warmup + steps; ++k) {
        if (k == warmup + 1) {
            start = std::chrono::steady_clock::now();
            cpu0 = bench::processCpuSeconds();
        }
        pose = head.sample(double(k) * settings.timeStep);
        colliders.apply(pose);
        const StepStats& s = solver.step(sphereRootFrames(dirs, radius, pose), pose);
        if (k > warmup) {
            if (k == warmup + 1) r.stats = s;
            else r.stats.accumulate(s);
        }
    }
    // Head sampling and root evaluation are inside the timed loop on purpose:
    // a shot driver pays them too (they are small next to the step).
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    r.stepsPerSecond = steps / seconds;
    r.cpuMsPerStep = 1000.0 * (bench::processCpuSeconds() - cpu0) / steps;
    if (digest) {
        const std::vector<char> state = solver.saveState();
        r.digest = bench::fnv1a(state.data(), state.size());
    }
    return r;
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<std::string> guideList{"94", "845"}, formList{"rod", "rope", "rigid"}, collList{"off", "on"},
        threadList{"1", "2"}, colliderList{"sphere"}, volList{"off"},
        integratorList{rodIntegratorName(GuideSettings{}.rodIntegrator)};  // the default (bdf2)
    int runs = 3, warmup = 20, steps = 250, substeps = 1, iterations = 20, perWorld = 16, rodSubsteps = 2;
    float rate = 90.f;
    bool preload = true, digest = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "bench_sim: %s needs a value\n", a.c_str());
                std::exit(1);
            }
            return argv[++i];
        };
        if (a == "--guides") guideList = split(next());
        else if (a == "--formulation") formList = split(next());
        else if (a == "--strand-collision") collList = split(next());
        else if (a == "--threads") threadList = split(next());
        else if (a == "--volume") volList = split(next());
        else if (a == "--runs") runs = std::stoi(next());
        else if (a == "--warmup") warmup = std::stoi(next());
        else if (a == "--steps") steps = std::stoi(next());
        else if (a == "--substeps") substeps = std::stoi(next());
        else if (a == "--iterations") iterations = std::stoi(next());
        else if (a == "--per-world") perWorld = std::stoi(next());
        else if (a == "--rod-substeps") rodSubsteps = std::stoi(next());
        else if (a == "--rod-integrator") integratorList = split(next());
        else if (a == "--rate") rate = std::stof(next());
        else if (a == "--preload") preload = next() != "off";
        else if (a == "--digest") digest = true;
        else if (a == "--collider") colliderList = split(next());
        else if (a == "--range") kRange = std::stof(next());
        else {
            std::fprintf(stderr, "bench_sim: unknown option %s\n", a.c_str());
            return 1;
        }
    }
    std::printf("B-sim: sphere r=0.1 m spinning %.0f deg/s about Y; %d warm-up + %d timed steps of 0.02 s; "
                "24 vertices, 0.25 m, collision radius 1 mm; substeps %d, iterations %d, %d guides per world; "
                "median of %d runs (min-max)\n\n",
                rate, warmup, steps, substeps, iterations, perWorld, runs);
    std::printf("| guides | formulation | collider | strand coll. | volume | threads | steps/s median (min-max) | CPU ms/step (min) | "
                "max stretch | max penetration mm | NaN | strand contacts/step (max) | load avg |%s\n",
                digest ? " state digest |" : "");
    std::printf("|---:|---|---|---|---|---:|---|---:|---:|---:|---:|---:|---:|%s\n", digest ? "---|" : "");
    for (const std::string& gs : guideList)
      for (const std::string& collider : colliderList)
        for (const std::string& form : formList)
          for (const std::string& integrator : form == "rod" ? integratorList : std::vector<std::string>{""})
            for (const std::string& coll : collList)
                for (const std::string& th : threadList) {
                  // The --volume settings' runs interleave (off, on, off, on, ...) so
                  // that a shared machine's load falls on each alike.
                  std::vector<std::vector<RunResult>> byVol(volList.size());
                  auto settingsFor = [&](const std::string& vol) {
                    GuideSettings s;
                    s.volume.enabled = vol != "off";
                    if (vol == "contact") s.volume.contactScale = 1.5f;  // the grid and the wisp contact
                    s.formulation = parseFormulation(form);
                    if (!integrator.empty()) s.rodIntegrator = parseRodIntegrator(integrator);
                    s.strandCollision = coll == "on";
                    s.threads = std::stoi(th);
                    s.substeps = substeps;
                    s.iterations = iterations;
                    s.strandsPerWorld = perWorld;
                    s.rodSubsteps = rodSubsteps;
                    s.preload = preload;
                    return s;
                  };
                  for (int r = 0; r < runs; ++r)
                    for (size_t vi = 0; vi < volList.size(); ++vi)
                      byVol[vi].push_back(runOnce(settingsFor(volList[vi]), std::stoul(gs), rate, warmup, steps, collider, digest));
                  for (size_t vi = 0; vi < volList.size(); ++vi) {
                    const std::string& vol = volList[vi];
                    const std::vector<RunResult>& results = byVol[vi];
                    const std::string label = integrator.empty() ? form : form + " (" + integrator + ")";
                    std::vector<double> sps, cpu;
                    StepStats worst = results[0].stats;
                    for (const RunResult& r : results) {
                        sps.push_back(r.stepsPerSecond);
                        cpu.push_back(r.cpuMsPerStep);
                        worst.accumulate(r.stats);
                    }
                    std::sort(sps.begin(), sps.end());
                    std::sort(cpu.begin(), cpu.end());
                    const double median = sps[sps.size() / 2];
                    double load[1] = {0};
                    getloadavg(load, 1);
                    std::printf("| %s | %s | %s | %s | %s | %s | %.1f (%.1f-%.1f) | %.2f (%.2f) | %.2e | %.3f | %zu | %zu | %.2f |",
                                gs.c_str(), label.c_str(), collider.c_str(), coll.c_str(), vol.c_str(), th.c_str(), median, sps.front(), sps.back(),
                                cpu[cpu.size() / 2], cpu.front(), worst.maxLengthError,
                                worst.maxPenetration * 1000.0, worst.nanCount, worst.strandContacts, load[0]);
                    if (digest) {
                        // Every run's digest must agree; a mismatch is printed as such.
                        bool same = true;
                        for (const RunResult& r : results) same = same && r.digest == results[0].digest;
                        std::printf(same ? " %016llx |" : " %016llx (runs differ) |",
                                    (unsigned long long)results[0].digest);
                    }
                    std::printf("\n");
                    std::fflush(stdout);
                  }
                }
    return 0;
}
