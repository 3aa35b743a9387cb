// hair.followers.*: how follower strands follow their guides (seed 000,
// sim/followers/followers.h). The follower count and root placement live with the roots.
#include "pipeline/scene/scene_keys.h"

namespace hp {

void addFollowerKeys(SchemaBuilder& b) {
    b.section("hair.followers",
              "Follower strands: strands without physics rebuilt every step from their own root on the "
              "deformed scalp, copying or interpolating the segment rotations of their two nearest guides "
              "(seed 000, Algorithm 1).")
        .choice("hair.followers.mode", "varied", {"cluster", "interpolate", "varied", "barycentric"},
                "cluster: copy the nearest guide's segment rotations; interpolate: slerp between the two "
                "nearest guides by relative root distance d1/(d1+d2); varied: slerp by "
                "fixed_offset·d_f(y) + rand·min(|v1|, max_velocity) (the seed's recommended mode); "
                "barycentric: blend the rotations of the three guides of the guide-root triangle over the "
                "follower (Delaunay on the scalp) by barycentric weights, so followers fill the volume "
                "between guides instead of sheets between two (neighbours is not used).")
        .choice("hair.followers.neighbours", "nearest", {"nearest", "shape-similarity"},
                "nearest: the two nearest guide roots, ordered (the seed's rule); shape-similarity: among "
                "the 8 nearest roots, the guides whose rest shapes are most alike (keeps followers from "
                "blending across a parting).")
        .number("hair.followers.fixed_offset", 0.2, 0, 1, "",
                "Varied mode: weight of the fixed offset d_f(y) = 1 - (y - qs)²/qs², which is 0 at root "
                "and tip and 1 mid-strand.")
        .number("hair.followers.max_velocity", 0.1, 0, 1000, "m/s",
                "Varied mode: clamp of the nearest guide's segment speed, the size of the per-segment "
                "random variation.")
        .flag("hair.followers.collide", true,
              "Push follower vertices that end up inside the head back out along the distance gradient, "
              "keeping segment lengths (follow-the-leader).")
        .flag("hair.followers.parallel", true,
              "Update followers on all threads (false: on one thread, seed 000's prototype without "
              "parallelisation; results are identical either way).")
        // Groom modifiers (sim/strands/groom_modifiers.h): applied once to the
        // followers' rest shapes, so the animation carries them and segment
        // lengths stay exact. All 0: the followers of the unmodified groom.
        .number("hair.followers.length_variation", 0, 0, 0.99, "",
                "Groom modifier: each follower's length is scaled by 1 - length_variation·u, u uniform in "
                "[0, 1) per follower (seeded by `seed`).")
        .number("hair.followers.clump", 0, 0, 1, "",
                "Groom modifier: pull of each follower toward its clump centre (the nearest of "
                "`clumps` centre followers) at the tip; along the strand clump·s^clump_profile, s the arc "
                "fraction.")
        .number("hair.followers.clump_profile", 1, 0.05, 20, "",
                "Groom modifier: exponent of the clump pull along the strand (1 linear from root to tip; "
                "larger keeps the clumps to the tips).")
        .integer("hair.followers.clumps", 2000, 1, 10000000, "",
                 "Groom modifier: number of clump centres, chosen among the followers by a seeded hash "
                 "(used when clump > 0).")
        .number("hair.followers.wave", 0, 0, 0.1, "m",
                "Groom modifier: wave amplitude across the strand (ramping in over the first fifth); the "
                "phase and plane are shared by a clump.")
        .number("hair.followers.wave_length", 0.04, 0.001, 10, "m", "Groom modifier: wave period along the strand.")
        .number("hair.followers.curl", 0, 0, 1, "",
                "Groom modifier: 0 a planar wave, 1 a helix (curl) of radius `wave`.")
        .number("hair.followers.frizz", 0, 0, 0.1, "m",
                "Groom modifier: amplitude at the tip of smooth random noise that grows as s² along the "
                "strand (control points every quarter of the strand).");
}

}  // namespace hp
