// @brief The scattering at one vertex of a physical-mode path: a hair fibre
// (Chiang et al. 2016, render/reference/hair_bsdf.h) in its local frame, or
// the head's skin (skinShade, render/view/view.h), behind one interface that
// evaluates f·cos with its sampling density and draws directions, which is
// what light sampling, BSDF sampling and their MIS combination need.
#pragma once

#include "render/reference/embree_scene.h"
#include "render/reference/hair_bsdf.h"
#include "render/view/view.h"

namespace hp {

/// Local frame of a fibre hit: x along the tangent, z the viewer's direction
/// projected into the normal plane, y = z × x (render/reference/hair_bsdf.h).
struct FiberFrame {
    Vec3f x, y, z;
    Vec3f toLocal(const Vec3f& w) const { return {w.dot(x), w.dot(y), w.dot(z)}; }
    Vec3f toWorld(const Vec3f& w) const { return w.x() * x + w.y() * y + w.z() * z; }
};
FiberFrame fiberFrame(const Vec3f& tangent, const Vec3f& wo);

/// h = sin γo: the hit's offset across the fibre, from the tube's surface
/// normal projected into the normal plane (y component; see hair_bsdf.h).
float fiberOffset(const FiberFrame& f, const Vec3f& ng);

/// Offset off the head's surface for rays leaving it: far above float error
/// at head scale, far below a hair radius.
inline float surfaceOffset(const Vec3f& p) { return 4e-6f * (1.f + p.cwiseAbs().maxCoeff()); }

/// Rays from the head see hair only (RayStart::throughHead says why).
inline const RayStart kFromHead{kNoStrand, 0, true};

/// One sampled direction.
struct VertexSample {
    Vec3f wi = Vec3f::Zero();
    Vec3f weight = Vec3f::Zero();  ///< f·cos / pdf
    float pdf = 0.f;               ///< solid angle
    bool valid = false;
};

class VertexBsdf {
  public:
    /// A hair hit: `bsdf` must outlive this.
    VertexBsdf(const HairBsdf& bsdf, const FiberFrame& frame, const Vec3f& wo);
    /// A head hit with shading normal n (facing wo) and its material.
    VertexBsdf(const SurfaceMaterial& skin, const Vec3f& n, const Vec3f& wo);

    /// f(wo, wi)·cos θi (for hair the kernel S, which holds its cosine), with
    /// the density sample() has for wi in *pdf and, for hair, the R lobe's
    /// part in *specular.
    Vec3f eval(const Vec3f& wi, float* pdf, Vec3f* specular = nullptr) const;
    /// Hair: Chiang's lobe sampling. Skin: the wrapped cosine, density
    /// max(0, n·l + w) / (π (1 + w)²), which is the diffuse part exactly, so
    /// weights are (1 − ks)·albedo plus a bounded sheen term, at most
    /// ks·π·N(s)·(1 + w)² (0.26 at the default ks 0.04, s 30, w 0.2), so
    /// the skin itself makes no fireflies.
    VertexSample sample(const Vec2f& u0, const Vec2f& u1) const;

  private:
    const HairBsdf* hair_ = nullptr;
    FiberFrame frame_{};
    const SurfaceMaterial* skin_ = nullptr;
    Vec3f n_ = Vec3f::UnitZ();
    Vec3f wo_ = Vec3f::UnitZ();
    Vec3f woLocal_ = Vec3f::UnitZ();
};

}  // namespace hp
