// The head as the simulation sees it: a plain deformed triangle mesh per
// time, hair roots bound to it by barycentric coordinates, and a collider.
//
// pipeline/ fills these from assimp (see pipeline/head/head_import.h); tests and
// benchmarks make them procedurally (makeSphereMesh). Nothing here knows
// about file formats.
#pragma once

#include "sim/strands/strand.h"

#include <Eigen/Geometry>

#include <array>
#include <memory>
#include <vector>

namespace hp {

using Tri = std::array<uint32_t, 3>;

/// An indexed triangle mesh in world space (metres, Y up).
struct TriangleMesh {
    std::vector<Vec3f> positions;
    std::vector<Vec3f> normals;  ///< per vertex, unit length (may be empty until computeNormals)
    std::vector<Vec2f> uvs;      ///< optional, per vertex
    std::vector<Tri> triangles;

    /// Area-weighted vertex normals.
    void computeNormals();
    Eigen::AlignedBox3f bounds() const;
    size_t triangleCount() const { return triangles.size(); }
};

/// A point on the mesh: triangle plus barycentric weights (b1, b2); the first
/// corner's weight is 1 - b1 - b2. Survives any deformation of the mesh.
struct SurfacePoint {
    uint32_t triangle = 0;
    float b1 = 0.f, b2 = 0.f;
};

/// Position and orthonormal frame of a surface point. `tangent` follows the
/// triangle's first edge, so the frame rotates with the deforming surface.
struct SurfaceFrame {
    Vec3f position = Vec3f::Zero();
    Vec3f normal = Vec3f::UnitY();
    Vec3f tangent = Vec3f::UnitX();
    Vec3f bitangent() const { return normal.cross(tangent); }
};

/// Evaluates a bound point on `mesh` (smooth interpolated normal).
SurfaceFrame evaluate(const TriangleMesh& mesh, const SurfacePoint& point);

/// Signed distance to the head: negative inside. Implementations must be
/// thread-safe for concurrent queries.
class Collider {
  public:
    virtual ~Collider() = default;
    /// Signed distance at `p`; when `normal` is given, the outward unit normal
    /// of the nearest surface point (the distance gradient).
    virtual float signedDistance(const Vec3f& p, Vec3f* normal = nullptr) const = 0;
    /// The same for a strand that ignores the head's parts in the mask
    /// `ignoreParts` (bit k: part k; a head that folds into itself,
    /// sim/collision/mesh_parts.h). Colliders without parts ignore the mask.
    virtual float signedDistanceIgnoring(const Vec3f& p, Vec3f* normal, uint32_t ignoreParts) const {
        (void)ignoreParts;
        return signedDistance(p, normal);
    }
};

/// An exact sphere (the benchmark head).
class SphereCollider final : public Collider {
  public:
    SphereCollider(const Vec3f& centre, float radius) : centre_(centre), radius_(radius) {}
    float signedDistance(const Vec3f& p, Vec3f* normal = nullptr) const override;

  private:
    Vec3f centre_;
    float radius_;
};

/// The head at one instant.
struct HeadPose {
    double time = 0.0;
    /// Rigid part of the head's motion (head bone or node transform). Solvers
    /// use it for frame-of-reference effects and teleport detection.
    Eigen::Isometry3f transform = Eigen::Isometry3f::Identity();
    TriangleMesh mesh;                        ///< deformed, world space
    std::shared_ptr<const Collider> collider; ///< may be null (no head collision)
    /// Visible meshes beside the head (a body, props), world space with
    /// normals: drawn with `mesh`, never a root's surface. May be empty.
    TriangleMesh scenery;
};

/// A head that can be sampled at any time (seconds). The pipeline's assimp
/// animation and the benchmarks' spinning sphere both implement it.
class HeadMotion {
  public:
    virtual ~HeadMotion() = default;
    virtual HeadPose sample(double time) const = 0;
};

/// A UV sphere mesh (used by tests, benchmarks and the procedural demo head).
TriangleMesh makeSphereMesh(const Vec3f& centre, float radius, int rings, int sectors);

/// The benchmark head of docs/benchmarks.md: a sphere spinning about +Y at a
/// constant rate, with an exact sphere collider.
class SpinningSphere final : public HeadMotion {
  public:
    SpinningSphere(float radius, float degreesPerSecond, int rings = 32, int sectors = 64);
    HeadPose sample(double time) const override;

  private:
    float radius_;
    float rate_;
    TriangleMesh rest_;
};

}  // namespace hp
