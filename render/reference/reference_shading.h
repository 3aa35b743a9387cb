// @brief Radiance of one camera sample for the reference renderer's two modes
// (internal to render/reference/reference.cpp; see render/reference/reference.h for the models).
#pragma once

#include "render/reference/embree_scene.h"
#include "render/reference/environment_light.h"
#include "render/reference/hair_bsdf.h"
#include "render/reference/light_sampling.h"
#include "render/reference/reference.h"
#include "render/reference/sampling.h"

namespace hp {

/// Everything the shading of one frame reads; shared by all threads.
struct ShadingContext {
    const EmbreeScene& scene;
    const View& view;
    const ReferenceSettings& settings;
    HairModel hair;
    std::vector<SampledLight> lights;  ///< view.lights in world space, prepared for sampling
    EnvironmentLight environment;      ///< view.environment plus view.environmentMap
};

/// What one camera sample saw.
struct SampleResult {
    Vec3f radiance = Vec3f::Zero();
    Vec3f diffuse = Vec3f::Zero();   ///< part of radiance (kajiya-kay: diffuse term; physical: all but R at the first hit)
    Vec3f specular = Vec3f::Zero();  ///< kajiya-kay: specular term; physical: R lobe of direct light at the first hit
    bool hit = false;
    float depth = 0.f;               ///< view-space depth of the first hit
    int64_t strandId = -1;           ///< stable id of the strand hit first (with the id layer only), −1 for head or nothing
    uint32_t rays = 0;
    /// physical: what the first hit's continuation added (part of radiance,
    /// all but the camera hit's own light sampling) and its rays.
    Vec3f indirect = Vec3f::Zero();
    uint32_t indirectRays = 0;
    /// With several indirect paths from the camera hit: the first two
    /// paths' own estimates of the indirect light (R + G + B, each as if it
    /// were the only path), to measure the variance that splitting averages
    /// out (render/reference/path_splitting.h).
    float paths[2] = {0.f, 0.f};
    int pathCount = 0;
    /// Of `rays`, those leaving a strand (all in the indirect part).
    uint32_t strandRays = 0;
    /// The work of the sample in units of a camera or shadow ray: a ray
    /// leaving a strand starts inside the dense hair, and Embree takes about
    /// 2.4 times as long over it (docs/benchmarks.md, "The cost per sample":
    /// 9.7k cycles against 3.0k camera and 4.1k shadow rays).
    float cost() const { return float(rays) + 1.4f * float(strandRays); }
    float indirectCost() const { return float(indirectRays) + 1.4f * float(strandRays); }
};

/// Shades the camera ray (origin, unit dir) whose first hit is `hit`, with
/// the context's mode; further random numbers come from `sampler`.
/// `indirectRate` (physical): the camera hit continues N indirect paths,
/// E[N] = rate, each weighted 1/rate (render/reference/path_splitting.h);
/// exactly 1 traces one path and draws no extra random number.
SampleResult shadeSample(const ShadingContext& ctx, const Vec3f& origin, const Vec3f& dir, const SceneHit& hit,
                         sampling::PixelSampler& sampler, float indirectRate = 1.f);

}  // namespace hp
