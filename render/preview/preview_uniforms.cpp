// The preview's per-pass uniform block (FrameUniforms, shaders/common.glsl's
// `Frame`): camera, lights, materials and every shadowed light's grid.
#include "render/preview/preview_gpu.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace hp {

namespace {

void copyMatrix(float* dst, const Mat4f& m) { std::memcpy(dst, m.data(), 16 * sizeof(float)); }
void set4(float* dst, float a, float b, float c, float d) { dst[0] = a, dst[1] = b, dst[2] = c, dst[3] = d; }
void set3(float* dst, const Vec3f& v, float w) { set4(dst, v.x(), v.y(), v.z(), w); }

}  // namespace

void setPassGrid(FrameUniforms& u, const LightGrid& grid, int resolution) {
    copyMatrix(u.viewProj, grid.clip());
    copyMatrix(u.lightView, grid.view);
    set4(u.gridMap, grid.scale.x(), grid.scale.y(), grid.offset.x(), grid.offset.y());
    set4(u.gridDepth, grid.nearDepth, grid.farDepth, grid.perspective ? 1.f : 0.f, float(resolution));
    const float res = float(resolution);
    set4(u.viewport, res, res, 1.f / res, 1.f / res);
}

void fillFrameUniforms(FrameUniforms& u, const UniformInputs& in) {
    std::memset(&u, 0, sizeof(u));
    const View& view = in.view;
    const PreviewSettings& settings = in.settings;
    const Camera& cam = view.camera;
    const Mat4f proj = cam.projection(), viewM = cam.view();
    const int ss = in.supersample;
    const float tw = float(cam.width * ss), th = float(cam.height * ss);
    copyMatrix(u.viewProj, proj * viewM);
    copyMatrix(u.view, viewM);
    set3(u.eye, cam.position, proj(1, 1) * 0.5f * th);
    set4(u.viewport, tw, th, 1.f / tw, 1.f / th);
    const size_t lights = std::min<size_t>(view.lights.size(), 16);
    for (size_t i = 0; i < lights; ++i) {
        const Light& l = view.lights[i];
        if (l.type == LightType::Directional) set3(u.lightVec[i], -l.direction.normalized(), 0.f);
        else set3(u.lightVec[i], l.position, 1.f);
        set3(u.lightRad[i], l.color * l.intensity, -1.f);  // w: the light's shadow slot, -1 none
    }
    // Each shadowed light's grid: the slot number in its light's lightRad.w.
    bool unshadowed = false;
    for (size_t k = 0; k < in.slots.size() && k < size_t(kMaxShadowedLights); ++k) {
        const ShadowSlot& slot = in.slots[k];
        const LightGrid& g = slot.grid;
        copyMatrix(u.slotClip[k], g.clip());
        copyMatrix(u.slotView[k], g.view);
        set4(u.slotMap[k], g.scale.x(), g.scale.y(), g.offset.x(), g.offset.y());
        set4(u.slotDepth[k], g.nearDepth, g.farDepth, g.perspective ? 1.f : 0.f, float(in.resolutions[k]));
        if (size_t(slot.light) < lights) u.lightRad[slot.light][3] = float(k);
    }
    for (size_t i = 0; i < lights; ++i) unshadowed |= u.lightRad[i][3] < 0.f;
    const HairMaterial& h = view.hair;
    set3(u.hairColor, h.color, h.kd);
    set3(u.specColor, h.specularColor, h.ks);
    set3(u.secondColor, h.secondaryColor, h.secondaryKs);
    set4(u.hairShape, h.shininess, h.secondaryShininess, h.primaryShift, h.secondaryShift);
    set3(u.headColor, view.head.color, view.head.ambient);
    set4(u.headSkin, view.head.wrap, view.head.specular, view.head.shininess, 0.f);
    const PreviewShadowSettings& sh = settings.shadow;
    // Optical depth of one unit of C (shaders/shadow.glsl).
    const float depthPerUnit = sh.weight == VoxelWeight::Crossings ? 1.f - std::clamp(h.transmittance, 0.f, 1.f)
                                                                    : -std::log(std::clamp(sh.alpha, 1e-6f, 1.f));
    set4(u.shadow, depthPerUnit, float(std::max(0, sh.pcfRadius)), 1.f / float(std::max(1, sh.shadowMapSize)),
         0.002f);
    // Fitted hair: each crossing keeps the light the fibre scatters
    // forward, a_f per colour, and spreads it by β_f² (Zinke 2008).
    const bool fittedHair = h.shading == HairShading::Fitted;
    if (fittedHair && sh.weight == VoxelWeight::Crossings)
        set3(u.shadowColor, Vec3f::Ones() - h.dual.forward.cwiseMin(Vec3f::Ones()), h.dual.forwardVariance);
    else
        set4(u.shadowColor, depthPerUnit, depthPerUnit, depthPerUnit, fittedHair ? h.dual.forwardVariance : 0.f);
    const HairLobe* lobes[4] = {&h.r, &h.trt, &h.tt, &h.dual.back};
    for (int k = 0; k < 4; ++k) {
        const HairLobe& lobe = *lobes[k];
        // z: the azimuthal variance per fibre crossed, s_φ² (the same for every lobe).
        set4(u.lobeShape[k], lobe.exponent, lobe.shift, fittedHair ? h.dual.forwardAzimuthVariance : 0.f, 0.f);
        for (int node = 0; node < kHairLobeNodes; ++node)
            set3(u.lobeStrength[k * kHairLobeNodes + node], lobe.strength[size_t(node)], 0.f);
        for (int a = 0; a < kHairLobeNodes; ++a)
            for (int b = 0; b < kHairLobeNodes; ++b) {
                const int index = (k * kHairLobeNodes + a) * kHairLobeNodes + b;
                u.lobeAzimuth[index / 4][index % 4] = lobe.azimuth[size_t(a)][size_t(b)];
            }
    }
    set4(u.tess, float(std::clamp(settings.tessellationLevel, 1, 64)), settings.tessellationPixels * float(ss),
         settings.curve == CurveType::BSpline ? 1.f : 0.f, settings.minPixelWidth * float(ss));
    set4(u.blend, in.blendReference, std::max(settings.blendDepthScale, 1e-5f), 0.f, 0.f);
    const GeneratedHairSettings& g = settings.generated;
    set3(u.gravity, g.gravity, 0.f);
    set3(u.wind, g.wind, g.gust);
    set4(u.furTime, float(in.frame.time), g.gustFrequency, std::max(g.gustWavelength, 1e-4f),
         float(std::clamp(g.innerLevel, 1, 64)));
    set4(u.furLevels, float(std::clamp(g.outerLevel, 1, 64)), 0.f, 0.f, 0.f);
    u.counts[0] = int(lights);
    u.counts[1] = int(std::min<size_t>(in.slots.size(), kMaxShadowedLights));
    u.counts[2] = (in.voxels ? kFlagVoxels : 0) | (in.shadowMap ? kFlagShadowMap : 0) |
                  (in.voxels && sh.filter ? kFlagVoxelFilter : 0) | (unshadowed ? kFlagUnshadowedLights : 0) |
                  (settings.blend == HairBlend::Sorted ? kFlagSortedHair : 0);
    u.counts[3] = fittedHair ? kHairFitted : h.twoLobes ? kHairKajiyaKayTwoLobes : kHairKajiyaKay;
}

Vec3f skinForwardAlbedo(const HairMaterial& hair) {
    if (hair.shading != HairShading::Fitted) return Vec3f::Zero();
    return hair.dual.forward.cwiseMax(Vec3f::Zero()).cwiseMin(Vec3f::Ones());
}

std::vector<std::string> hairShadingDefines(const FrameUniforms& u) {
    // Mesa's llvmpipe (gallivm) runs both sides of a branch under an
    // execution mask even when its condition is uniform: every shaded
    // vertex paid the fitted and the Kajiya-Kay model, and for each light
    // both the shadowed and the unshadowed path (docs/benchmarks.md).
    std::string lights = "HAIR_LIGHTS(F)";
    for (int i = 0; i < std::clamp(u.counts[0], 0, 16); ++i)
        lights += cat(" F(", i, ", ", int(u.lightRad[i][3]), ", ", u.lightVec[i][3] >= 0.5f ? "true" : "false", ")");
    return {cat("HAIR_FLAGS ", u.counts[2]), cat("HAIR_MODEL ", u.counts[3]), lights};
}

}  // namespace hp
