#include "pipeline/scene/follower_settings.h"

namespace hp {

FollowerSettings followerSettings(const Scene& s) {
    FollowerSettings f;
    const std::string& mode = s.text("hair.followers.mode");
    f.mode = mode == "cluster" ? FollowerMode::Cluster
             : mode == "interpolate" ? FollowerMode::Interpolate
             : mode == "barycentric" ? FollowerMode::Barycentric
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

GroomModifiers groomModifiers(const Scene& s) {
    GroomModifiers m;
    m.lengthVariation = float(s.number("hair.followers.length_variation"));
    m.clump = float(s.number("hair.followers.clump"));
    m.clumpProfile = float(s.number("hair.followers.clump_profile"));
    m.clumps = uint32_t(s.integer("hair.followers.clumps"));
    m.wave = float(s.number("hair.followers.wave"));
    m.waveLength = float(s.number("hair.followers.wave_length"));
    m.curl = float(s.number("hair.followers.curl"));
    m.frizz = float(s.number("hair.followers.frizz"));
    m.seed = uint32_t(s.integer("seed"));
    return m;
}

}  // namespace hp
