// Hair standing on a tipped head (issue 29): the share of strands whose
// highest vertex stands more than 2 cm above their root along world up, on
// a few frames. A groom whose rest state leans on the scalp lies down on it
// whatever way the head turns; one whose rest curvature holds the crown hair
// up as a cantilever (a pre-load that ignores the scalp) stands when the
// head tips. The strands are those the strand cache and `export-usd` hold
// (guides first, then followers), counted together and apart.
//
// The last column is the guides' mean tip drop since the first frame: with
// the head held still (--set head.clip_speed=0) it is the groom's sag.
//
//   bench_stand [--scene scenes/default.yaml] [--frames 1,36,84] [--threads 2] [--rise 0.02] [--set key=value ...]
//
// Compare:  bench_stand --set simulation.preload=true
//           bench_stand --set simulation.preload=false
#include "pipeline/scene/scene.h"
#include "pipeline/stages/shot_simulation.h"
#include "sim/collision/mesh_query.h"

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

using namespace hp;

int main(int argc, char** argv) {
    std::string path = "scenes/default.yaml", frameList = "1,36,84";
    std::vector<std::string> overrides;
    int threads = 2;
    bool detail = false;
    float rise = 0.02f;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "bench_stand: %s needs a value\n", a.c_str());
                std::exit(1);
            }
            return argv[++i];
        };
        if (a == "--scene") path = next();
        else if (a == "--frames") frameList = next();
        else if (a == "--threads") threads = std::atoi(next().c_str());
        else if (a == "--rise") rise = float(std::atof(next().c_str()));
        else if (a == "--set") overrides.push_back(next());
        else if (a == "--detail") detail = true;
        else {
            std::fprintf(stderr, "bench_stand: unknown option %s\n", a.c_str());
            return 1;
        }
    }
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(std::max(1, threads)));
    std::vector<int> frames;
    std::stringstream in(frameList);
    for (std::string item; std::getline(in, item, ',');) frames.push_back(std::atoi(item.c_str()));
    std::sort(frames.begin(), frames.end());
    const Scene scene = Scene::load(path, overrides);
    ShotSimulation sim(scene, scene.number("fps"), frames.front());
    const size_t guides = sim.guideCount();
    std::printf("strands whose highest vertex stands more than %.0f mm above their root (world up), %s", 1e3 * rise,
                path.c_str());
    for (const std::string& o : overrides) std::printf(" --set %s", o.c_str());
    std::printf("\n\n| frame | all strands | guides | followers | highest rise mm | of them standing on the first frame too | guides' mean tip drop mm |\n"
                "|---:|---:|---:|---:|---:|---:|---:|\n");
    std::vector<char> firstStanding;
    std::vector<float> firstTip;  // the guides' tip heights on the first frame
    for (int frame : frames) {
        const StrandFrame& f = sim.advanceTo(frame);
        size_t standing[2] = {0, 0}, count[2] = {0, 0}, again = 0;
        const bool isFirst = firstStanding.empty();
        if (isFirst) {
            firstStanding.assign(f.strandCount(), 0);
        }
        float highest = 0.f;
        for (size_t s = 0; s < f.strandCount(); ++s) {
            const uint32_t first = f.first(s), n = f.vertexCount(s);
            float top = f.positions[first].y();
            for (uint32_t i = 1; i < n; ++i) top = std::max(top, f.positions[first + i].y());
            const float up = top - f.positions[first].y();
            highest = std::max(highest, up);
            const int kind = s < guides ? 0 : 1;
            ++count[kind];
            standing[kind] += up > rise ? 1 : 0;
            if (isFirst) firstStanding[s] = up > rise;
            else again += up > rise && firstStanding[s] ? 1 : 0;
        }
        if (detail) {
            // The standing guides: how high their root sits, how far their
            // highest vertex rises and how far it is from the head.
            const MeshQuery head(sim.pose().mesh);
            for (size_t g = 0; g < guides; ++g) {
                const uint32_t first = f.first(g), n = f.vertexCount(g);
                uint32_t top = first;
                for (uint32_t i = 1; i < n; ++i)
                    if (f.positions[first + i].y() > f.positions[top].y()) top = first + i;
                const float up = f.positions[top].y() - f.positions[first].y();
                if (up <= rise) continue;
                int near = 0;
                for (uint32_t i = 1; i < n; ++i) near += head.closest(f.positions[first + i]).distance < 0.003f;
                std::printf("  guide %zu: root y %.1f mm, rises %.1f mm at vertex %u, which is %.1f mm off the head; "
                            "%d of %u vertices within 3 mm of it\n",
                            g, 1e3 * f.positions[first].y(), 1e3 * up, top - first,
                            1e3 * head.closest(f.positions[top]).distance, near, n - 1);
            }
        }
        // How far the guides' tips fell since the first frame (with the head
        // held still, `--set head.clip_speed=0`, the groom's sag).
        if (firstTip.empty())
            for (size_t g = 0; g < guides; ++g) firstTip.push_back(f.positions[f.first(g) + f.vertexCount(g) - 1].y());
        double drop = 0;
        for (size_t g = 0; g < guides; ++g) drop += firstTip[g] - f.positions[f.first(g) + f.vertexCount(g) - 1].y();
        drop /= double(std::max<size_t>(1, guides));
        auto pct = [](size_t a, size_t b) { return b ? 100.0 * double(a) / double(b) : 0.0; };
        std::printf("| %d | %.2f%% (%zu of %zu) | %.2f%% | %.2f%% | %.1f | %zu | %.2f |\n", frame,
                    pct(standing[0] + standing[1], count[0] + count[1]), standing[0] + standing[1],
                    count[0] + count[1], pct(standing[0], count[0]), pct(standing[1], count[1]), 1e3 * highest,
                    isFirst ? standing[0] + standing[1] : again, 1e3 * drop);
        std::fflush(stdout);
    }
    return 0;
}
