// @brief Follower strands (Gomes 2024): strands without physics that copy or
// interpolate the per-segment rotations of their two nearest guides, rebuilt
// every step from their own root frame on the deformed scalp.
//
// Use: build a Followers once per groom (neighbour selection, tables), then
// call update() after every guide step; it writes guides + followers into one
// StrandFrame that the render and export stages read.
//
//   Followers followers(groom, settings);            // once
//   StrandFrame frame;                               // reused every step
//   for each step:
//       FollowerStats s = followers.update({guides, guideRoots, followerRoots,
//                                           collider, dt}, frame);
//
// What a follower is (sim/followers/follower_kernels.h has the equations):
//   d_y   = E_f · slerp(q1_y, K q2_y K⁻¹, w_y) · f_y    (unit direction)
//   x_0   = follower root,   x_{y+1} = x_y + L_y d_y      (lengths exact)
// q_v,y: rotation of guide v's segment y in v's root frame, from rest to now,
// twist by parallel transport along the guide; f_y: the follower's rest
// direction; E_f: the follower's current root frame; w_y: 0 (cluster),
// d1/(d1+d2) (interpolate) or Algorithm 1's d_r (varied). E_f and K remove the
// rest twist between the root frames' tangents (mesh tangents follow triangle
// edges and jump between neighbouring triangles): E_f is the follower's frame
// turned about its normal to match its nearest guide's frame carried over by
// the minimal rotation between the normals, K the same for the second guide
// relative to the first. At rest every q = 1, so followers keep their rest
// shape exactly; a follower whose root frame is the guide's moved rigidly is
// the guide moved rigidly.
//
// Choices where Gomes 2024 is silent or Unity-specific:
// - d_v reads guide 1's speed at the same segment (mean of the segment's two
//   vertex velocities, world space, m/s): Gomes 2024 buffers each guide
//   segment's Rigidbody velocity. World space, as there: a turning head is
//   motion and switches the variation on; a still head lets followers align.
// - d_f uses qs = (S - 1) / 2 (sim/followers/follower_kernels.h: equal to Gomes 2024's
//   integer "half the segment count" for its 23 segments; 0 at root and tip).
// - d_r below 0 (rand < 0 near root and tip) extrapolates the slerp past
//   guide 1 instead of clamping to [0, 1] as Unity's Quaternion.Slerp would,
//   so the variation is symmetric about the fixed-offset curve.
// - rand_xy is a hash of (seed, follower index, segment): no stored table.
// - Velocities of followers: finite differences of what is drawn (see update()).
//
// Why rotations relative to the root frame and transported along the strand:
// Gomes 2024's Unity prototype slerps the segments' transform rotations; here a
// strand is positions only, so a rotation must be derived. Expressing it in
// the guide's root frame removes the head's motion (a follower on the other
// side of a turning head gets its own frame's motion, not a translated copy of
// the guide), and transporting the frame along the strand gives a twist that
// is continuous along the strand and alike for guides that bend alike; the
// minimal rotation of each segment alone would be singular for a segment bent
// half a turn from rest and could differ arbitrarily in twist between two
// guides, which slerp would then blend into a spurious rotation.
#pragma once

#include "sim/strands/head.h"
#include "sim/strands/strand.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace hp {

enum class FollowerMode {
    Cluster,      ///< copy the nearest guide's segment rotations
    Interpolate,  ///< slerp between the two nearest guides by relative root distance
    Varied,       ///< Gomes 2024's Algorithm 1 (recommended)
    /// Three guides, the corners of the guide-root triangle over the
    /// follower (sim/followers/follower_triangles.h), rotations blended by the
    /// barycentric weights b: q = normalize(b1 q1 + b2 ±K2 q2 K2⁻¹ + b3 ±K3 q3 K3⁻¹)
    /// (signs toward q1, K the rest twist into guide 1's frame). Followers
    /// fill the volume between guides instead of the ruled sheets between two.
    /// Without followerShapes a follower's rest shape is the same blend of
    /// its three guides' rest directions.
    Barycentric,
};

enum class NeighbourRule {
    Nearest,          ///< the two nearest guide roots (Gomes 2024's rule)
    ShapeSimilarity,  ///< among the nearest few, the guides whose rest shapes match best
};

struct FollowerSettings {
    FollowerMode mode = FollowerMode::Varied;
    NeighbourRule neighbours = NeighbourRule::Nearest;
    /// Shape similarity: how many nearest roots are candidates.
    int shapeCandidates = 8;
    float fixedOffset = 0.2f;  ///< Algorithm 1's weight of d_f
    float maxVelocity = 0.1f;  ///< Algorithm 1's clamp of d_v, m/s
    bool collide = true;       ///< project follower vertices out of the head
    uint32_t seed = 1;         ///< seeds rand_xy
    float rootRadius = 0.00004f;  ///< follower radius at the root, m
    float tipRadius = 0.00001f;   ///< follower radius at the tip, m
    /// Update the followers on TBB's threads (false: one thread, Gomes 2024's
    /// "without parallelisation"). Results are identical either way.
    bool parallel = true;
};

/// Strands at rest, each in its own root frame (x = tangent, y = normal,
/// z = tangent × normal; root at the origin), in StrandFrame-style offsets.
struct RestShapes {
    std::vector<uint32_t> offsets{0};
    std::vector<Vec3f> points;

    size_t count() const { return offsets.size() - 1; }
    void add(const Vec3f* p, size_t n);
    /// `count` straight strands along the normal, `vertices` evenly spaced over `length`.
    static RestShapes straight(size_t count, int vertices, float length);
};

/// What a groom gives the followers once.
struct FollowerGroom {
    std::vector<SurfaceFrame> guideRoots;  ///< rest root frames of the guides
    RestShapes guideShapes;                ///< one per guide (vertex counts must match the guide frames)
    std::vector<SurfaceFrame> followerRoots;  ///< rest root frames of the followers
    /// Optional: one rest shape per follower. When empty, a follower takes
    /// its nearest guide's rest directions with its own vertex count and length.
    RestShapes followerShapes;
    /// Without followerShapes: vertices and length per follower (one value = all).
    std::vector<uint32_t> followerVertices{24};
    std::vector<float> followerLengths{0.25f};
    /// Strand ids written to the frame (one value per follower); empty:
    /// guide count + follower index.
    std::vector<uint32_t> followerIds;
};

/// Each follower's rest shape as the followers take it when the groom has no
/// followerShapes: its nearest guide's rest directions, resampled to the
/// follower's vertex count (FollowerClass::guideSegment), turned by the rest
/// twist between the two root frames, times the follower's segment length.
/// Returns groom.followerShapes itself when it is not empty. Followers built
/// from the result keep the same rest shapes (to float rounding).
RestShapes followerBaseShapes(const FollowerGroom& groom);

/// Orthonormal root frame [t, n, t × n] of a rest SurfaceFrame (Gram-Schmidt,
/// so slightly inexact mesh frames are accepted). Throws hp::Error naming
/// `what` `index` for a non-finite or degenerate frame.
Eigen::Matrix3d restRootFrame(const SurfaceFrame& frame, const char* what, size_t index);

/// The two guides a follower reads, in the order used (guide1 leads).
struct FollowerNeighbours {
    uint32_t guide1 = 0, guide2 = 0;
    float distance1 = 0.f, distance2 = 0.f;  ///< rest root distances, m
    uint32_t guide3 = 0;                     ///< Barycentric mode: the third corner
    float weight[3] = {1.f, 0.f, 0.f};       ///< Barycentric mode: weights of guides 1, 2, 3
};

/// One step's inputs. `guides` may be the same object as update()'s `out`
/// (followers are then appended in place after the guides).
struct FollowerStep {
    const StrandFrame& guides;                     ///< strands [0, guideCount()) are the guides
    const std::vector<SurfaceFrame>& guideRoots;     ///< current root frames of the guides
    const std::vector<SurfaceFrame>& followerRoots;  ///< current root frames on the deformed scalp
    const Collider* collider = nullptr;            ///< null: no head collision
    /// Seconds since the previous update into the same `out`; 0 = no previous
    /// (first step, cut). See update() for velocities.
    double dt = 0.0;
    /// Per follower (followerCount() entries; null: none), the head's parts
    /// it ignores: those its root lies inside at this step's pose
    /// (sim/collision/mesh_parts.h partsAroundRoots, the guides' rule). Its
    /// vertices collide with the collider's signedDistanceIgnoring(p, n, mask).
    const uint32_t* ignoreParts = nullptr;
};

/// A follower vertex pinned in a pinch (sim/followers/follower_pinch.h)
/// and the place it was held toward: its position in the previous frame.
/// The only thing a frame of followers reads from the frame before, besides
/// the velocities by difference.
struct FollowerPin {
    uint32_t vertex = 0;  ///< index in the follower block (0 = first follower's root)
    Vec3f last = Vec3f::Zero();
};

struct FollowerStats {
    size_t projected = 0;         ///< follower vertices pushed out of the head
    /// Projected vertices that sliding along the surface left inside, placed
    /// outside by turning their segment about its parent (sim/followers/follower_pinch.h).
    size_t bent = 0;
    /// Projected vertices with no place outside at their segment length
    /// (a pinch): held at their length toward their place in the previous
    /// frame (sim/followers/follower_pinch.h). Lengths stay exact.
    size_t pinned = 0;
    /// Projected vertices left inside (signed distance < 0 after the slide,
    /// the bend and the pin): the segment keeps its length instead. Every
    /// other follower vertex is outside (queried, or cleared by the bound).
    size_t penetrationCount = 0;
    float maxPenetration = 0.f;   ///< deepest of those, m
    size_t collisionQueries = 0;  ///< collider queries the guide-distance bound could not skip
    bool differenceVelocities = false;  ///< velocities are (x - x_prev) / dt
    bool layoutWritten = false;   ///< offsets, ids and radii were (re)written this update
    /// The pinned vertices that were held toward their previous place
    /// (velocities by difference only), sorted by vertex: with the guides,
    /// the root frames and the collider of this frame, what update() needs to
    /// give this frame's positions again bit for bit (Followers::rebuild).
    std::vector<FollowerPin> pins;
};

class Followers {
  public:
    /// Checks the groom (throws hp::Error naming the strand and what is
    /// wrong), selects neighbours, and allocates everything update() needs.
    Followers(const FollowerGroom& groom, const FollowerSettings& settings);
    ~Followers();
    Followers(Followers&&) noexcept;
    Followers& operator=(Followers&&) noexcept;

    /// Writes guides + followers of this step into `out`: guides first
    /// (copied unless `step.guides` is `out`), then the followers, with
    /// tapered radii and ids. `out` keeps its capacity between steps, so after
    /// the first update nothing is allocated.
    ///
    /// Velocities: when `step.dt > 0` and `out` still holds this object's
    /// previous output (same layout, same buffer, followers untouched), a
    /// follower's velocity is the finite difference (x - x_prev) / dt of what
    /// is drawn; otherwise it is the slerp-weighted blend of its two guides'
    /// vertex velocities, (1 - w) v1 + w v2. Throws hp::Error when the step's
    /// sizes disagree with the groom or a guide vertex is not finite.
    ///
    /// Runs on TBB's threads (settings.parallel); results are the same bits
    /// for any thread count on one machine (an AVX2 + FMA machine and an
    /// older x86-64 one round differently, see sim/followers/follower_step.cpp). One
    /// update at a time per Followers object. To
    /// keep the per-step cost to the followers themselves, a guide solver
    /// writing into `out` in place should overwrite the guide block rather
    /// than clear() the frame (which forces the layout to be rewritten and
    /// loses the previous positions the velocities need).
    FollowerStats update(const FollowerStep& step, StrandFrame& out);

    /// Declares that `out` holds this object's previous output (e.g. read
    /// back from the strand cache when a simulation resumes), so the next
    /// update() takes finite-difference velocities from it, exactly as if
    /// update() had written it. Throws hp::Error when its layout does not
    /// match the groom.
    void adoptPrevious(const StrandFrame& out);

    /// Makes `out` (this groom's layout, e.g. an earlier output) the previous
    /// output whose pinned vertices hold `pins` (an earlier update's
    /// FollowerStats::pins): the next update() with the same step as that
    /// one's gives its positions again, bit for bit, without the frame before
    /// it (its other previous positions only feed velocities). Throws
    /// hp::Error when a pin lies outside the follower block.
    void adoptPins(StrandFrame& out, const std::vector<FollowerPin>& pins);

    /// Segment length errors |length / rest - 1| of the followers in `out`
    /// (this object's last output, or any frame with its layout): max and
    /// mean over every follower segment. Rest lengths are the groom's (own
    /// rest shapes' segments, or length / segments). Throws hp::Error when
    /// `out` does not have this groom's layout.
    struct LengthError {
        double max = 0, mean = 0;
    };
    LengthError lengthError(const StrandFrame& out) const;

    size_t guideCount() const;
    size_t followerCount() const;
    const FollowerSettings& settings() const;
    const FollowerNeighbours& neighbours(size_t follower) const;

    struct Impl;  ///< opaque (sim/followers/follower_state.h, shared by the build and update sources)

  private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace hp
