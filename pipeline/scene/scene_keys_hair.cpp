// hair.* root placement: how many guide and follower roots, and how they
// are spread over the scalp (sim/strands/roots.h). The solver and follower keys live
// in their own files.
#include "pipeline/scene/scene_keys.h"

namespace hp {

void addHairKeys(SchemaBuilder& b) {
    b.section("hair", "Hair grown on the head's scalp (head.scalp): guide strands simulated, followers interpolated.");
    b.section("hair.guides", "Simulated guide strands.")
        .integer("hair.guides.count", 845, 0, 1000000, "", "Number of guide roots.");
    b.section("hair.followers", "Follower strands, placed independently of the guides.")
        .integer("hair.followers.count", 100000, 0, 10000000, "", "Number of follower roots.");
    b.section("hair.roots", "Root placement on the scalp; roots ride the deforming mesh (triangle + barycentrics).")
        .choice("hair.roots.method", "fibonacci", {"fibonacci", "blue-noise"},
                "fibonacci: the seed's Fibonacci sphere lattice around the scalp's centre (a sphere fit, or the "
                "region's centre and axis) projected onto the outermost surface; blue-noise: area-uniform "
                "Poisson-disk roots by sample elimination (random from the scene seed).");
}

}  // namespace hp
