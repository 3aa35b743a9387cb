// Plain strand data shared by every stage after the simulation.
//
// A StrandFrame is one frame of all strands (guides first, then followers) in
// structure-of-arrays form: the renderers, the voxelizer and the strand cache
// read it without knowing anything about Bullet or the solvers.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace hp {

using Vec2f = Eigen::Vector2f;
using Vec3f = Eigen::Vector3f;

/// All strands of one frame. Units: metres, metres per second, world space.
struct StrandFrame {
    int frame = 0;
    double time = 0.0;          ///< seconds since the shot's time origin
    uint32_t guideCount = 0;    ///< strands [0, guideCount) are guides, the rest followers

    /// Strand s owns vertices [offsets[s], offsets[s+1]); offsets.front() == 0.
    std::vector<uint32_t> offsets{0};
    std::vector<Vec3f> positions;   ///< per vertex, root first
    std::vector<Vec3f> velocities;  ///< per vertex; empty means "at rest"
    std::vector<float> radii;       ///< per vertex, metres
    std::vector<uint32_t> ids;      ///< per strand, stable across frames

    size_t strandCount() const { return offsets.size() - 1; }
    size_t vertexCount() const { return positions.size(); }
    uint32_t first(size_t strand) const { return offsets[strand]; }
    uint32_t vertexCount(size_t strand) const { return offsets[strand + 1] - offsets[strand]; }

    /// Drops all strands (keeps capacity, so a frame buffer can be reused).
    void clear();
    /// Reserves room for `strands` strands of `verticesPerStrand` vertices.
    void reserve(size_t strands, size_t verticesPerStrand);
    /// Appends one strand; velocities may be null (zero velocity).
    void addStrand(uint32_t id, const Vec3f* points, const float* radius, size_t count,
                   const Vec3f* velocity = nullptr);
    /// Throws hp::Error when the arrays disagree in size or hold NaN/Inf.
    void validate() const;
};

/// Radius tapering linearly from `root` at t = 0 to `tip` at t = 1.
inline float taperedRadius(float root, float tip, float t) { return root + (tip - root) * t; }

}  // namespace hp
