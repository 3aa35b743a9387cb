#include "pipeline/follower_settings.h"

namespace hp {

FollowerSettings followerSettings(const Scene& s) {
    FollowerSettings f;
    const std::string& mode = s.text("hair.followers.mode");
    f.mode = mode == "cluster" ? FollowerMode::Cluster
             : mode == "interpolate" ? FollowerMode::Interpolate
                                     : FollowerMode::Varied;
    f.neighbours = s.text("hair.followers.neighbours") == "shape-similarity" ? NeighbourRule::ShapeSimilarity
                                                                             : NeighbourRule::Nearest;
    f.fixedOffset = float(s.number("hair.followers.fixed_offset"));
    f.maxVelocity = float(s.number("hair.followers.max_velocity"));
    f.collide = s.flag("hair.followers.collide");
    f.parallel = s.flag("hair.followers.parallel");
    f.seed = uint32_t(s.integer("seed"));
    // Followers taper like the guides (hair.radius.*; the curly model has its own).
    f.rootRadius = float(s.number("hair.radius.root"));
    f.tipRadius = float(s.number("hair.radius.tip"));
    return f;
}

}  // namespace hp
