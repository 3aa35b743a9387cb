#include "render/reference/vertex_bsdf.h"

#include "render/reference/sampling.h"

#include <algorithm>
#include <cmath>

namespace hp {

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

float fiberOffset(const FiberFrame& f, const Vec3f& ng) {
    Vec3f n = ng - ng.dot(f.x) * f.x;
    const float len = n.norm();
    if (len < 1e-6f) return 0.f;
    return std::clamp(n.dot(f.y) / len, -1.f, 1.f);
}

VertexBsdf::VertexBsdf(const HairBsdf& bsdf, const FiberFrame& frame, const Vec3f& wo)
    : hair_(&bsdf), frame_(frame), wo_(wo), woLocal_(frame.toLocal(wo)) {}

VertexBsdf::VertexBsdf(const SurfaceMaterial& skin, const Vec3f& n, const Vec3f& wo) : skin_(&skin), n_(n), wo_(wo) {}

Vec3f VertexBsdf::eval(const Vec3f& wi, float* pdf, Vec3f* specular) const {
    if (hair_) {
        Vec3f lobes[HairModel::kLobes];
        const Vec3f f = hair_->eval(woLocal_, frame_.toLocal(wi), lobes, pdf);
        if (specular) *specular = lobes[0];
        return f;
    }
    const float w = std::max(skin_->wrap, 0.f);
    *pdf = std::max(0.f, n_.dot(wi) + w) * float(1.0 / M_PI) / ((1.f + w) * (1.f + w));
    if (specular) *specular = Vec3f::Zero();
    return skinShade(*skin_, n_, wi, wo_);
}

VertexSample VertexBsdf::sample(const Vec2f& u0, const Vec2f& u1) const {
    VertexSample s;
    if (hair_) {
        const HairSample h = hair_->sample(woLocal_, u0, u1);
        if (!h.valid) return s;
        s.wi = frame_.toWorld(h.wi).normalized();
        s.weight = h.weight;
        s.pdf = h.pdf;
        s.valid = true;
        return s;
    }
    // Wrapped cosine around n: c = n·l on (−w, 1] with density ∝ (c + w)
    // (dω = dc dφ), so (c + w)² / (1 + w)² = u, φ uniform.
    const float w = std::max(skin_->wrap, 0.f);
    const float c = std::min(1.f, (1.f + w) * std::sqrt(u0.x()) - w);
    const float sinT = std::sqrt(std::max(0.f, 1.f - c * c));
    const float phi = 2.f * float(M_PI) * u0.y();
    Vec3f b1, b2;
    sampling::orthonormalBasis(n_, &b1, &b2);
    s.wi = (sinT * std::cos(phi) * b1 + sinT * std::sin(phi) * b2 + c * n_).normalized();
    const Vec3f f = eval(s.wi, &s.pdf);
    if (!(s.pdf > 0.f)) return s;
    s.weight = f / s.pdf;
    s.valid = true;
    return s;
}

}  // namespace hp
