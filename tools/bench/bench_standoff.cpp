// Body of the hair (issue 30): how far the middle of each strand stands off
// the head, frame by frame, so runs with the hair-hair grid off and on
// compare. For each strand, the vertex halfway along it; its distance to the
// frame's deformed head mesh (the exact closest point,
// sim/collision/mesh_query.h: the solver's distance grid stops measuring
// 1 cm out). Reports the median and mean over guides and over followers,
// and the share of strands whose middle lies within 5 mm of the head.
//
//   bench_standoff [--scene scenes/default.yaml] [--frames 1,36,84] [--threads 2] [--set key=value ...]
//
// Compare:  bench_standoff --set simulation.volume.enabled=false
//           bench_standoff --set simulation.volume.enabled=true
#include "pipeline/scene/scene.h"
#include "pipeline/stages/shot_simulation.h"
#include "sim/collision/mesh_query.h"

#include <tbb/global_control.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

using namespace hp;

namespace {

struct Summary {
    double median = 0, mean = 0, within5mm = 0;
};

Summary summarise(std::vector<float> d) {
    Summary s;
    if (d.empty()) return s;
    std::sort(d.begin(), d.end());
    s.median = d[d.size() / 2];
    for (float x : d) {
        s.mean += x;
        s.within5mm += x < 0.005f ? 1.0 : 0.0;
    }
    s.mean /= double(d.size());
    s.within5mm /= double(d.size());
    return s;
}

}  // namespace

int main(int argc, char** argv) {
    std::string path = "scenes/default.yaml", frameList = "1,36,84";
    std::vector<std::string> overrides;
    int threads = 2;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "bench_standoff: %s needs a value\n", a.c_str());
                std::exit(1);
            }
            return argv[++i];
        };
        if (a == "--scene") path = next();
        else if (a == "--frames") frameList = next();
        else if (a == "--threads") threads = std::atoi(next().c_str());
        else if (a == "--set") overrides.push_back(next());
        else {
            std::fprintf(stderr, "bench_standoff: unknown option %s\n", a.c_str());
            return 1;
        }
    }
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(std::max(1, threads)));
    std::vector<int> frames;
    std::stringstream in(frameList);
    for (std::string item; std::getline(in, item, ',');) frames.push_back(std::atoi(item.c_str()));
    const Scene scene = Scene::load(path, overrides);
    const double fps = scene.number("fps");
    ShotSimulation sim(scene, fps, frames.front());
    const size_t guides = sim.guideCount();
    std::printf("standoff of the strands' middles from the head, %s", path.c_str());
    for (const std::string& o : overrides) std::printf(" --set %s", o.c_str());
    std::printf("\n\n| frame | guides median mm | guides mean mm | guides within 5 mm | followers median mm | "
                "followers mean mm | followers within 5 mm | densest hair (grid) /cm² | volume pushes |\n"
                "|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int frame : frames) {
        const StrandFrame& f = sim.advanceTo(frame);
        const MeshQuery head(sim.pose().mesh);
        std::vector<float> g, fo;
        for (size_t s = 0; s < f.strandCount(); ++s) {
            const uint32_t mid = f.first(s) + f.vertexCount(s) / 2;
            (s < guides ? g : fo).push_back(head.closest(f.positions[mid]).distance);
        }
        const Summary a = summarise(g), b = summarise(fo);
        std::printf("| %d | %.1f | %.1f | %.0f%% | %.1f | %.1f | %.0f%% | %.0f | %zu |\n", frame, 1e3 * a.median,
                    1e3 * a.mean, 100 * a.within5mm, 1e3 * b.median, 1e3 * b.mean, 100 * b.within5mm,
                    sim.stats().guides.maxHairDensity, sim.stats().guides.volumePushed);
    }
    return 0;
}
