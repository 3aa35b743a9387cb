#include "render/reference/reference.h"

#include "core/errors.h"
#include "render/reference/embree_scene.h"
#include "render/reference/adaptive_sampling.h"
#include "render/reference/path_splitting.h"
#include "render/reference/reference_shading.h"

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <chrono>
#include <ctime>
#include <limits>
#include <mutex>

namespace hp {

const char* referenceModeName(ReferenceMode mode) {
    return mode == ReferenceMode::Physical ? "physical" : "kajiya-kay";
}

std::vector<std::string> referenceChannels(const ReferenceSettings& s) {
    std::vector<std::string> c{"R", "G", "B", "A", "Z", "samples", "error"};
    if (s.diffuseSpecularLayers)
        for (const char* n : {"diffuse.R", "diffuse.G", "diffuse.B", "specular.R", "specular.G", "specular.B"})
            c.push_back(n);
    if (s.strandIdLayer) c.push_back("strand_id");
    return c;
}

struct ReferenceRenderer::Impl {
    EmbreeDevice device;
};

ReferenceRenderer::ReferenceRenderer() : impl_(std::make_unique<Impl>()) {}
ReferenceRenderer::~ReferenceRenderer() = default;

int64_t ReferenceRenderer::embreeBytesInUse() const { return impl_->device.bytesInUse(); }

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
double cpuSecondsSince(std::clock_t c0) { return double(std::clock() - c0) / CLOCKS_PER_SEC; }

void checkSettings(const View& view, const ReferenceSettings& s) {
    if (view.camera.width <= 0 || view.camera.height <= 0)
        throw FrameError(cat("reference: image size ", view.camera.width, "x", view.camera.height, " is empty"));
    if (s.samplesPerPixel < 1) throw FrameError(cat("reference: ", s.samplesPerPixel, " samples per pixel"));
    if (s.noiseThreshold < 0.f || !std::isfinite(s.noiseThreshold))
        throw FrameError(cat("reference: noise threshold ", s.noiseThreshold));
    if (s.noiseThreshold > 0.f) {
        if (s.minSamples < 1 || !isPowerOfTwo(uint32_t(s.minSamples)) || s.maxSamples < s.minSamples ||
            !isPowerOfTwo(uint32_t(s.maxSamples)))
            throw FrameError(cat("reference: adaptive sample counts ", s.minSamples, "..", s.maxSamples,
                                 " must be powers of two with min <= max"));
    }
    if (!(s.filter.radius > 0.f) || (s.filter.type == PixelFilterType::Gaussian && !(s.filter.sigma > 0.f)))
        throw FrameError(cat("reference: pixel filter radius ", s.filter.radius, ", sigma ", s.filter.sigma));
    if (s.bounces < 0) throw FrameError(cat("reference: ", s.bounces, " bounces"));
    if (s.bounceSplits < 1) throw FrameError(cat("reference: ", s.bounceSplits, " bounce splits"));
    if (s.tileSize < 1) throw FrameError(cat("reference: tile size ", s.tileSize));
    const float t = view.hair.transmittance;
    if (!(t >= 0.f && t <= 1.f)) throw FrameError(cat("reference: hair transmittance ", t, " is outside [0, 1]"));
}

/// Flush-to-zero and denormals-are-zero for the current thread while alive:
/// Embree's traversal slows down badly on denormals (it warns about this),
/// and thin hair makes them likely. The previous mode is restored, since TBB
/// workers run other code afterwards.
class FlushDenormals {
  public:
    FlushDenormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | 0x8040u); }
    ~FlushDenormals() { _mm_setcsr(saved_); }
    FlushDenormals(const FlushDenormals&) = delete;
    FlushDenormals& operator=(const FlushDenormals&) = delete;

  private:
    unsigned saved_;
};

/// What a pixel has gathered so far: sums of its samples in a fixed order.
struct PixelState {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Vector3d firstHalf = Eigen::Vector3d::Zero();  ///< sum of the first n/2 samples
    uint32_t n = 0;
    uint32_t covered = 0;
    float depth = 0.f;
    float error = std::numeric_limits<float>::infinity();
};

/// The image being sampled: per-pixel sums, the optional layers' sums and
/// which pixels still sample.
struct Film {
    int width, height;
    std::vector<PixelState> pixels;
    std::vector<Eigen::Vector3d> diffuse, specular;  ///< with the diffuse/specular layers
    std::vector<int64_t> ids;                        ///< with the id layer
    std::vector<uint8_t> active;
    /// Efficiency-aware splitting: the training samples' statistics while
    /// `rates` is empty, then each pixel's rate of indirect paths.
    std::vector<SplitStats> splitStats;
    std::vector<float> rates;

    Film(int w, int h, const ReferenceSettings& s, float farClip)
        : width(w), height(h), pixels(size_t(w) * size_t(h)), active(pixels.size(), 1) {
        for (PixelState& p : pixels) p.depth = farClip;
        if (s.diffuseSpecularLayers)
            diffuse.assign(pixels.size(), Eigen::Vector3d::Zero()), specular = diffuse;
        if (s.strandIdLayer) ids.assign(pixels.size(), -1);
        if (s.efficiencySplitting && s.mode == ReferenceMode::Physical) splitStats.resize(pixels.size());
    }
};

/// Takes each active pixel of one tile from its sample count up to `target`
/// samples (indices n .. target−1 of its sequence). The first half's sum is
/// kept at index target/2, which is where the previous pass stopped.
uint64_t sampleTile(const ShadingContext& ctx, const sampling::SamplerLayout& layout, Film& film, int x0, int y0, int x1,
                    int y1, uint32_t target) {
    const ReferenceSettings& s = ctx.settings;
    const Camera& cam = ctx.view.camera;
    const bool layers = !film.diffuse.empty(), ids = !film.ids.empty();
    const FlushDenormals flush;
    const CameraRays camera(cam);
    uint64_t rays = 0;
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
            const size_t k = size_t(y) * size_t(film.width) + size_t(x);
            if (!film.active[k]) continue;
            PixelState& px = film.pixels[k];
            SplitStats* train = film.rates.empty() && !film.splitStats.empty() ? &film.splitStats[k] : nullptr;
            // Training samples trace two paths (each weighted 1/2) to measure
            // what splitting would average out (path_splitting.h).
            const float rate = train ? 2.f : film.rates.empty() ? 1.f : film.rates[k];
            sampling::PixelSampler sampler(layout, x, y);
            for (uint32_t i = px.n; i < target; ++i) {
                if (i == target / 2) px.firstHalf = px.sum;
                sampler.start(i);
                const Vec2f offset = sampleFilterOffset(s.filter, sampler.next2D());
                const Vec3f dir = camera.direction(float(x) + 0.5f + offset.x(), float(y) + 0.5f + offset.y());
                const SceneHit hit = ctx.scene.intersect(cam.position, dir, 0.f, std::numeric_limits<float>::infinity());
                const SampleResult r = shadeSample(ctx, cam.position, dir, hit, sampler, rate);
                rays += r.rays;
                if (train) {
                    // As one path: D + I₁, and half the indirect cost of two.
                    const float i1 = r.pathCount > 0 ? r.paths[0] : 0.f, i2 = r.pathCount > 1 ? r.paths[1] : i1;
                    const float d = r.radiance.sum() - r.indirect.sum();
                    const float c1 = 0.5f * r.indirectCost();
                    train->add(d + i1, i1, i2, r.cost() - c1, c1);
                }
                px.sum += r.radiance.cast<double>();
                if (layers) film.diffuse[k] += r.diffuse.cast<double>(), film.specular[k] += r.specular.cast<double>();
                if (r.hit) {
                    ++px.covered;
                    // The nearest sample decides depth and id (no filtering of ids).
                    if (r.depth < px.depth) {
                        px.depth = r.depth;
                        if (ids) film.ids[k] = r.strandId;
                    }
                }
            }
            if (px.n < target) {
                px.n = target;
                px.error = pixelError(px.sum / double(target), px.firstHalf / double(target / 2 ? target / 2 : 1));
            }
        }
    }
    return rays;
}

/// The film's means as the output image (channels of referenceChannels).
Image resolve(const Film& film, const ReferenceSettings& s) {
    Image image(film.width, film.height, referenceChannels(s));
    const int idChannel = s.strandIdLayer ? image.channelCount() - 1 : -1;
    for (int y = 0; y < film.height; ++y)
        for (int x = 0; x < film.width; ++x) {
            const size_t k = size_t(y) * size_t(film.width) + size_t(x);
            const PixelState& p = film.pixels[k];
            const double inv = p.n ? 1.0 / double(p.n) : 0.0;
            float* px = &image.at(x, y, 0);
            for (int c = 0; c < 3; ++c) px[c] = float(p.sum[c] * inv);
            px[3] = float(double(p.covered) * inv);
            px[4] = p.depth;
            px[5] = float(p.n);
            px[6] = std::isfinite(p.error) ? p.error : 0.f;
            if (!film.diffuse.empty())
                for (int c = 0; c < 3; ++c)
                    px[7 + c] = float(film.diffuse[k][c] * inv), px[10 + c] = float(film.specular[k][c] * inv);
            if (idChannel >= 0) px[idChannel] = float(film.ids[k]);
        }
    return image;
}

}  // namespace

ReferenceGeometry::~ReferenceGeometry() = default;

std::unique_ptr<ReferenceGeometry> ReferenceRenderer::build(const StrandFrame* strands, const TriangleMesh* head) {
    EmbreeDevice& device = impl_->device;
    device.resetPeak();  // the renders' peaks then cover this build too
    const int64_t before = device.bytesInUse();
    const auto t0 = Clock::now();
    const std::clock_t c0 = std::clock();
    std::unique_ptr<ReferenceGeometry> g(new ReferenceGeometry);
    g->scene_ = std::make_unique<EmbreeScene>(device, strands, head);
    g->buildSeconds = secondsSince(t0);
    g->buildCpuSeconds = cpuSecondsSince(c0);
    g->sceneBytes = device.bytesInUse() - before;
    return g;
}

Image ReferenceRenderer::render(const View& view, const StrandFrame* strands, const TriangleMesh* head,
                                const ReferenceSettings& settings, ReferenceStats* stats) {
    checkSettings(view, settings);  // before the build: a bad setting costs no BVH
    return render(view, *build(strands, head), settings, stats);
}

Image ReferenceRenderer::render(const View& shotView, const ReferenceGeometry& geometry,
                                const ReferenceSettings& settings, ReferenceStats* stats) {
    View view = shotView;
    view.lights = shotView.worldLights();  // a camera-relative rig follows this frame's camera
    checkSettings(view, settings);
    EmbreeDevice& device = impl_->device;
    const int64_t idle = device.bytesInUse() - geometry.sceneBytes;
    const int64_t peakBefore = device.peakBytes();
    device.resetPeak();

    const auto t0 = Clock::now();  // the time limit counts from here
    const EmbreeScene& scene = *geometry.scene_;
    ReferenceStats st;
    st.buildSeconds = geometry.buildSeconds;
    st.buildCpuSeconds = geometry.buildCpuSeconds;
    st.sceneBytes = geometry.sceneBytes;
    st.strands = scene.strandCount();
    st.segments = scene.segmentCount();

    const auto t1 = Clock::now();
    const std::clock_t c1 = std::clock();
    std::vector<SampledLight> lights(view.lights.begin(), view.lights.end());
    const ShadingContext ctx{scene, view, settings, HairModel(settings.fiber), std::move(lights),
                             EnvironmentLight(view.environment, view.environmentMap)};
    Film film(view.camera.width, view.camera.height, settings, view.camera.farClip);
    const int ts = settings.tileSize;
    const int tilesX = (film.width + ts - 1) / ts, tilesY = (film.height + ts - 1) / ts;
    const size_t tiles = size_t(tilesX) * size_t(tilesY);
    const bool adaptive = settings.noiseThreshold > 0.f;
    const uint32_t last = uint32_t(adaptive ? settings.maxSamples : settings.samplesPerPixel);
    std::atomic<uint64_t> rays{0};
    std::atomic<bool> outOfTime{false};
    std::mutex progressMutex;
    // Passes: every active pixel goes to `target` samples; between passes the
    // pixels whose error is below the threshold stop (with their neighbours
    // dilated back in), and the target doubles, so counts stay powers of two.
    const uint32_t first = adaptive ? uint32_t(settings.minSamples) : last;
    // The sampler's levels are the passes (render/reference/sampling.h).
    const auto layout = sampling::SamplerLayout::make(settings.sampler, settings.seed, settings.frame, film.width,
                                                      film.height, first);
    // Efficiency-aware splitting: the first half of the first pass (two
    // paths a sample) trains each region's rate, the rest of the samples use
    // it (path_splitting.h).
    const bool training = !film.splitStats.empty();
    for (uint32_t target = training ? std::max(1u, first / 2) : first;; target *= 2) {
        std::atomic<size_t> done{0};
        tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles, 1), [&](const tbb::blocked_range<size_t>& range) {
            for (size_t t = range.begin(); t != range.end(); ++t) {
                // The first pass always completes: every pixel gets its minimum.
                if (target > first && settings.timeLimit > 0.0 && secondsSince(t0) > settings.timeLimit)
                    outOfTime = true;
                if (outOfTime) return;
                const int tx = int(t % size_t(tilesX)), ty = int(t / size_t(tilesX));
                const int x0 = tx * ts, y0 = ty * ts;
                rays += sampleTile(ctx, layout, film, x0, y0, std::min(x0 + ts, film.width),
                                   std::min(y0 + ts, film.height), target);
                if (settings.progress) {
                    std::lock_guard<std::mutex> lock(progressMutex);
                    settings.progress(++done, tiles);
                }
            }
        });
        if (training && film.rates.empty()) {
            // 5×5 pixels pool their statistics; rates are fixed from here on.
            const std::vector<SplitStats> pooled = poolSplitStats(film.splitStats, film.width, film.height, 2);
            film.rates.resize(pooled.size());
            for (size_t k = 0; k < pooled.size(); ++k)
                film.rates[k] = efficientSplitRate(pooled[k], settings.splitMinRate, settings.splitMaxRate);
            if (target < first) continue;  // the training half: the first pass goes on
        }
        ++st.passes;
        size_t sampling = 0;
        if (adaptive) {
            for (size_t k = 0; k < film.pixels.size(); ++k)
                film.active[k] = film.active[k] && !(film.pixels[k].error < settings.noiseThreshold);
            dilateActive(film.active, film.width, film.height);
            for (uint8_t a : film.active) sampling += a;
        }
        if (settings.passDone) settings.passDone(int(target), double(sampling) / double(film.pixels.size()));
        if (!adaptive || sampling == 0 || outOfTime || target >= last) break;
    }
    st.timeLimitReached = outOfTime;
    st.minSamples = std::numeric_limits<int>::max();
    double samples = 0.0, error = 0.0;
    size_t converged = 0;
    for (const PixelState& p : film.pixels) {
        st.minSamples = std::min(st.minSamples, int(p.n));
        st.maxSamples = std::max(st.maxSamples, int(p.n));
        samples += p.n;
        if (std::isfinite(p.error)) error += p.error;
        converged += p.error < settings.noiseThreshold;
    }
    const double pixels = double(film.pixels.size());
    if (!film.rates.empty()) {
        double rateSum = 0.0;
        st.minSplitRate = std::numeric_limits<float>::max(), st.maxSplitRate = 0.f;
        for (float r : film.rates)
            rateSum += r, st.minSplitRate = std::min(st.minSplitRate, r), st.maxSplitRate = std::max(st.maxSplitRate, r);
        st.meanSplitRate = rateSum / pixels;
    }
    st.meanSamples = samples / pixels;
    st.meanError = error / pixels;
    st.convergedFraction = double(converged) / pixels;
    Image image = resolve(film, settings);
    st.renderSeconds = secondsSince(t1);
    st.renderCpuSeconds = cpuSecondsSince(c1);
    st.rays = rays.load();
    st.peakBytes = std::max(peakBefore, device.peakBytes()) - idle;
    if (stats) *stats = st;
    return image;
}

}  // namespace hp
