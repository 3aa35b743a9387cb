// Benchmark of the GL preview (docs/benchmarks.md "B-render", preview part):
// milliseconds per 1920x1080 frame with shadows on (voxel grid + shadow
// map) and 4x MSAA, camera (0, 0.05, 0.9) looking at the origin, vertical
// FOV 40 deg, one directional light (-1, -1, -1) of intensity 3, black
// background. Strands: makeSyntheticHair (24 vertices, 0.04 -> 0.01 mm radius)
// on the sphere head of radius 0.1 m, until the simulation provides the
// 845 guides + followers; the count is the same.
//
//   bench_preview [--strands 10000,100000] [--frames 3] [--warmup 1]
//                 [--profile] [--png out.png] [--shading kajiya-kay|fitted]
//                 [--lights one|rig] [--other-resolution N] [--max-lights N]
//                 [--share 0|1] [--voxels 0|1] [--shadow-map 0|1] [--msaa N] [--pieces P]
//                 [--compute 0|1] [--voxelize auto|gpu|cpu] [--line-pieces auto|stages|compute]
// --shading fitted shades with the hair material fitted to the physical
// fibre (render/reference/hair_fit.h, melanin 1.3) and dual scattering; the
// default keeps the plain Kajiya-Kay material the benchmark always had.
// --lights rig replaces B-render's one light by the default three-point rig
// (render/view/view.h threePointRig, camera-relative): the preview then
// shadows each of its lights that casts shadows (each costs a voxelization,
// a sum and a shadow map); --other-resolution sets the voxel resolution of
// the shadowed lights after the first (PreviewShadowSettings::otherResolution).
// For experiments: --max-lights N (PreviewShadowSettings::maxLights: 1 shadows
// the key alone), --share 0 (each light tessellates the strands itself),
// --voxels 0, --shadow-map 0, --msaa N, --pieces P (tessellationPixels),
// --compute 1 (shade the strand vertices in a compute pass,
// PreviewSettings::shadeInCompute; the default 0 shades every tessellated
// point in the tessellation stage), --voxelize gpu|cpu
// (PreviewShadowSettings::voxelize: the light grids rasterized by the GPU or
// splatted on the CPU; auto, the default, the CPU on llvmpipe),
// --line-pieces stages|compute (PreviewSettings::piecesInCompute: the thin
// strands' pieces by the tessellation stages or by compute passes; auto, the
// default, compute on llvmpipe).
// Per strand count: median, min and max of the timed frames (draw + glFinish,
// wall and process CPU time, llvmpipe's threads included), readback time,
// peak resident memory; --profile adds a per-pass breakdown of one extra frame
// (wall, process CPU, and the CPU of the calling thread, which on llvmpipe
// runs the vertex, tessellation and geometry shaders; the rest is its
// rasterizer threads).
#include "core/errors.h"
#include "render/preview/gl_context.h"
#include "render/preview/preview.h"
#include "render/reference/hair_fit.h"
#include "sim/strands/synthetic.h"
#include "tools/bench/b_render_view.h"
#include "tools/bench/bench_support.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

using namespace hp;

namespace {

double wallSeconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double peakMiB() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_maxrss) / 1024.0;
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<size_t> counts = {10000, 100000};
    int frames = 3, warmup = 1;
    bool profile = false;
    bool fitted = false, rig = false;
    int otherResolution = -1;
    VoxelizeOn voxelize = VoxelizeOn::Auto;
    int voxels = -1, shadowMap = -1, msaa = -1, maxLights = -1, share = -1, compute = -1, linePieces = -1;
    float pieces = -1.f;
    std::string png;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        const bool more = i + 1 < argc;
        if (a == "--strands" && more) {
            counts.clear();
            std::stringstream list(argv[++i]);
            for (std::string item; std::getline(list, item, ',');) counts.push_back(std::stoul(item));
        } else if (a == "--frames" && more) {
            frames = std::max(1, std::atoi(argv[++i]));
        } else if (a == "--warmup" && more) {
            warmup = std::max(0, std::atoi(argv[++i]));
        } else if (a == "--profile") {
            profile = true;
        } else if (a == "--shading" && more) {
            fitted = std::string(argv[++i]) == "fitted";
        } else if (a == "--lights" && more) {
            rig = std::string(argv[++i]) == "rig";
        } else if (a == "--other-resolution" && more) {
            otherResolution = std::atoi(argv[++i]);
        } else if (a == "--voxels" && more) {
            voxels = std::atoi(argv[++i]);
        } else if (a == "--shadow-map" && more) {
            shadowMap = std::atoi(argv[++i]);
        } else if (a == "--max-lights" && more) {
            maxLights = std::atoi(argv[++i]);
        } else if (a == "--line-pieces" && more) {
            const std::string v = argv[++i];
            linePieces = v == "compute" ? 1 : v == "stages" ? 0 : -1;
        } else if (a == "--compute" && more) {
            compute = std::atoi(argv[++i]);
        } else if (a == "--voxelize" && more) {
            const std::string v = argv[++i];
            voxelize = v == "cpu" ? VoxelizeOn::Cpu : v == "gpu" ? VoxelizeOn::Gpu : VoxelizeOn::Auto;
        } else if (a == "--share" && more) {
            share = std::atoi(argv[++i]);
        } else if (a == "--msaa" && more) {
            msaa = std::atoi(argv[++i]);
        } else if (a == "--pieces" && more) {
            pieces = float(std::atof(argv[++i]));
        } else if (a == "--png" && more) {
            png = argv[++i];
        } else {
            std::cerr << "usage: bench_preview [--strands N,M] [--frames N] [--warmup N] [--profile] [--png FILE] [--shading kajiya-kay|fitted] [--lights one|rig] [--other-resolution N] [--max-lights N] [--share 0|1] [--voxels 0|1] [--shadow-map 0|1] [--msaa N] [--pieces P] [--compute 0|1] [--voxelize auto|gpu|cpu] [--line-pieces auto|stages|compute]\n";
            return 1;
        }
    }
    try {
        auto context = GlContext::createHeadless();
        View view = bench::bRenderView(1920, 1080);
        if (fitted) fitHairMaterial(HairFiberParams{}, &view.hair);
        if (rig) view.lights = threePointRig();
        PreviewSettings settings;  // 4x MSAA, voxels (additive, nearest, 256^3) + 2048^2 PCF shadow map
        if (otherResolution >= 0) settings.shadow.otherResolution = otherResolution;
        if (voxels >= 0) settings.shadow.voxels = voxels != 0;
        if (shadowMap >= 0) settings.shadow.shadowMap = shadowMap != 0;
        if (msaa >= 0) settings.msaa = msaa;
        if (maxLights >= 0) settings.shadow.maxLights = maxLights;
        if (share >= 0) settings.shadow.shareTessellation = share != 0;
        settings.shadow.voxelize = voxelize;
        if (compute >= 0) settings.shadeInCompute = compute != 0;
        settings.piecesInCompute = linePieces;
        if (pieces >= 0.f) settings.tessellationPixels = pieces;
        const TriangleMesh head = makeSphereMesh(Vec3f::Zero(), 0.1f, 32, 64);
        std::printf("bench_preview: %s\n", context->description().c_str());
        std::printf("hair shading: %s\n", fitted ? "fitted (dual scattering)" : "kajiya-kay");
        int shadowing = 0;
        for (const Light& l : view.lights) shadowing += l.castsShadows;
        std::printf("lights: %s, %d with shadows\n", rig ? "three-point rig" : "one directional", shadowing);
        std::printf("B-render preview, 1920x1080, 4x MSAA, voxel shadows %d^3 + shadow map %d^2, tessellation "
                    "%.0f px pieces, %d timed frames after %d warm-up\n",
                    settings.shadow.resolution, settings.shadow.shadowMapSize, settings.tessellationPixels, frames,
                    warmup);
        std::printf("%9s %9s | %12s %10s %10s | %12s | %11s | %8s\n", "strands", "segments", "wall ms med",
                    "min", "max", "cpu ms med", "readback ms", "peak MiB");
        for (size_t count : counts) {
            SyntheticHairSettings hs;
            hs.strands = count;
            hs.vertices = 24;
            const StrandFrame strands = makeSyntheticHair(hs);
            PreviewRenderer renderer(settings);
            PreviewFrame frame;
            frame.strands = &strands;
            frame.head = &head;
            std::vector<double> wall, cpu;
            for (int f = 0; f < warmup + frames; ++f) {
                frame.time = f / 24.0;
                const double w0 = wallSeconds(), c0 = bench::processCpuSeconds();
                renderer.draw(view, frame);
                renderer.finish();
                if (f >= warmup) wall.push_back((wallSeconds() - w0) * 1e3), cpu.push_back((bench::processCpuSeconds() - c0) * 1e3);
            }
            const double r0 = wallSeconds();
            const Image image = renderer.readback();
            const double readbackMs = (wallSeconds() - r0) * 1e3;
            const bench::Stats w = bench::stats(wall), c = bench::stats(cpu);
            std::printf("%9zu %9zu | %12.0f %10.0f %10.0f | %12.0f | %11.0f | %8.0f\n", count,
                        renderer.stats().strandSegments, w.median, w.min, w.max, c.median, readbackMs, peakMiB());
            if (!png.empty() && count == counts.back()) writeImage(png, image);
            if (profile) {
                PreviewSettings p = settings;
                p.profile = true;
                renderer.setSettings(p);
                renderer.draw(view, frame);
                for (const PreviewStats::Pass& pass : renderer.stats().passes)
                    std::printf("    %-16s wall %8.1f ms  cpu %8.1f ms  (calling thread %8.1f ms)\n", pass.name.c_str(),
                                pass.wallMs, pass.cpuMs, pass.threadMs);
                renderer.setSettings(settings);
            }
        }
    } catch (const Error& e) {
        std::fprintf(stderr, "bench_preview: %s\n", e.what());
        return 1;
    }
    return 0;
}
