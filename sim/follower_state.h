// Internal to sim/followers*.cpp: the state a Followers object builds once
// and reads every step. Not for other modules (include sim/followers.h).
#pragma once

#include "sim/follower_kernels.h"
#include "sim/followers.h"

#include <Eigen/Geometry>

#include <vector>

namespace hp {

/// Longest strand the follower tables accept (stack scratch is sized by it).
constexpr uint32_t kMaxFollowerVertices = 256;

/// Followers sharing one segment count S; their guide tables are resampled
/// to S segments, padded to P (a multiple of 8) so every loop over segments
/// runs over whole vectors.
struct FollowerClass {
    uint32_t segments = 0;
    uint32_t pad = 0;
    /// Per guide, kHot rows of P floats: qw qx qy qz (rotation of the guide
    /// segment mapped to follower segment y), speed (m/s, the segment's
    /// centre), rx ry rz (the guide's unit rest direction, static).
    std::vector<float> hot;
    /// Per guide, S + 1 mapped vertices × kCold floats: x y z (world),
    /// clearance (signed distance to the head), vx vy vz, unused.
    std::vector<float> cold;
    std::vector<float> radii;  ///< S + 1 tapered radii
    std::vector<float> df;     ///< Algorithm 1's d_f(y), P values (exact at root and tip)
    static constexpr int kHot = 8;
    static constexpr int kCold = 8;

    /// Guide segment read by follower segment y: the one covering the same
    /// fraction of the strand, floor((y + 1/2) Sg / S); y itself when Sg = S.
    static uint32_t guideSegment(uint32_t y, uint32_t followerSegments, uint32_t guideSegments) {
        const uint32_t s = ((2 * y + 1) * guideSegments) / (2 * followerSegments);
        return s < guideSegments ? s : guideSegments - 1;
    }
};

struct Followers::Impl {
    FollowerSettings settings;
    size_t guides = 0, followers = 0;

    // Guides (rest): segment offsets and inverse transported rest frames P_y⁻¹.
    std::vector<uint32_t> guideSegmentOffsets{0};
    std::vector<follower::Quat> restInverse;
    std::vector<Eigen::Vector3f> guideRestDirs;  ///< unit, root-frame coordinates

    std::vector<FollowerClass> classes;

    // Followers, structure of arrays.
    std::vector<FollowerNeighbours> neighbours;
    std::vector<uint8_t> classOf;
    std::vector<float> weight;             ///< interpolation weight d1 / (d1 + d2)
    std::vector<float> alignC, alignS;     ///< follower frame turned about its normal by φ_f
    std::vector<float> twistC, twistS;     ///< guide 2's rotations turned into guide 1's frame
    std::vector<float> segmentLength;      ///< followers without own rest shapes
    std::vector<uint32_t> ownRest;         ///< offset into ownRestData, or kNone
    std::vector<float> ownRestData;        ///< per follower: dx[P] dy[P] dz[P] length[P], aligned frame
    std::vector<uint32_t> vertexOffset;    ///< follower vertex offsets, relative to the follower block
    std::vector<uint32_t> ids;
    std::vector<uint32_t> order;           ///< processing order: by class, then index (streams memory)
    static constexpr uint32_t kNone = ~0u;

    // What the previous update wrote (finite-difference velocities).
    const Vec3f* lastPositions = nullptr;
    size_t lastVertexCount = 0;
};

}  // namespace hp
