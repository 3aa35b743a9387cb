// B-render, reference part (docs/benchmarks.md): seconds per 1920×1080 frame at
// 16 spp of the Embree reference, physical mode (4 bounces) and Kajiya-Kay,
// for 10k and 100k strands × 24 vertices with shadows; Embree scene memory
// (device memory monitor) and peak RSS.
//
// Until the simulation exists the strands are makeSyntheticHair's (roots on a
// Fibonacci cap of the upper hemisphere, hanging down; root radius 0.04 mm to
// 0.01 mm at the tip) around the benchmark sphere head (r = 0.1 m), which is
// rendered too.
//
//   bench_reference [--strands 10000,100000] [--modes physical,kajiya-kay]
//                   [--width 1920] [--height 1080] [--spp 16] [--bounces 4]
//                   [--repeat 1] [--threads 2] [--out DIR] [--no-head] [--no-shadows]
//                   [--melanin 1.3] [--shadow-roulette 0.03125 (0: off)] [--seed 1]
//                   [--noise-threshold T (adaptive; 0: --spp fixed)] [--min-samples 16]
//                   [--max-samples 1024] [--time-limit S] [--filter gaussian|box]
//                   [--seeds A,B] [--sampler zsobol|independent] [--bounce-splits 1]
//                   [--splitting off|efficiency] [--split-rates MIN,MAX]
//
// B-converge (docs/benchmarks.md): with --seeds A,B every render is made with
// both sampler seeds and the two images are compared on the hair mask (FLIP,
// SSIM: render/compare/compare.h), the noise figure that needs no
// higher-sample image (and rmse2, the RMSE between the two on the mask:
// √2 times each one's RMSE against the converged image); the time column is
// then one render's.
#include "render/compare/compare.h"
#include "render/reference/reference.h"
#include "sim/strands/head.h"
#include "sim/strands/synthetic.h"
#include "tools/bench/b_render_view.h"

#include <tbb/global_control.h>

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

using namespace hp;

namespace {

std::vector<std::string> split(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream in(s);
    for (std::string item; std::getline(in, item, ',');)
        if (!item.empty()) out.push_back(item);
    return out;
}

double peakRssMiB() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_maxrss) / 1024.0;  // kilobytes on Linux
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<std::string> strandCounts{"10000", "100000"}, modes{"physical", "kajiya-kay"};
    int width = 1920, height = 1080, spp = 16, bounces = 4, repeat = 1, threads = 2, bounceSplits = 1;
    bool withHead = true, shadows = true, efficiencySplitting = false;
    float splitMin = ReferenceSettings{}.splitMinRate, splitMax = ReferenceSettings{}.splitMaxRate;
    float melanin = 1.3f;
    float shadowRoulette = ReferenceSettings{}.shadowRouletteThreshold;
    uint64_t seed = 1;
    std::vector<std::string> seeds;
    float noiseThreshold = 0.f;
    int minSamples = 16, maxSamples = 1024;
    double timeLimit = 0.0;
    PixelFilterType filter = PixelFilterType::Gaussian;
    sampling::SamplerType sampler = ReferenceSettings{}.sampler;
    std::string out;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "missing value after %s\n", a.c_str());
                std::exit(1);
            }
            return argv[++i];
        };
        if (a == "--strands") strandCounts = split(next());
        else if (a == "--modes") modes = split(next());
        else if (a == "--width") width = std::stoi(next());
        else if (a == "--height") height = std::stoi(next());
        else if (a == "--spp") spp = std::stoi(next());
        else if (a == "--bounces") bounces = std::stoi(next());
        else if (a == "--bounce-splits") bounceSplits = std::stoi(next());
        else if (a == "--splitting") efficiencySplitting = next() == "efficiency";
        else if (a == "--split-rates") {
            const std::vector<std::string> r = split(next());
            splitMin = std::stof(r.at(0)), splitMax = std::stof(r.at(1));
        }
        else if (a == "--repeat") repeat = std::max(1, std::stoi(next()));
        else if (a == "--threads") threads = std::stoi(next());
        else if (a == "--out") out = next();
        else if (a == "--no-head") withHead = false;
        else if (a == "--no-shadows") shadows = false;
        else if (a == "--melanin") melanin = std::stof(next());
        else if (a == "--shadow-roulette") shadowRoulette = std::stof(next());
        else if (a == "--seed") seed = std::stoull(next());
        else if (a == "--seeds") seeds = split(next());
        else if (a == "--noise-threshold") noiseThreshold = std::stof(next());
        else if (a == "--min-samples") minSamples = std::stoi(next());
        else if (a == "--max-samples") maxSamples = std::stoi(next());
        else if (a == "--time-limit") timeLimit = std::stod(next());
        else if (a == "--sampler")
            sampler = next() == "independent" ? sampling::SamplerType::Independent : sampling::SamplerType::ZSobol;
        else if (a == "--filter") filter = next() == "box" ? PixelFilterType::Box : PixelFilterType::Gaussian;
        else {
            std::fprintf(stderr, "unknown option %s (see the comment at the top of bench_reference.cpp)\n", a.c_str());
            return 1;
        }
    }
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));

    // docs/benchmarks.md B-render camera and light.
    View view = bench::bRenderView(width, height);
    view.lights[0].direction.normalize();
    const TriangleMesh head = makeSphereMesh(Vec3f::Zero(), 0.1f, 32, 64);

    std::printf("# bench_reference: %dx%d, %s, %d bounces (physical), %d threads, head %s, shadow roulette %g, "
                "%s filter, %s sampler, synthetic hair\n",
                width, height,
                noiseThreshold > 0.f ? ("noise threshold " + std::to_string(noiseThreshold) + ", spp " +
                                        std::to_string(minSamples) + ".." + std::to_string(maxSamples))
                                           .c_str()
                                     : (std::to_string(spp) + " spp").c_str(),
                bounces, threads, withHead ? "on" : "off", shadowRoulette, pixelFilterName(filter),
                sampling::samplerName(sampler));
    std::printf("%-8s %-11s %8s %9s %9s %9s %8s %8s %8s %10s %10s %9s %8s %8s %7s %7s %8s\n", "strands", "mode", "build_s",
                "render_s", "frame_s", "spread_s", "bcpu_s", "rcpu_s", "rays/spl", "embree_MB", "emb_peakMB", "rss_MB",
                "spp_mean", "spp_max", "flip2", "ssim2", "rmse2");
    if (seeds.empty()) seeds.push_back(std::to_string(seed));
    ReferenceRenderer renderer;
    for (const std::string& count : strandCounts) {
        SyntheticHairSettings hs;
        hs.strands = size_t(std::stoul(count));
        hs.vertices = 24;
        const StrandFrame strands = makeSyntheticHair(hs);
        for (const std::string& modeName : modes) {
            ReferenceSettings s;
            s.mode = modeName == "physical" ? ReferenceMode::Physical : ReferenceMode::KajiyaKay;
            s.samplesPerPixel = spp;
            s.bounces = bounces;
            s.bounceSplits = bounceSplits;
            s.efficiencySplitting = efficiencySplitting;
            s.splitMinRate = splitMin, s.splitMaxRate = splitMax;
            s.frame = 1;
            s.noiseThreshold = noiseThreshold;
            s.minSamples = minSamples;
            s.maxSamples = maxSamples;
            s.timeLimit = timeLimit;
            s.filter.type = filter;
            s.sampler = sampler;
            if (filter == PixelFilterType::Box) s.filter.radius = 0.5f;
            s.shadows = shadows;
            s.fiber.sigmaA = hairAbsorptionFromMelanin(melanin, 0.f);
            s.shadowRouletteThreshold = shadowRoulette;
            std::vector<double> frame, build, render, bcpu, rcpu;
            ReferenceStats st;
            std::vector<Image> images;
            for (const std::string& seedText : seeds) {
                s.seed = std::stoull(seedText);
                Image image;
                for (int r = 0; r < repeat; ++r) {
                    image = renderer.render(view, &strands, withHead ? &head : nullptr, s, &st);
                    bcpu.push_back(st.buildCpuSeconds);
                    rcpu.push_back(st.renderCpuSeconds);
                    build.push_back(st.buildSeconds);
                    render.push_back(st.renderSeconds);
                    frame.push_back(st.buildSeconds + st.renderSeconds);
                }
                images.push_back(std::move(image));
            }
            double flip2 = -1.0, ssim2 = -1.0, rmse2 = -1.0;
            if (images.size() >= 2) {
                CompareSettings cs;
                cs.mask = MaskMode::Hair;
                const FrameMetrics m = compareImages(images[0], images[1], cs).metrics;
                flip2 = m.flip, ssim2 = m.ssim, rmse2 = m.rmse;
            }
            const Image& image = images.front();
            const double spread = *std::max_element(frame.begin(), frame.end()) -
                                  *std::min_element(frame.begin(), frame.end());
            std::printf("%-8s %-11s %8.2f %9.2f %9.2f %9.2f %8.2f %8.2f %8.2f %10.1f %10.1f %9.0f %8.1f %8d %7.4f %7.4f %8.5f\n",
                        count.c_str(), modeName.c_str(), median(build), median(render), median(frame), spread,
                        median(bcpu), median(rcpu), double(st.rays) / (double(width) * height * st.meanSamples),
                        double(st.sceneBytes) / (1 << 20), double(st.peakBytes) / (1 << 20), peakRssMiB(),
                        st.meanSamples, st.maxSamples, flip2, ssim2, rmse2);
            if (s.efficiencySplitting && s.mode == ReferenceMode::Physical)
                std::printf("# efficiency splitting: indirect paths a camera sample %.3f mean, %.3f..%.3f\n",
                            st.meanSplitRate, st.minSplitRate, st.maxSplitRate);
            std::fflush(stdout);
            if (!out.empty()) {
                std::filesystem::create_directories(out);
                const std::string base = out + "/reference_" + count + "_" + modeName;
                writeImage(base + ".png", image);
                writeImage(base + ".exr", image);
            }
        }
    }
    std::printf("# embree bytes after all renders: %lld (scenes released)\n", (long long)renderer.embreeBytesInUse());
    return 0;
}
