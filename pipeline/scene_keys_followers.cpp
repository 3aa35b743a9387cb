// hair.followers.*: how follower strands follow their guides (seed 000,
// sim/followers.h). The follower count and root placement live with the roots.
#include "pipeline/scene_keys.h"

namespace hp {

void addFollowerKeys(SchemaBuilder& b) {
    b.section("hair.followers",
              "Follower strands: strands without physics rebuilt every step from their own root on the "
              "deformed scalp, copying or interpolating the segment rotations of their two nearest guides "
              "(seed 000, Algorithm 1).")
        .choice("hair.followers.mode", "varied", {"cluster", "interpolate", "varied"},
                "cluster: copy the nearest guide's segment rotations; interpolate: slerp between the two "
                "nearest guides by relative root distance d1/(d1+d2); varied: slerp by "
                "fixed_offset·d_f(y) + rand·min(|v1|, max_velocity) (the seed's recommended mode).")
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
              "parallelisation; results are identical either way).");
}

}  // namespace hp
