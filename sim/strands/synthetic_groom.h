// @brief A procedural groom on the benchmark sphere head and a deterministic
// guide motion, for follower tests and the B-follow benchmark when no guide
// solver runs (docs/benchmarks.md: sphere r = 0.1 m spinning 90°/s about +Y,
// guides and followers on independent Fibonacci lattices over the upper
// hemisphere, 0.25 m, 24 vertices).
//
// The motion is not physics: each guide hangs in sim/strands/synthetic.h's drooping
// shape (leaving along the normal, bending toward -Y, kept outside the head),
// sways sideways, and is carried rigidly by the spinning head.
#pragma once

#include "sim/followers/followers.h"

#include <Eigen/Geometry>

namespace hp {

struct SphereGroomSettings {
    size_t guides = 845;
    size_t followers = 100000;
    int vertices = 24;          ///< per strand (23 segments)
    float length = 0.25f;       ///< m
    float headRadius = 0.1f;    ///< sphere centred at the origin
    float capMinCosine = 0.f;   ///< 0 = upper hemisphere
};

/// Root frame of a point on the sphere: normal = `direction`, tangent an
/// arbitrary unit vector orthogonal to it (Eigen's unitOrthogonal, which
/// jumps between neighbouring roots the way mesh tangents do).
SurfaceFrame sphereRootFrame(const Vec3f& direction, float radius);

/// Guide and follower rest roots (independent Fibonacci caps), straight
/// guide rest shapes along the normal, follower vertex count and length.
FollowerGroom makeSphereGroom(const SphereGroomSettings& settings);

/// Rest root frames turned by the head's rotation.
void rotateRoots(const std::vector<SurfaceFrame>& rest, const Eigen::Quaternionf& rotation,
                 std::vector<SurfaceFrame>& out);

struct SyntheticGuideSettings {
    float degreesPerSecond = 90.f;  ///< head spin about +Y
    float droop = 1.f;              ///< sim/strands/synthetic.h's droop
    /// How fast the strand turns toward the droop direction: weight
    /// min(1, droop · bend · k / (n - 1)) at vertex k; 1 is sim/strands/synthetic.h's
    /// gentle arc, 3 lays the hair over the head like hair under gravity.
    float bend = 3.f;
    float sway = 0.35f;             ///< sideways lean of the droop direction (fraction of -Y)
    float swayHz = 0.5f;
    float headRadius = 0.1f;
};

/// Drooping, swaying guides carried by the spinning sphere.
class SyntheticGuides {
  public:
    SyntheticGuides(const FollowerGroom& groom, const SyntheticGuideSettings& settings);

    /// Guides (positions, velocities by a 1 ms backward difference, radii,
    /// ids 0..G-1) and their root frames at `time`, written into the given
    /// buffers (capacity reused).
    void sample(double time, StrandFrame& guides, std::vector<SurfaceFrame>& guideRoots) const;
    /// The head's rotation at `time`.
    Eigen::Quaternionf headRotation(double time) const;

  private:
    void shape(double time, size_t guide, Vec3f* out) const;

    SyntheticGuideSettings settings_;
    std::vector<SurfaceFrame> rest_;
    std::vector<uint32_t> vertices_;
    std::vector<float> lengths_;
};

}  // namespace hp
