// @brief The reference renderer's ray-tracing adapter: an Embree 3 scene of
// one frame's strands (round Catmull-Rom curves with per-vertex radius) and
// the head (triangles). embree_scene.cpp is the only render file that
// includes embree3/rtcore.h (with core/embree_ray.h, the ray set-up it shares
// with sim/collision/mesh_query.cpp), so moving to Embree 4 touches only those.
//
// Notes on why:
// - Catmull-Rom interpolates the strand vertices, so the reference tube goes
//   through exactly the points the preview draws. Each strand gets phantom end
//   points (2 p0 − p1 and 2 pn−1 − pn−2) so its first and last segments exist
//   and end at the root and the tip.
// - Queries that start on a strand ignore hits on that strand within one
//   segment of the start (the fibre's own surface): the hair BSDF already
//   accounts for the light's path through its own fibre.
// - Shadow rays through hair accumulate a per-crossing transmittance in an
//   occlusion filter and continue; Embree may report the same crossing more
//   than once (entry and exit of a tube, the overlapping ends of adjacent
//   segments), so crossings of the same strand within one segment count once.
#pragma once

#include "sim/strands/head.h"
#include "sim/strands/strand.h"

#include <cstdint>
#include <memory>

namespace hp {

/// An Embree device with a memory monitor: every byte Embree allocates for
/// the scenes built on it is counted.
class EmbreeDevice {
  public:
    EmbreeDevice();
    ~EmbreeDevice();
    EmbreeDevice(const EmbreeDevice&) = delete;
    EmbreeDevice& operator=(const EmbreeDevice&) = delete;

    /// Bytes Embree holds now (geometry buffers, BVHs, scratch).
    int64_t bytesInUse() const;
    /// Largest bytesInUse() since construction or resetPeak().
    int64_t peakBytes() const;
    void resetPeak();

    struct Impl;
    Impl& impl() const { return *impl_; }

  private:
    std::unique_ptr<Impl> impl_;
};

constexpr uint32_t kNoStrand = 0xffffffffu;

/// What a ray hit.
struct SceneHit {
    enum class Kind { None, Hair, Head };
    Kind kind = Kind::None;
    float t = 0.f;               ///< distance along the (unit) ray direction
    Vec3f ng = Vec3f::Zero();    ///< geometric normal, unit (for hair: the tube's surface normal)
    uint32_t strand = kNoStrand; ///< hair: index into the StrandFrame
    uint32_t segment = 0;        ///< hair: global segment index (Embree primitive)
    float u = 0.f;               ///< hair: parameter along the segment, 0..1
    uint32_t triangle = 0;       ///< head: triangle index
    float b1 = 0.f, b2 = 0.f;    ///< head: barycentrics of corners 1 and 2
};

/// Where a query starts, so that it can skip its own surface.
struct RayStart {
    uint32_t strand = kNoStrand;  ///< starting strand, kNoStrand for camera rays and the head
    uint32_t segment = 0;
    /// Rays leaving the head (shadow rays, and the physical mode's search
    /// for lights along a bounce, which must agree with them for multiple
    /// importance sampling) pass through it: the head casts no shadow
    /// on itself. A low-poly head's flat triangles would otherwise cut its
    /// smooth shading into a staircase along the terminator (the "shadow
    /// terminator" problem); its own shading (n·l) darkens the far side.
    /// The preview does the same (shaders/head.frag).
    bool throughHead = false;
};

/// Position, unit tangent (root to tip) and radius on a strand's axis.
struct CurvePoint {
    Vec3f position = Vec3f::Zero();
    Vec3f tangent = Vec3f::UnitX();
    float radius = 0.f;
};

/// One frame's geometry in Embree. Build once per frame; queries are
/// thread-safe. The StrandFrame and mesh need not outlive it (it copies what
/// it needs), but the device must.
class EmbreeScene {
  public:
    /// Either input may be null. Throws FrameError naming the strand/vertex
    /// or triangle on NaN/Inf positions or negative radii.
    EmbreeScene(const EmbreeDevice& device, const StrandFrame* strands, const TriangleMesh* head);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    /// Closest hit along origin + t·dir, t in (tnear, tfar). `dir` must be unit.
    SceneHit intersect(const Vec3f& origin, const Vec3f& dir, float tnear, float tfar,
                       const RayStart& start = {}) const;

    /// Fraction of light passing from origin toward origin + tfar·dir: 0 if
    /// the head (or, with hairTransmittance = 0, any strand) blocks it, else
    /// hairTransmittance^n for n distinct strand crossings.
    float transmittance(const Vec3f& origin, const Vec3f& dir, float tnear, float tfar, float hairTransmittance,
                        const RayStart& start = {}) const;

    /// The strand's axis at a hit (segment, u).
    CurvePoint curvePoint(uint32_t segment, float u) const;
    /// Smooth (interpolated vertex) normal of the head at a hit, unit.
    Vec3f headShadingNormal(uint32_t triangle, float b1, float b2) const;

    size_t strandCount() const;
    size_t segmentCount() const;
    /// Stable id (StrandFrame::ids) of a strand index, or the index when ids are absent.
    uint32_t strandId(uint32_t strand) const;

    struct Impl;  ///< Embree handles; opaque outside embree_scene.cpp

  private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace hp
