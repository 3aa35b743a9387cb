// Internal to sim/followers*.cpp and sim/followers/follower_step.cpp: the state a
// Followers object builds once and the tables each step fills. Not for other
// modules (include sim/followers/followers.h).
#pragma once

#include "sim/followers/follower_kernels.h"
#include "sim/followers/followers.h"

#include <Eigen/Geometry>

#include <cstddef>
#include <vector>

namespace hp {

/// Longest strand the follower tables accept (stack scratch is sized by it).
constexpr uint32_t kMaxFollowerVertices = 256;

/// Two guides read together by some followers: guide 1 leads, guide 2's
/// rotations are turned about y into guide 1's frame by K = (twistC, twistS).
struct GuidePair {
    uint32_t guide1 = 0, guide2 = 0;
    float twistC = 1.f, twistS = 0.f;
};

/// Rows of a class's hot table, per guide (GuideRows): what the pair and
/// guide records are built from each step.
enum class HotRow : uint32_t {
    RotationW, RotationX, RotationY, RotationZ,  ///< q: the guide segment mapped to the slot's segment, rest to now
    Speed,                                       ///< m/s, the segment's centre
    RestX, RestY, RestZ,                         ///< unit rest direction, root frame (static)
    Count
};

/// Rows of a class's cold table, per guide (GuideRows); slot = vertex.
enum class ColdRow : uint32_t {
    X, Y, Z,                             ///< the guide vertex, world
    Bound,                               ///< its collisionBound (+inf at the root and in the padding)
    VelocityX, VelocityY, VelocityZ,     ///< its velocity
    Count
};

/// Row::Count rows of P floats per guide, a structure of arrays: a loop
/// over the slots of one row reads contiguous floats and vectorises.
template <typename Row>
class GuideRows {
  public:
    static constexpr size_t kRows = size_t(Row::Count);
    void assign(size_t guides, size_t pad) {
        pad_ = pad;
        data_.assign(guides * kRows * pad, 0.f);
    }
    float* row(size_t guide, Row r) { return data_.data() + (guide * kRows + size_t(r)) * pad_; }
    const float* row(size_t guide, Row r) const { return data_.data() + (guide * kRows + size_t(r)) * pad_; }

  private:
    std::vector<float> data_;
    size_t pad_ = 0;
};

/// Per guide and slot, what the followers led by that guide read for the
/// slot's segment, rebuilt every step. One record is 32 bytes; the step
/// transposes the records of 8 lanes into vectors 4 floats at a time, so
/// the two groups (lead, then vertex and bound) must stay in this order.
struct GuideRecord {
    /// A = q r q* of follower_kernels.h's (2) and 0 (followers with the
    /// guides' rest shape), or the guide's rotation q, w x y z (own rest shapes).
    float lead[4];
    float vertex[3];  ///< the guide vertex, world (the follower vertex's collision bound centre)
    float bound;      ///< its collisionBound
    const float* vertexAndBound() const { return vertex; }  ///< the second group: x y z bound
};

/// Per guide pair and slot, rebuilt every step (32 bytes, read like
/// GuideRecord in two groups of 4: θ and terms 0-2, then terms 3-5 and d_v).
struct PairRecord {
    float theta;  ///< the slerp arc θ between q1 and K q2 K⁻¹
    /// B - A then D of (2) (followers with the guides' rest shape), or the
    /// quaternion e of (1), w x y z, then 0, 0 (own rest shapes).
    float terms[6];
    float speedOffset;  ///< Algorithm 1's d_v: guide 1's clamped speed
    const float* arcAndTerms() const { return &theta; }            ///< θ, terms 0-2
    const float* lastTermsAndSpeed() const { return &terms[3]; }   ///< terms 3-5, d_v
};

static_assert(sizeof(GuideRecord) == 8 * sizeof(float) && offsetof(GuideRecord, bound) == 7 * sizeof(float),
              "the step reads a guide record as two groups of 4 floats");
static_assert(sizeof(PairRecord) == 8 * sizeof(float) && offsetof(PairRecord, speedOffset) == 7 * sizeof(float),
              "the step reads a pair record as two groups of 4 floats");

/// A packet's own rest segment at one slot (direction × length, in the
/// aligned frame), each coordinate over the packet's 8 lanes: one vector load each.
struct OwnRestSlot {
    float x[8], y[8], z[8];
};

/// Followers sharing one segment count S. Every table is in slots: P
/// slots (P a multiple of 8, P >= S + 1) where slot j is vertex j and
/// segment j - 1, the segment ending at vertex j; slot 0 (the root) and the
/// padding hold identity rotations and zero directions.
struct FollowerClass {
    uint32_t segments = 0;
    uint32_t pad = 0;
    GuideRows<HotRow> hot;
    GuideRows<ColdRow> cold;
    std::vector<GuideRecord> guideRecords;  ///< per guide, P slots
    /// Guide pairs of this class's followers and their records, per pair P slots.
    std::vector<GuidePair> pairs;
    std::vector<PairRecord> pairRecords;
    std::vector<float> radii;          ///< S + 1 tapered radii
    std::vector<float> weightedCurve;  ///< fixedOffset · d_f(j - 1) per slot, 0 at slot 0 and in the padding

    const GuideRecord* guideRecord(size_t guide) const { return guideRecords.data() + guide * pad; }
    const PairRecord* pairRecord(size_t pair) const { return pairRecords.data() + pair * pad; }

    /// Guide segment read by follower segment y: the one covering the same
    /// fraction of the strand, floor((y + 1/2) Sg / S); y itself when Sg = S.
    static uint32_t guideSegment(uint32_t y, uint32_t followerSegments, uint32_t guideSegments) {
        const uint32_t s = ((2 * y + 1) * guideSegments) / (2 * followerSegments);
        return s < guideSegments ? s : guideSegments - 1;
    }
};

/// Eight consecutive followers of one class, computed together in the 8
/// lanes of a vector (lanes = followers). Consecutive, so the output and the
/// per-step roots stream through memory in order; each lane reads its own
/// guide and pair records (8 loads and a transpose per slot). The last
/// packet of a class repeats its last follower in the unused lanes
/// (computed, never written).
struct alignas(32) FollowerPacket {
    static constexpr int kLanes = 8;
    float alignC[kLanes], alignS[kLanes];  ///< follower frame turned about its normal by φ_f
    float scale[kLanes];    ///< segment length (1 with own rest shapes: their segments carry it)
    float weight[kLanes];   ///< interpolation weight d1 / (d1 + d2)
    uint32_t hash[kLanes];  ///< followerHash(seed, follower)
    uint32_t follower[kLanes], guide1[kLanes], pair[kLanes];
    uint32_t vertexOffset[kLanes];  ///< first output vertex, relative to the follower block
    uint32_t count = 0, cls = 0;
    uint32_t own = 0;  ///< the packet's first OwnRestSlot (P of them) in Followers::Impl::ownRest
};

static_assert(sizeof(OwnRestSlot) == 3 * FollowerPacket::kLanes * sizeof(float), "one float per lane and coordinate");

/// Barycentric mode: the second and third guide of each lane of a packet,
/// the weights, and the rest twists K2, K3 (about y) into guide 1's frame.
struct alignas(32) TrianglePacket {
    static constexpr int kLanes = FollowerPacket::kLanes;
    uint32_t guide2[kLanes], guide3[kLanes];
    float b1[kLanes], b2[kLanes], b3[kLanes];
    float k2c[kLanes], k2s[kLanes], k3c[kLanes], k3s[kLanes];
};

struct Followers::Impl {
    FollowerSettings settings;
    size_t guides = 0, followers = 0;

    // Guides (rest): segment offsets and inverse transported rest frames P_y⁻¹.
    std::vector<uint32_t> guideSegmentOffsets{0};
    std::vector<follower::Quat> restInverse;
    std::vector<Eigen::Vector3f> guideRestDirs;  ///< unit, root-frame coordinates

    std::vector<FollowerClass> classes;
    std::vector<FollowerPacket> packets;  ///< all classes, class by class
    std::vector<TrianglePacket> triangles;  ///< Barycentric mode: one per packet

    // Followers, structure of arrays.
    std::vector<FollowerNeighbours> neighbours;
    std::vector<uint8_t> classOf;
    std::vector<uint32_t> pairOf;          ///< index into the class's pairs
    std::vector<float> weight;             ///< interpolation weight d1 / (d1 + d2)
    std::vector<float> alignC, alignS;     ///< follower frame turned about its normal by φ_f
    std::vector<float> segmentLength;      ///< followers without own rest shapes
    /// Own rest segments, per packet P slots; zero at slot 0 and in the
    /// padding. Empty: the followers take their guides' rest shapes.
    std::vector<OwnRestSlot> ownRest;
    std::vector<uint32_t> vertexOffset;    ///< follower vertex offsets, relative to the follower block
    std::vector<uint32_t> ids;

    // What the previous update wrote (finite-difference velocities).
    const Vec3f* lastPositions = nullptr;
    size_t lastVertexCount = 0;
};

namespace follower {

/// Collision bound of a guide vertex for follower vertices near it: the
/// signed distance is 1-Lipschitz, so a follower vertex p with
/// |p - g|² < bound is outside the head by more than the root radius (the
/// largest follower radius) and needs no query. bound = (clearance(g) -
/// rootRadius)² when that is positive, -1 (never) otherwise.
inline float collisionBound(float clearance, float rootRadius) {
    const float clear = clearance - rootRadius;
    return clear > 0.f ? clear * clear : -1.f;
}

/// What one step of the followers reads and writes (follower_step.cpp).
struct StepContext {
    const Followers::Impl* im;
    const SurfaceFrame* roots;
    const Collider* collider;  ///< null: no collision
    Vec3f* positions;          ///< the follower block of the output
    Vec3f* velocities;
    bool difference;           ///< finite-difference velocities
    float invDt;
    const uint32_t* ignoreParts;  ///< per follower: the head's parts it ignores (null: none)
};

struct Counters {
    size_t projected = 0, queries = 0;
    size_t bent = 0;        ///< vertices the slide left inside, bent out (follower_pinch.h)
    size_t pinned = 0;      ///< vertices with no place outside at their length, held (follower_pinch.h)
    size_t inside = 0;      ///< projected vertices left inside (signed distance < 0)
    float maxDepth = 0.f;   ///< deepest of those, m
    std::vector<FollowerPin> pins;  ///< pinned vertices that read their previous place
};

/// Rebuilds the pair records [begin, end) of class `c` from its guide rows.
void buildPairs(const Followers::Impl& im, FollowerClass& c, size_t begin, size_t end);

/// Packets [begin, end) of this step: shapes, collision, output.
void processPackets(const StepContext& ctx, size_t begin, size_t end, Counters& counters);

}  // namespace follower
}  // namespace hp
