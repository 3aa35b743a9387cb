// @brief The Embree reference renderer: ray-traced frames of the strands and
// the head, to compare the GL preview against.
//
// Two shading modes share one camera, light set and geometry:
// - kajiya-kay: the preview's model, exactly kajiyaKay() of render/view/view.h
//   with the View's HairMaterial, direct light only, with ray-traced shadows
//   through semi-transparent hair (HairMaterial::transmittance per strand
//   crossing, the same parameter the preview's voxel shadows derive from). Any difference
//   to the preview is then visibility, shadows and anti-aliasing, not shading.
// - physical: a path tracer with Chiang et al.'s hair BSDF (render/reference/hair_bsdf.h)
//   and the head's energy-conserving skinShade (render/view/view.h); shadow rays see hair as opaque because light that
//   passes through strands is carried by the BSDF's transmission lobes.
//   Shadow rays of light samples with a small unshadowed contribution are
//   traced by Russian roulette (ReferenceSettings::shadowRouletteThreshold):
//   unbiased, and most of dark hair's shadow rays are skipped. Every light
//   casts shadows (ReferenceSettings::unshadowedLights); lights with size
//   (render/reference/light_sampling.h) and the environment
//   (render/reference/environment_light.h) are sampled both ways and combined
//   by multiple importance sampling; paths end by Russian roulette from the
//   second bounce on.
//
// Sampling: each pixel is the mean of its own samples, placed by filter
// importance sampling (render/reference/pixel_filter.h). With a noise
// threshold, pixels sample in passes that double their count until their
// error estimate is below it (render/reference/adaptive_sampling.h).
//
// Determinism: every random number is a hash of (seed, frame, pixel, sample,
// dimension) (render/reference/sampling.h), pixels are independent, samples are
// summed in a fixed order, and adaptive sampling decides between passes, so
// an image is bit-identical for any thread count (unless a time limit stops
// it: where the clock stops depends on the machine).
#pragma once

#include "render/image/image_io.h"
#include "render/reference/hair_bsdf.h"
#include "render/reference/pixel_filter.h"
#include "render/reference/sampling.h"
#include "render/view/view.h"
#include "sim/strands/head.h"
#include "sim/strands/strand.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace hp {

enum class ReferenceMode { KajiyaKay, Physical };

/// Physical mode: what a light with Light::castsShadows == false does.
/// - Shadowed (default, unbiased): the flag is a preview convenience and is
///   ignored; every light casts shadows and lights every bounce.
/// - FirstHit (biased): such a light lights only the camera-visible hit,
///   unshadowed, and never a point reached after a bounce (so it cannot add
///   its energy twice or light deep TT / skin paths); it is light-sampled only.
enum class UnshadowedLights { Shadowed, FirstHit };

/// Physical mode: how direct light from lights with size and the environment
/// is estimated. Mis (default) combines light and BSDF sampling with the
/// power heuristic; the other two exist to test that all three agree.
enum class LightStrategy { Mis, LightOnly, BsdfOnly };

/// "kajiya-kay" / "physical".
const char* referenceModeName(ReferenceMode mode);

struct ReferenceSettings {
    ReferenceMode mode = ReferenceMode::KajiyaKay;
    /// Fixed sample count of every pixel when noiseThreshold is 0.
    int samplesPerPixel = 16;
    /// Adaptive sampling (Cycles' estimate, adaptive_sampling.h): a pixel
    /// stops when its error estimate falls below this; 0 = off (every pixel
    /// takes samplesPerPixel).
    float noiseThreshold = 0.f;
    int minSamples = 16;         ///< adaptive: first pass (a power of two)
    int maxSamples = 1024;       ///< adaptive: no pixel goes past this (a power of two)
    /// Seconds from the start of sampling (after the scene's build) after
    /// which no further pass or tile starts (0 = none). Pixels keep the samples they have; the image
    /// then depends on the machine's speed.
    double timeLimit = 0.0;
    PixelFilter filter;          ///< Gaussian σ 0.5 px, radius 1.5 px (pbrt-v4's default)
    int bounces = 4;             ///< physical: indirect bounces after the first hit (0 = direct light only)
    /// physical: independent indirect paths from each camera sample's first
    /// hit, each counted 1/N (unbiased; 1 = one path, as before).
    int bounceSplits = 1;
    /// physical: efficiency-aware Russian roulette and splitting of the
    /// indirect path at the camera hit (render/reference/path_splitting.h):
    /// the first half of the first pass traces two paths a sample and
    /// measures each region's variance and cost; later samples continue
    /// N paths with E[N] = r, r in [splitMinRate, splitMaxRate] chosen per
    /// pixel, each weighted 1/r (unbiased). Measured a loss at equal time
    /// on the default shot (docs/benchmarks.md), so off by default: every
    /// sample one path (or bounceSplits).
    bool efficiencySplitting = false;
    float splitMinRate = 0.25f, splitMaxRate = 4.f;
    /// How pixels share the sampler's sequences: independent (white-noise
    /// error) or zsobol (blue noise across pixels), render/reference/sampling.h.
    sampling::SamplerType sampler = sampling::SamplerType::Independent;
    uint64_t seed = 1;
    int frame = 0;               ///< part of the random sequence, so frames decorrelate
    bool shadows = true;
    HairFiberParams fiber;           ///< physical mode
    UnshadowedLights unshadowedLights = UnshadowedLights::Shadowed;
    LightStrategy lightStrategy = LightStrategy::Mis;
    /// physical: light samples whose unshadowed contribution is below this
    /// fraction of the light's radiance (max over RGB of path throughput ×
    /// BSDF, 1/sr) trace their shadow ray by Russian roulette (unbiased,
    /// slightly noisier); 0 traces every shadow ray.
    float shadowRouletteThreshold = 1.f / 32.f;
    bool diffuseSpecularLayers = false;  ///< add diffuse.{R,G,B} and specular.{R,G,B}
    bool strandIdLayer = false;          ///< add strand_id (stable id of the nearest strand, −1 for none)
    int tileSize = 32;                   ///< pixels per tile side; tiles run in parallel (TBB)
    /// Called after each finished tile of a pass with (tiles done, tiles);
    /// calls are serialised, but may come from any thread.
    std::function<void(size_t, size_t)> progress;
    /// Called after each pass with (samples per pixel reached, fraction of
    /// pixels still sampling), from the calling thread.
    std::function<void(int, double)> passDone;
};

/// Measurements of one render.
struct ReferenceStats {
    double buildSeconds = 0.0;   ///< Embree scene construction
    double renderSeconds = 0.0;  ///< tracing and shading
    /// Process CPU time of the two phases (all threads): the work done, which
    /// a busy shared machine inflates far less than wall time.
    double buildCpuSeconds = 0.0;
    double renderCpuSeconds = 0.0;
    int64_t sceneBytes = 0;      ///< Embree memory held by the frame's scene (memory monitor)
    int64_t peakBytes = 0;       ///< Embree peak over build and render
    size_t strands = 0;
    size_t segments = 0;
    uint64_t rays = 0;           ///< camera, bounce and shadow rays
    int passes = 0;              ///< sampling passes (1 without adaptive sampling)
    int minSamples = 0;          ///< fewest samples a pixel took
    int maxSamples = 0;          ///< most samples a pixel took
    double meanSamples = 0.0;    ///< samples per pixel, averaged over the image
    double convergedFraction = 0.0;  ///< pixels whose error ended below the threshold
    double meanError = 0.0;      ///< the error layer averaged over the image
    bool timeLimitReached = false;
    /// With efficiencySplitting: the indirect paths' rates chosen for the
    /// pixels (1 without).
    float minSplitRate = 1.f, maxSplitRate = 1.f;
    double meanSplitRate = 1.0;  ///< over the image
};

/// Channel names of the output image, in order: R G B A Z, samples (the
/// pixel's sample count), error (its final error estimate,
/// adaptive_sampling.h pixelError), then diffuse.R/G/B and specular.R/G/B
/// if asked for, then strand_id. Colour is linear and
/// premultiplied by A (coverage), plus the environment seen where nothing is
/// hit (zero with the default black environment); Z is the view-space depth
/// of the nearest sample, camera.farClip where nothing was hit.
std::vector<std::string> referenceChannels(const ReferenceSettings& settings);

class EmbreeScene;

/// One frame's geometry as the renderer traces it (the Embree scene of its
/// strands and head), built once for several renders of that frame: the
/// physical reference and its Kajiya-Kay companion trace the same scene.
/// Made by ReferenceRenderer::build; must not outlive that renderer.
class ReferenceGeometry {
  public:
    ~ReferenceGeometry();
    ReferenceGeometry(const ReferenceGeometry&) = delete;
    ReferenceGeometry& operator=(const ReferenceGeometry&) = delete;

    double buildSeconds = 0.0, buildCpuSeconds = 0.0;
    int64_t sceneBytes = 0;  ///< Embree memory the scene holds

  private:
    friend class ReferenceRenderer;
    ReferenceGeometry() = default;
    std::unique_ptr<EmbreeScene> scene_;
};

/// Renders frames; keeps one Embree device alive across them. A render
/// given the strands and head builds the frame's scene and releases it
/// before returning; build() keeps one for several renders.
class ReferenceRenderer {
  public:
    ReferenceRenderer();
    ~ReferenceRenderer();
    ReferenceRenderer(const ReferenceRenderer&) = delete;
    ReferenceRenderer& operator=(const ReferenceRenderer&) = delete;

    /// `strands` and `head` may be null (nothing of that kind). The image has
    /// view.camera.width × height pixels. Throws FrameError for broken input
    /// (NaN vertices, negative radii) or invalid settings.
    Image render(const View& view, const StrandFrame* strands, const TriangleMesh* head,
                 const ReferenceSettings& settings, ReferenceStats* stats = nullptr);

    /// The frame's geometry, for render(view, geometry, ...); same inputs
    /// and errors as render(view, strands, head, ...). Rendering from it
    /// gives the same bits as rendering from the strands and head.
    std::unique_ptr<ReferenceGeometry> build(const StrandFrame* strands, const TriangleMesh* head);
    /// Renders a built frame; the stats' build figures are the geometry's.
    Image render(const View& view, const ReferenceGeometry& geometry, const ReferenceSettings& settings,
                 ReferenceStats* stats = nullptr);

    /// Bytes Embree holds between renders (should return to its idle value).
    int64_t embreeBytesInUse() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace hp
