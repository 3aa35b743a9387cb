#include "pipeline/scene/follower_settings.h"
#include "pipeline/scene/key_fields.h"

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
    readKeys(s, f, {
        {"hair.followers.fixed_offset", &FollowerSettings::fixedOffset},
        {"hair.followers.max_velocity", &FollowerSettings::maxVelocity},
        {"hair.followers.collide", &FollowerSettings::collide},
        {"hair.followers.parallel", &FollowerSettings::parallel},
        {"seed", &FollowerSettings::seed},
    });
    // Followers taper like the guides (hair.radius.*; the curly model has its own).
    f.rootRadius = float(s.number("hair.radius.root"));
    f.tipRadius = float(s.number("hair.radius.tip"));
    return f;
}

GroomModifiers groomModifiers(const Scene& s) {
    GroomModifiers m;
    readKeys(s, m, {
        {"hair.followers.length_variation", &GroomModifiers::lengthVariation},
        {"hair.followers.clump", &GroomModifiers::clump},
        {"hair.followers.clump_profile", &GroomModifiers::clumpProfile},
        {"hair.followers.clumps", &GroomModifiers::clumps},
        {"hair.followers.wave", &GroomModifiers::wave},
        {"hair.followers.wave_length", &GroomModifiers::waveLength},
        {"hair.followers.curl", &GroomModifiers::curl},
        {"hair.followers.frizz", &GroomModifiers::frizz},
        {"seed", &GroomModifiers::seed},
    });
    return m;
}

}  // namespace hp
