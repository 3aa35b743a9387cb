// Exact geometric queries on a triangle mesh: closest point (with the
// triangle feature it lies on) and ray casts, through an Embree 3 BVH.
//
// Root placement projects lattice points onto the scalp with it, the exact
// collider measures penetration with it, and tests use it as ground truth for
// the signed distance grid. Embree stays inside mesh_query.cpp.
#pragma once

#include "sim/strands/head.h"

#include <limits>
#include <memory>
#include <vector>

namespace hp {

/// The part of a triangle (corners a, b, c) a closest point lies on; the
/// inside/outside sign of the exact collider depends on it.
enum class TriangleFeature : uint8_t { Face, EdgeAB, EdgeBC, EdgeCA, VertexA, VertexB, VertexC };

struct TrianglePoint {
    float b1 = 0.f, b2 = 0.f;  ///< barycentric weights of b and c (a: 1 - b1 - b2)
    TriangleFeature feature = TriangleFeature::Face;
};

/// @brief Closest point of segment (p0, p1) to p as a parameter in [0, 1]:
///   t = clamp((p - p0)·d / |d|², 0, 1),  d = p1 - p0  (0 for a point segment).
float segmentParameter(const Vec3f& p, const Vec3f& p0, const Vec3f& p1);

/// @brief Closest point of triangle (a, b, c) to p (Ericson, Real-Time
/// Collision Detection 5.1.5): Voronoi regions of the corners and edges
/// first, the face interior last. Degenerate triangles give an edge or corner.
TrianglePoint closestPointOnTriangle(const Vec3f& p, const Vec3f& a, const Vec3f& b, const Vec3f& c);

/// The closest surface point to a query.
struct MeshPoint {
    SurfacePoint point;             ///< triangle and barycentrics (the original mesh's triangle index)
    Vec3f position = Vec3f::Zero();
    float distance = std::numeric_limits<float>::infinity();  ///< unsigned, metres
    TriangleFeature feature = TriangleFeature::Face;
    bool found() const { return distance < std::numeric_limits<float>::infinity(); }
};

struct RayHit {
    SurfacePoint point;
    float t = std::numeric_limits<float>::infinity();  ///< distance along the (unit) direction
    bool hit() const { return t < std::numeric_limits<float>::infinity(); }
};

/// @brief A BVH over (a subset of) a mesh's triangles for closest-point and
/// ray queries. Queries are thread-safe; refit() is not (call it between
/// query phases).
///
/// Ties between triangles at the same distance (a point on a shared edge)
/// are broken by the lower triangle index, so results do not depend on the
/// BVH's traversal order or on the number of threads.
class MeshQuery {
  public:
    /// Builds the BVH over the triangles of `mesh` whose `mask` entry is
    /// non-zero (all triangles when `mask` is empty). Copies what it needs.
    explicit MeshQuery(const TriangleMesh& mesh, const std::vector<uint8_t>& mask = {});
    ~MeshQuery();
    MeshQuery(const MeshQuery&) = delete;
    MeshQuery& operator=(const MeshQuery&) = delete;

    /// The closest point within `maxDistance` (not found() when none).
    MeshPoint closest(const Vec3f& p, float maxDistance = std::numeric_limits<float>::infinity()) const;

    /// First hit of the ray origin + t·direction, t in [tMin, tMax]; `direction` unit length.
    RayHit intersect(const Vec3f& origin, const Vec3f& direction, float tMin = 0.f,
                     float tMax = std::numeric_limits<float>::infinity()) const;

    /// Moves the vertices (same topology, e.g. the next frame's deformed
    /// mesh) and refits the BVH instead of rebuilding it.
    void refit(const std::vector<Vec3f>& positions);

    size_t triangleCount() const;   ///< triangles in the BVH
    Vec3f vertex(uint32_t i) const;  ///< current position of mesh vertex i
    const Tri& triangle(uint32_t meshTriangle) const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace hp
