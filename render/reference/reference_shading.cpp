#include "render/reference/reference_shading.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hp {

namespace {

constexpr float kInvPi = float(1.0 / M_PI);
constexpr float kInf = std::numeric_limits<float>::infinity();

/// Offset off the head's surface for rays leaving it: far above float error
/// at head scale, far below a hair radius.
/// Shadow rays from the head see hair only (RayStart::throughHead says why).
const RayStart kFromHead{kNoStrand, 0, true};

float surfaceOffset(const Vec3f& p) { return 4e-6f * (1.f + p.cwiseAbs().maxCoeff()); }

/// Local frame of a fibre hit: x along the tangent, z the viewer's direction
/// projected into the normal plane, y = z × x (render/reference/hair_bsdf.h).
struct FiberFrame {
    Vec3f x, y, z;
    Vec3f toLocal(const Vec3f& w) const { return {w.dot(x), w.dot(y), w.dot(z)}; }
    Vec3f toWorld(const Vec3f& w) const { return w.x() * x + w.y() * y + w.z() * z; }
};

FiberFrame fiberFrame(const Vec3f& tangent, const Vec3f& wo) {
    FiberFrame f;
    f.x = tangent;
    Vec3f perp = wo - wo.dot(tangent) * tangent;
    if (perp.squaredNorm() < 1e-12f) {
        Vec3f b2;
        sampling::orthonormalBasis(tangent, &perp, &b2);
    }
    f.z = perp.normalized();
    f.y = f.z.cross(f.x);
    return f;
}

/// h = sin γo: the hit's offset across the fibre, from the tube's surface
/// normal projected into the normal plane (y component; see hair_bsdf.h).
float fiberOffset(const FiberFrame& f, const Vec3f& ng) {
    Vec3f n = ng - ng.dot(f.x) * f.x;
    const float len = n.norm();
    if (len < 1e-6f) return 0.f;
    return std::clamp(n.dot(f.y) / len, -1.f, 1.f);
}

/// Fraction of the light toward direction l (distance `distance`) that
/// reaches p: 1 without shadows.
float visibility(const ShadingContext& ctx, const Vec3f& p, const Vec3f& l, float distance, float hairTransmittance,
                 const RayStart& start, uint32_t* rays) {
    if (!ctx.settings.shadows) return 1.f;
    ++*rays;
    const float tfar = std::isfinite(distance) ? distance : kInf;
    return ctx.scene.transmittance(p, l, 0.f, tfar, hairTransmittance, start);
}

/// Shadow-ray Russian roulette of the physical mode: a light sample whose
/// unshadowed contribution β·S·L is small next to the light's own radiance L
/// (max over RGB of β·S below `threshold`, in 1/sr) traces its shadow ray only
/// with probability q = max(β·S)/threshold and, when traced, counts 1/q
/// times. E[visibility · [traced] / q] = E[visibility], so the estimate stays
/// unbiased; the extra noise is at most of the order of the threshold times
/// the small contributions themselves. Dark hair makes most light samples
/// small (its BSDF lobes are narrow and absorbing): at brown hair and the
/// default threshold about 80% of the shadow rays are skipped.
/// Returns the weight 1/q, or 0 when the shadow ray is skipped.
float shadowRoulette(const Vec3f& throughput, float threshold, float u) {
    const float c = throughput.maxCoeff();
    if (!(c > 0.f)) return 0.f;
    if (!(threshold > 0.f) || c >= threshold) return 1.f;
    const float q = c / threshold;
    return u < q ? 1.f / q : 0.f;
}

/// Light leaving `light` toward p, with shadowing. `start` lets the shadow
/// ray skip the surface it leaves.
Vec3f incident(const ShadingContext& ctx, const Light& light, const Vec3f& p, float hairTransmittance,
               const RayStart& start, Vec3f* l, uint32_t* rays) {
    Vec3f radiance;
    float distance;
    *l = light.toLight(p, &radiance, &distance);
    if (radiance.maxCoeff() <= 0.f || !light.castsShadows) return radiance;
    return radiance * visibility(ctx, p, *l, distance, hairTransmittance, start, rays);
}

// ------------------------------------------------------------ kajiya-kay --

SampleResult shadeKajiyaKay(const ShadingContext& ctx, const Vec3f& o, const Vec3f& d, const SceneHit& hit) {
    SampleResult r;
    const View& view = ctx.view;
    const float T = view.hair.transmittance;
    const Vec3f p = o + hit.t * d;
    const Vec3f v = -d;
    Vec3f l;
    if (hit.kind == SceneHit::Kind::Hair) {
        const CurvePoint cp = ctx.scene.curvePoint(hit.segment, hit.u);
        const Vec3f& t = cp.tangent;
        // The shading normal only orients shifted tangents: the view-facing
        // normal, as a ribbon in the preview has.
        const FiberFrame frame = fiberFrame(t, v);
        const RayStart start{hit.strand, hit.segment};
        for (const Light& light : view.lights) {
            const Vec3f radiance = incident(ctx, light, p, T, start, &l, &r.rays);
            Vec3f diffuse, specular;
            kajiyaKay(view.hair, t, frame.z, l, v, &diffuse, &specular);
            r.diffuse += diffuse.cwiseProduct(radiance);
            r.specular += specular.cwiseProduct(radiance);
        }
        // A constant environment lights hair as an ambient diffuse term.
        r.diffuse += view.environment.cwiseProduct(view.hair.color) * view.hair.kd;
    } else {
        Vec3f n = ctx.scene.headShadingNormal(hit.triangle, hit.b1, hit.b2);
        Vec3f ng = hit.ng;
        if (ng.dot(v) < 0.f) ng = -ng;
        if (n.dot(ng) < 0.f) n = -n;
        const Vec3f q = p + surfaceOffset(p) * ng;
        r.diffuse = view.head.color.cwiseProduct(Vec3f::Constant(view.head.ambient) + view.environment);
        for (const Light& light : view.lights) {
            Vec3f radiance;
            l = light.toLight(q, &radiance, nullptr);
            const Vec3f f = skinShade(view.head, n, l, v);
            if (f.maxCoeff() <= 0.f) continue;  // no shadow ray where the light cannot reach
            r.diffuse += f.cwiseProduct(incident(ctx, light, q, T, kFromHead, &l, &r.rays));
        }
    }
    r.radiance = r.diffuse + r.specular;
    return r;
}

// -------------------------------------------------------------- physical --

SampleResult tracePhysical(const ShadingContext& ctx, Vec3f o, Vec3f d, SceneHit hit,
                           sampling::PixelSampler& sampler) {
    SampleResult r;
    const View& view = ctx.view;
    Vec3f beta = Vec3f::Ones();
    Vec3f l;
    // Past the last bounce one more BSDF-sampled ray still gathers the
    // environment (its direct light), when there is one.
    const bool environment = view.environment.maxCoeff() > 0.f;
    for (int bounce = 0;; ++bounce) {
        const bool last = bounce >= ctx.settings.bounces;
        const Vec3f p = o + hit.t * d;
        const Vec3f wo = -d;
        Vec3f nextDir;
        RayStart start;
        Vec3f nextOrigin = p;
        if (hit.kind == SceneHit::Kind::Hair) {
            const CurvePoint cp = ctx.scene.curvePoint(hit.segment, hit.u);
            const FiberFrame frame = fiberFrame(cp.tangent, wo);
            const HairBsdf bsdf(ctx.hair, fiberOffset(frame, hit.ng));
            const Vec3f woL = frame.toLocal(wo);
            start = RayStart{hit.strand, hit.segment};
            for (const Light& light : view.lights) {
                const float u = sampler.nextSide();
                Vec3f radiance;
                float distance;
                l = light.toLight(p, &radiance, &distance);
                if (radiance.maxCoeff() <= 0.f) continue;
                Vec3f lobes[HairModel::kLobes];
                const Vec3f f = bsdf.eval(woL, frame.toLocal(l), lobes);
                const float weight = shadowRoulette(beta.cwiseProduct(f), ctx.settings.shadowRouletteThreshold, u);
                if (weight <= 0.f) continue;
                if (light.castsShadows) radiance *= visibility(ctx, p, l, distance, 0.f, start, &r.rays);
                radiance *= weight;
                r.radiance += beta.cwiseProduct(f).cwiseProduct(radiance);
                if (bounce == 0) r.specular += lobes[0].cwiseProduct(radiance);
            }
            if (last && !environment) break;
            const Vec2f u0 = sampler.next2D(), u1 = sampler.next2D();
            const HairSample s = bsdf.sample(woL, u0, u1);
            if (!s.valid) break;
            beta = beta.cwiseProduct(s.weight);
            nextDir = frame.toWorld(s.wi).normalized();
        } else {
            Vec3f n = ctx.scene.headShadingNormal(hit.triangle, hit.b1, hit.b2);
            Vec3f ng = hit.ng;
            if (ng.dot(wo) < 0.f) ng = -ng;
            if (n.dot(ng) < 0.f) n = -n;
            nextOrigin = p + surfaceOffset(p) * ng;
            const Vec3f albedo = view.head.color;
            for (const Light& light : view.lights) {
                const float u = sampler.nextSide();
                Vec3f radiance;
                float distance;
                l = light.toLight(nextOrigin, &radiance, &distance);
                if (radiance.maxCoeff() <= 0.f) continue;
                // The head's material with the cosine, as S is for hair; over π
                // for a Lambert part that conserves energy (render/view/view.h).
                const Vec3f f = skinShade(view.head, n, l, wo) * kInvPi;
                if (f.maxCoeff() <= 0.f) continue;
                const float weight = shadowRoulette(beta.cwiseProduct(f), ctx.settings.shadowRouletteThreshold, u);
                if (weight <= 0.f) continue;
                if (light.castsShadows) radiance *= visibility(ctx, nextOrigin, l, distance, 0.f, kFromHead, &r.rays);
                radiance *= weight;
                r.radiance += beta.cwiseProduct(f).cwiseProduct(radiance);
            }
            if (last && !environment) break;
            Vec3f b1, b2;
            sampling::orthonormalBasis(n, &b1, &b2);
            const Vec3f w = sampling::cosineHemisphere(sampler.next2D());
            nextDir = (w.x() * b1 + w.y() * b2 + w.z() * n).normalized();
            if (nextDir.dot(ng) <= 0.f) break;
            beta = beta.cwiseProduct(albedo);  // (albedo/π · cos) / (cos/π)
        }
        // Russian roulette: continue with probability max(β) (≤ 1) and
        // reweight, which is unbiased and stops the many paths that dark
        // hair has already absorbed.
        if (!last) {
            const float survive = std::min(1.f, beta.maxCoeff());
            if (survive < 1.f) {
                if (!(sampler.next1D() < survive)) break;
                beta /= survive;
            }
        }
        o = nextOrigin;
        d = nextDir;
        ++r.rays;
        hit = ctx.scene.intersect(o, d, 0.f, kInf, start);
        if (hit.kind == SceneHit::Kind::None) {
            r.radiance += beta.cwiseProduct(view.environment);
            break;
        }
        if (last) break;
    }
    r.diffuse = r.radiance - r.specular;
    return r;
}

}  // namespace

SampleResult shadeSample(const ShadingContext& ctx, const Vec3f& origin, const Vec3f& dir, const SceneHit& hit,
                         sampling::PixelSampler& sampler) {
    SampleResult r;
    if (hit.kind == SceneHit::Kind::None) {
        r.radiance = r.diffuse = ctx.view.environment;
        r.rays = 1;
        return r;
    }
    r = ctx.settings.mode == ReferenceMode::KajiyaKay ? shadeKajiyaKay(ctx, origin, dir, hit)
                                                      : tracePhysical(ctx, origin, dir, hit, sampler);
    r.rays += 1;
    r.hit = true;
    const Camera& cam = ctx.view.camera;
    r.depth = (origin + hit.t * dir - cam.position).dot((cam.target - cam.position).normalized());
    // The id table is large and cold: read it only for the id layer.
    if (hit.kind == SceneHit::Kind::Hair && ctx.settings.strandIdLayer) r.strandId = ctx.scene.strandId(hit.strand);
    return r;
}

}  // namespace hp
