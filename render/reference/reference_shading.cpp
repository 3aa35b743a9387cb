#include "render/reference/reference_shading.h"

#include "render/reference/path_splitting.h"
#include "render/reference/vertex_bsdf.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace hp {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

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
/// unshadowed contribution C is small next to the light's own scale E (the
/// irradiance a delta light of its intensity gives; max over RGB of C / E
/// below `threshold`, in 1/sr) traces its shadow ray only with probability
/// q = max(C/E)/threshold and, when traced, counts 1/q times.
/// E[visibility · [traced] / q] = E[visibility], so the estimate stays
/// unbiased; the extra noise is at most of the order of the threshold times
/// the small contributions themselves. Dark hair makes most light samples
/// small (its BSDF lobes are narrow and absorbing): at brown hair and the
/// default threshold about 80% of the shadow rays are skipped. Only samples
/// that would trace a shadow ray take part.
/// Returns the weight 1/q, or 0 when the shadow ray is skipped.
float shadowRoulette(float c, float threshold, float u) {
    if (!(c > 0.f)) return 0.f;
    if (!(threshold > 0.f) || c >= threshold) return 1.f;
    const float q = c / threshold;
    return u < q ? 1.f / q : 0.f;
}

/// Veach's power heuristic (β = 2) for the technique of density a against b.
float powerHeuristic(float a, float b) {
    const float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.f ? a2 / (a2 + b2) : 0.f;
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

/// The preview's picture: lights as the preview approximates them
/// (Light::toLight), castsShadows honoured, the environment as its mean.
SampleResult shadeKajiyaKay(const ShadingContext& ctx, const Vec3f& o, const Vec3f& d, const SceneHit& hit) {
    SampleResult r;
    const View& view = ctx.view;
    const float T = view.hair.transmittance;
    const Vec3f p = o + hit.t * d;
    const Vec3f v = -d;
    const Vec3f ambient = view.meanEnvironment();
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
        r.diffuse += ambient.cwiseProduct(view.hair.color) * view.hair.kd;
    } else {
        Vec3f n = ctx.scene.headShadingNormal(hit.triangle, hit.b1, hit.b2);
        Vec3f ng = hit.ng;
        if (ng.dot(v) < 0.f) ng = -ng;
        if (n.dot(ng) < 0.f) n = -n;
        const Vec3f q = p + surfaceOffset(p) * ng;
        r.diffuse = view.head.color.cwiseProduct(Vec3f::Constant(view.head.ambient) + ambient);
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

/// One path of the physical mode. At each vertex: next-event estimation of
/// every light and of the environment (light sampling), then one BSDF
/// sample that continues the path and, where it meets a light with size or
/// escapes to the environment, adds their radiance. Both estimates of the
/// same light are weighted by the power heuristic (Veach and Guibas 1995),
/// so together they count it once; delta lights are light-sampled only.
SampleResult tracePhysical(const ShadingContext& ctx, Vec3f o, Vec3f d, SceneHit hit, sampling::PixelSampler& sampler,
                           Vec3f beta = Vec3f::Ones(), int firstBounce = 0, float indirectRate = 1.f) {
    SampleResult r;
    const ReferenceSettings& s = ctx.settings;
    const EnvironmentLight& env = ctx.environment;
    const bool firstHitOnly = s.unshadowedLights == UnshadowedLights::FirstHit;
    const bool lightSampling = s.lightStrategy != LightStrategy::BsdfOnly;
    const bool bsdfSampling = s.lightStrategy != LightStrategy::LightOnly;
    // A constant sky is gathered by BSDF sampling alone: light-sampling it
    // (nearly uniform directions) cost a shadow ray per vertex for 3% less
    // noise on the default shot, a loss at equal time. A map is sampled
    // both ways.
    const bool skyLightSampling = lightSampling && env.hasMap();
    const bool skyBsdfSampling = bsdfSampling || !env.hasMap();
    // Lights that only the first hit sees (first-hit option) are light-sampled only.
    auto firstHitLight = [&](const SampledLight& l) { return firstHitOnly && !l.light().castsShadows; };
    // Is there anything a BSDF ray past the last bounce could still find?
    bool hittable = false;
    for (const SampledLight& l : ctx.lights) hittable = hittable || (!l.delta() && !firstHitLight(l));
    hittable = (hittable && bsdfSampling) || (env.active() && skyBsdfSampling);
    // The camera hit's own light sampling, to tell the indirect part apart.
    Vec3f direct = Vec3f::Zero();
    uint32_t directRays = 0;
    bool directKnown = false;
    for (int bounce = firstBounce;; ++bounce) {
        const bool last = bounce >= s.bounces;
        const Vec3f p = o + hit.t * d;
        const Vec3f wo = -d;
        Vec3f origin = p;
        RayStart start;
        const bool onHead = hit.kind == SceneHit::Kind::Head;
        Vec3f headNg = Vec3f::Zero();
        std::optional<HairBsdf> hairBsdf;
        VertexBsdf bsdf(ctx.view.head, Vec3f::UnitZ(), wo);
        if (hit.kind == SceneHit::Kind::Hair) {
            const CurvePoint cp = ctx.scene.curvePoint(hit.segment, hit.u);
            const FiberFrame frame = fiberFrame(cp.tangent, wo);
            hairBsdf.emplace(ctx.hair, fiberOffset(frame, hit.ng));
            bsdf = VertexBsdf(*hairBsdf, frame, wo);
            start = RayStart{hit.strand, hit.segment};
        } else {
            Vec3f n = ctx.scene.headShadingNormal(hit.triangle, hit.b1, hit.b2);
            Vec3f ng = hit.ng;
            if (ng.dot(wo) < 0.f) ng = -ng;
            if (n.dot(ng) < 0.f) n = -n;
            origin = p + surfaceOffset(p) * ng;
            headNg = ng;
            bsdf = VertexBsdf(ctx.view.head, n, wo);
            start = kFromHead;
        }

        // Light sampling: one sample per light, then the environment.
        for (const SampledLight& light : ctx.lights) {
            const float u = sampler.nextSide();
            const Vec2f ul = sampler.next2D();
            const bool firstHit = firstHitLight(light);
            if (firstHit && bounce > 0) continue;  // never after a bounce
            if (!light.delta() && !lightSampling && !firstHit) continue;
            const LightSample ls = light.sample(origin, ul);
            if (!ls.valid) continue;
            float pdfB = 0.f;
            Vec3f spec;
            const Vec3f f = bsdf.eval(ls.wi, &pdfB, &spec);
            if (!(f.maxCoeff() > 0.f)) continue;
            // Delta lights give irradiance; lights with size radiance / pdf.
            Vec3f li = ls.radiance;
            if (!light.delta()) li *= (firstHit || !bsdfSampling ? 1.f : powerHeuristic(ls.pdf, pdfB)) / ls.pdf;
            Vec3f c = beta.cwiseProduct(f).cwiseProduct(li);
            if (!firstHit && s.shadows) {  // roulette only where a shadow ray would be traced
                const float w = shadowRoulette(c.maxCoeff() / light.scale(origin), s.shadowRouletteThreshold, u);
                if (w <= 0.f) continue;
                li *= w * visibility(ctx, origin, ls.wi, ls.distance, 0.f, start, &r.rays);
                c = beta.cwiseProduct(f).cwiseProduct(li);
            }
            r.radiance += c;
            if (bounce == 0) r.specular += spec.cwiseProduct(li);
        }
        if (env.active()) {
            const Vec2f ue = sampler.next2D();
            const LightSample ls = skyLightSampling ? env.sample(ue) : LightSample{};
            float pdfB = 0.f;
            Vec3f spec;
            const Vec3f f = ls.valid ? bsdf.eval(ls.wi, &pdfB, &spec) : Vec3f::Zero();
            if (f.maxCoeff() > 0.f) {
                Vec3f li = ls.radiance * ((skyBsdfSampling ? powerHeuristic(ls.pdf, pdfB) : 1.f) / ls.pdf);
                li *= visibility(ctx, origin, ls.wi, kInf, 0.f, start, &r.rays);
                r.radiance += beta.cwiseProduct(f).cwiseProduct(li);
                if (bounce == 0) r.specular += spec.cwiseProduct(li);
            }
        }
        if (bounce == firstBounce) direct = r.radiance, directRays = r.rays, directKnown = true;
        if (last && !hittable) break;

        // BSDF sampling: the path's next direction, with `throughput`
        // (updated), its contributions counted `weight` times; false where
        // the path ends. Sets d, next and intoHead.
        SceneHit next;
        bool intoHead = false;
        auto step = [&](Vec3f& throughput, float weight) -> bool {
            const Vec2f u0 = sampler.next2D(), u1 = sampler.next2D();
            const VertexSample bs = bsdf.sample(u0, u1);
            if (!bs.valid) return false;
            throughput = throughput.cwiseProduct(bs.weight);
            // Russian roulette from the second bounce on (as pbrt-v4: the first
            // bounces carry most of the picture and cost little): continue with
            // probability max(β) (≤ 1) and reweight, which is unbiased and stops
            // the many paths that dark hair has already absorbed.
            if (!last && bounce >= 1) {
                const float survive = std::min(1.f, throughput.maxCoeff());
                const float ur = sampler.next1D();
                if (survive < 1.f) {
                    if (!(ur < survive)) return false;
                    throughput /= survive;
                }
            }
            d = bs.wi;
            // The path goes on with the head opaque: a bounce off the skin must
            // not see hair through the neck. A direction into the head's surface
            // (the wrap lobe past the terminator) ends it.
            intoHead = onHead && !(d.dot(headNg) > 0.f);
            next = SceneHit{};
            if (!intoHead) {
                ++r.rays;
                r.strandRays += !onHead;
                next = ctx.scene.intersect(origin, d, 0.f, kInf, onHead ? RayStart{} : start);
            }
            if (bsdfSampling || skyBsdfSampling) {
                // The lights and sky this ray reaches, seen as the light samples'
                // shadow rays see them (hair blocks; from the head, the head does
                // not), so that both estimates of each light agree for MIS.
                float tLight = next.kind == SceneHit::Kind::None ? kInf : next.t;
                if (onHead && (intoHead || next.kind == SceneHit::Kind::Head)) {
                    ++r.rays;
                    const SceneHit hair = ctx.scene.intersect(origin, d, 0.f, kInf, kFromHead);
                    tLight = hair.kind == SceneHit::Kind::None ? kInf : hair.t;
                }
                if (!s.shadows) tLight = kInf;
                Vec3f found = Vec3f::Zero();
                for (const SampledLight& light : ctx.lights) {
                    if (firstHitLight(light) || !bsdfSampling) continue;
                    Vec3f le;
                    float pdfL;
                    if (light.hit(origin, d, tLight, &le, &pdfL))
                        found += le * (lightSampling ? powerHeuristic(bs.pdf, pdfL) : 1.f);
                }
                if (env.active() && skyBsdfSampling && std::isinf(tLight))
                    found += env.radiance(d) * (skyLightSampling ? powerHeuristic(bs.pdf, env.pdf(d)) : 1.f);
                if (found.maxCoeff() > 0.f) {
                    r.radiance += weight * throughput.cwiseProduct(found);
                    if (bounce == 0 && s.diffuseSpecularLayers) {
                        // The R lobe's share of what this direction brought.
                        float pdfB;
                        Vec3f spec;
                        const Vec3f f = bsdf.eval(d, &pdfB, &spec);
                        for (int c = 0; c < 3; ++c)
                            if (f[c] > 0.f) r.specular[c] += weight * throughput[c] * found[c] * spec[c] / f[c];
                    }
                }
            }
            return true;
        };
        // Splitting (ReferenceSettings::bounceSplits): several independent
        // continuations of the camera hit, each counted 1/N: an estimate of
        // the indirect light with 1/N of one's variance, without paying again
        // for the camera ray, the first hit's shading and its direct light.
        // Efficiency-aware rate (path_splitting.h): N paths with E[N] = rate,
        // each counted 1/rate; N = 0 is Russian roulette of the indirect part.
        const bool rated = bounce == 0 && indirectRate != 1.f;
        const int splits = rated ? splitCount(indirectRate, sampler.next1D())
                                 : bounce == 0 ? std::max(1, s.bounceSplits) : 1;
        if (splits > 1 || rated) {
            const float w = 1.f / (rated ? indirectRate : float(splits));
            for (int k = 0; k < splits; ++k) {
                const Vec3f before = r.radiance;
                Vec3f b = beta;
                if (step(b, w) && !intoHead && next.kind != SceneHit::Kind::None && !last) {
                    const SampleResult sub = tracePhysical(ctx, origin, d, next, sampler, b, bounce + 1);
                    r.radiance += w * sub.radiance;
                    r.rays += sub.rays;
                    r.strandRays += sub.strandRays;
                }
                // The first two paths' own estimates (unweighted), for training.
                if (bounce == 0 && k < 2) r.paths[k] = (r.radiance - before).sum() / w, r.pathCount = k + 1;
            }
            break;
        }
        if (!step(beta, 1.f)) break;
        o = origin;
        hit = next;
        if (intoHead || hit.kind == SceneHit::Kind::None || last) break;
    }
    r.diffuse = r.radiance - r.specular;
    if (directKnown) r.indirect = r.radiance - direct, r.indirectRays = r.rays - directRays;
    return r;
}

}  // namespace

SampleResult shadeSample(const ShadingContext& ctx, const Vec3f& origin, const Vec3f& dir, const SceneHit& hit,
                         sampling::PixelSampler& sampler, float indirectRate) {
    SampleResult r;
    if (hit.kind == SceneHit::Kind::None) {
        // The sky seen: the map itself in physical mode, its mean in the preview's.
        r.radiance = r.diffuse = ctx.settings.mode == ReferenceMode::Physical ? ctx.environment.radiance(dir)
                                                                                : ctx.view.meanEnvironment();
        r.rays = 1;
        return r;
    }
    r = ctx.settings.mode == ReferenceMode::KajiyaKay ? shadeKajiyaKay(ctx, origin, dir, hit)
                                                      : tracePhysical(ctx, origin, dir, hit, sampler, Vec3f::Ones(), 0, indirectRate);
    r.rays += 1;
    r.hit = true;
    const Camera& cam = ctx.view.camera;
    r.depth = (origin + hit.t * dir - cam.position).dot((cam.target - cam.position).normalized());
    // The id table is large and cold: read it only for the id layer.
    if (hit.kind == SceneHit::Kind::Hair && ctx.settings.strandIdLayer) r.strandId = ctx.scene.strandId(hit.strand);
    return r;
}

}  // namespace hp
