// @brief Groom modifiers: length variation, clumping, wave/curl and frizz,
// applied once to the followers' REST shapes (FollowerGroom::followerShapes).
//
// Why on the rest shape: a follower is rebuilt every step as its guides'
// segment rotations applied to its own rest segments (sim/followers/followers.h), so a
// modified rest shape is carried through the animation by the unchanged
// per-step kernel, and the kernel keeps each segment at its rest length.
// Without modifiers the followers of two guides are near-parallel copies that
// fuse into flat "feathers" at production density (issue 19, item 5).
//
// Every modifier is a pure function of (seed, follower index, rest roots,
// rest shapes): the same groom and seed give the same bits on any thread
// count. A follower's rest shape x_0..x_n (root-local, x_0 = 0, segment
// lengths L_k, arc fraction s_k = Σ_{i<k} L_i / Σ L) becomes, in order:
//   length:  L_k ← λ L_k,  x_k ← λ x_k,  λ = 1 - lengthVariation · u_f
//   clump:   t_k = x_k + c(s_k) (C_k - x_k),   c(s) = clump · s^clumpProfile
//            (C_k: the clump centre's vertex at the same arc fraction, carried
//            into this follower's root frame through world space)
//   wave:    t_k += wave · r(s_k) (cos φ_k b1 + curl · sin φ_k b2),
//            φ_k = 2π s_k ℓ / waveLength + phase,  r(s) = min(1, 5 s)
//   frizz:   t_k += frizz · s_k² · N_f(s_k)  (smooth noise, |N| ≤ √3)
// and is then re-placed follow-the-leader so every segment keeps its length:
//   x'_0 = x_0,   x'_{k+1} = x'_k + L_k (t_{k+1} - x'_k) / |t_{k+1} - x'_k|.
// u_f, phase and N_f are hashes of (seed, follower or clump centre): no RNG
// state. b1, b2 are unit vectors across the strand's chord (b1 from the root
// frame's tangent turned by the clump's phase, b2 = chord × b1).
#pragma once

#include "sim/followers/followers.h"

#include <cstdint>
#include <vector>

namespace hp {

struct GroomModifiers {
    float lengthVariation = 0.f;  ///< [0, 1): shortest follower is (1 - this) of its length
    float clump = 0.f;            ///< [0, 1]: pull toward the clump centre at the tip
    float clumpProfile = 1.f;     ///< exponent of the pull along the strand, > 0
    uint32_t clumps = 0;          ///< clump centres among the followers (0: no clumping)
    float wave = 0.f;             ///< m: wave amplitude
    float waveLength = 0.04f;     ///< m: wave period along the strand
    float curl = 0.f;             ///< [0, 1]: 0 a planar wave, 1 a helix (curl)
    float frizz = 0.f;            ///< m: frizz amplitude at the tip
    float frizzScale = 0.25f;     ///< strand fraction between frizz noise control points
    uint32_t seed = 1;

    /// True when any modifier changes a shape.
    bool active() const {
        return lengthVariation > 0.f || (clump > 0.f && clumps > 0) || wave > 0.f || frizz > 0.f;
    }
};

/// The followers' rest shapes with the modifiers applied: `base` (one rest
/// shape per follower, root-local as RestShapes says) at the rest roots
/// `roots`. Vertex counts are kept; segment lengths are kept exactly except
/// for the length variation's uniform factor per follower. Throws hp::Error
/// when the sizes disagree or a setting is out of range.
RestShapes modifyFollowerShapes(const RestShapes& base, const std::vector<SurfaceFrame>& roots,
                                const GroomModifiers& modifiers);

/// Applies the modifiers to a groom: when any is active, its followerShapes
/// become the modified shapes (of followerBaseShapes(groom) when it had
/// none). Inactive modifiers leave the groom untouched, so the followers are
/// bit for bit those of the unmodified groom.
void applyGroomModifiers(FollowerGroom& groom, const GroomModifiers& modifiers);

}  // namespace hp
