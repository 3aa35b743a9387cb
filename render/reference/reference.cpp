#include "render/reference/reference.h"

#include "core/errors.h"
#include "render/reference/embree_scene.h"
#include "render/reference/reference_shading.h"

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <ctime>
#include <limits>
#include <mutex>

namespace hp {

const char* referenceModeName(ReferenceMode mode) {
    return mode == ReferenceMode::Physical ? "physical" : "kajiya-kay";
}

std::vector<std::string> referenceChannels(const ReferenceSettings& s) {
    std::vector<std::string> c{"R", "G", "B", "A", "Z"};
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
    if (s.bounces < 0) throw FrameError(cat("reference: ", s.bounces, " bounces"));
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

/// Renders the pixels of one tile into `image`.
uint64_t renderTile(const ShadingContext& ctx, Image& image, int x0, int y0, int x1, int y1) {
    const ReferenceSettings& s = ctx.settings;
    const Camera& cam = ctx.view.camera;
    const int nc = image.channelCount();
    const bool layers = s.diffuseSpecularLayers;
    const int idChannel = s.strandIdLayer ? nc - 1 : -1;
    const float inv = 1.f / float(s.samplesPerPixel);
    const FlushDenormals flush;
    const CameraRays camera(cam);
    uint64_t rays = 0;
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
            sampling::PixelSampler sampler(s.seed, s.frame, x, y);
            Eigen::Vector3d rgb = Eigen::Vector3d::Zero(), dif = rgb, spec = rgb;
            int covered = 0;
            float depth = cam.farClip;
            int64_t id = -1;
            for (int i = 0; i < s.samplesPerPixel; ++i) {
                sampler.start(uint32_t(i));
                const Vec2f u = sampler.next2D();
                const Vec3f dir = camera.direction(float(x) + u.x(), float(y) + u.y());
                const SceneHit hit = ctx.scene.intersect(cam.position, dir, 0.f, std::numeric_limits<float>::infinity());
                const SampleResult r = shadeSample(ctx, cam.position, dir, hit, sampler);
                rays += r.rays;
                rgb += r.radiance.cast<double>();
                if (layers) dif += r.diffuse.cast<double>(), spec += r.specular.cast<double>();
                if (r.hit) {
                    ++covered;
                    // The nearest sample decides depth and id (no filtering of ids).
                    if (r.depth < depth) depth = r.depth, id = r.strandId;
                }
            }
            float* px = &image.at(x, y, 0);
            for (int c = 0; c < 3; ++c) px[c] = float(rgb[c]) * inv;
            px[3] = float(covered) * inv;
            px[4] = depth;
            if (layers)
                for (int c = 0; c < 3; ++c) px[5 + c] = float(dif[c]) * inv, px[8 + c] = float(spec[c]) * inv;
            if (idChannel >= 0) px[idChannel] = float(id);
        }
    }
    return rays;
}

}  // namespace

Image ReferenceRenderer::render(const View& shotView, const StrandFrame* strands, const TriangleMesh* head,
                                const ReferenceSettings& settings, ReferenceStats* stats) {
    View view = shotView;
    view.lights = shotView.worldLights();  // a camera-relative rig follows this frame's camera
    checkSettings(view, settings);
    EmbreeDevice& device = impl_->device;
    device.resetPeak();
    const int64_t idle = device.bytesInUse();

    const auto t0 = Clock::now();
    const std::clock_t c0 = std::clock();
    const EmbreeScene scene(device, strands, head);
    ReferenceStats st;
    st.buildSeconds = secondsSince(t0);
    st.buildCpuSeconds = cpuSecondsSince(c0);
    st.sceneBytes = device.bytesInUse() - idle;
    st.strands = scene.strandCount();
    st.segments = scene.segmentCount();

    const auto t1 = Clock::now();
    const std::clock_t c1 = std::clock();
    std::vector<SampledLight> lights(view.lights.begin(), view.lights.end());
    const ShadingContext ctx{scene, view, settings, HairModel(settings.fiber), std::move(lights),
                             EnvironmentLight(view.environment, view.environmentMap)};
    Image image(view.camera.width, view.camera.height, referenceChannels(settings));
    const int ts = settings.tileSize;
    const int tilesX = (image.width + ts - 1) / ts, tilesY = (image.height + ts - 1) / ts;
    const size_t tiles = size_t(tilesX) * size_t(tilesY);
    std::atomic<size_t> done{0};
    std::atomic<uint64_t> rays{0};
    std::mutex progressMutex;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles, 1), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t t = range.begin(); t != range.end(); ++t) {
            const int tx = int(t % size_t(tilesX)), ty = int(t / size_t(tilesX));
            const int x0 = tx * ts, y0 = ty * ts;
            rays += renderTile(ctx, image, x0, y0, std::min(x0 + ts, image.width), std::min(y0 + ts, image.height));
            if (settings.progress) {
                std::lock_guard<std::mutex> lock(progressMutex);
                settings.progress(++done, tiles);
            }
        }
    });
    st.renderSeconds = secondsSince(t1);
    st.renderCpuSeconds = cpuSecondsSince(c1);
    st.rays = rays.load();
    st.peakBytes = device.peakBytes() - idle;
    if (stats) *stats = st;
    return image;
}

}  // namespace hp
