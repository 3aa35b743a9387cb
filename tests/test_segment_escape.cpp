// Where a segment's end goes in a pinch (sim/collision/segment_escape.h):
// outside every part at its exact length, nearest the wanted direction,
// else the least deep place. Against analytic solids built here: two
// overlapping spheres (a head tipping onto its neck: the surfaces meet at a
// crease with their normals 170° apart, the gap outside both a thin sliver
// about it) and a thin tilted slab gap.
#include "sim/collision/mesh_parts.h"
#include "sim/collision/segment_escape.h"
#include "sim/followers/follower_pinch.h"
#include "sim/guides/rod_kernels.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

using namespace hp;

namespace {

constexpr float kPi = 3.14159265f;

/// Two spheres of radius R whose surfaces cross at a circle where their
/// outward normals are `angle` apart: centres d apart with
/// cos(angle) = (2R² - d²)/(2R²) (the law of cosines in the triangle of
/// the centres and a crease point).
struct TwoSpheres {
    float R = 0.1f, d = 0.f;
    Vec3f a = Vec3f::Zero(), b = Vec3f::Zero();
    std::unique_ptr<PartsCollider> both;
    explicit TwoSpheres(float angle) {
        d = R * std::sqrt(2.f - 2.f * std::cos(angle));
        b = Vec3f(d, 0.f, 0.f);
        both = std::make_unique<PartsCollider>(std::vector<std::shared_ptr<const Collider>>{
            std::make_shared<SphereCollider>(a, R), std::make_shared<SphereCollider>(b, R)});
    }
    float phiA(const Vec3f& p) const { return (p - a).norm() - R; }
    float phiB(const Vec3f& p) const { return (p - b).norm() - R; }
    /// The point of the mid-plane x = d/2 at height h outside both spheres,
    /// toward direction (0, cos ψ, sin ψ) about the axis.
    Vec3f gapPoint(float h, float psi) const {
        const float s = std::sqrt((R + h) * (R + h) - 0.25f * d * d);
        return Vec3f(0.5f * d, s * std::cos(psi), s * std::sin(psi));
    }
};

}  // namespace

TEST(SegmentEscape, InTheCreaseOfTwoOverlappingSpheresTheEndLiesOutsideBoth) {
    // The parent 1 mm outside both spheres in the gap by the crease, the
    // segment 9.6 mm (the folding head's guides). Straight out from the
    // surface under the parent (the rod's old pin: sphere A's normal there)
    // points into sphere B; the place found is outside both with the
    // clearance, at the exact length.
    const TwoSpheres s(170.f * kPi / 180.f);
    const float L = 0.0096f, r = 1e-4f, h = 0.001f;
    const Vec3f parent = s.gapPoint(h, 0.3f);
    ASSERT_NEAR(s.phiA(parent), h, 1e-6f);
    ASSERT_NEAR(s.phiB(parent), h, 1e-6f);
    const Vec3f straightOut = parent + L * (parent - s.a).normalized();
    EXPECT_LT(s.phiB(straightOut), -0.005f) << "the straight-out pin goes deep into the other sphere";

    const SegmentEscape e = escapeSegment(*s.both, parent, L, r, straightOut, &straightOut);
    EXPECT_TRUE(e.outside);
    EXPECT_NEAR((e.position - parent).norm() / L, 1.f, 1e-5f) << "at its length";
    EXPECT_GE(s.phiA(e.position), r * 0.99f) << "outside sphere A";
    EXPECT_GE(s.phiB(e.position), r * 0.99f) << "outside sphere B";
    EXPECT_NEAR(e.distance, std::min(s.phiA(e.position), s.phiB(e.position)), 1e-6f);
    std::printf("straight out: %.3f mm inside B; escaped: %.3f / %.3f mm outside A / B\n",
                -1e3f * s.phiB(straightOut), 1e3f * s.phiA(e.position), 1e3f * s.phiB(e.position));

    // The followers' pinch takes the same place: bent, not pinned.
    const follower::PinchPlace f = follower::placePinched(*s.both, parent, L, r, straightOut, &straightOut);
    EXPECT_FALSE(f.pinned);
    EXPECT_GE(std::min(s.phiA(f.position), s.phiB(f.position)), r * 0.99f);
}

TEST(SegmentEscape, AGapThinnerThanTheLatticeIsFoundByClimbing) {
    // Solid on both sides of a 0.3 mm slab gap, tilted; parent on its
    // mid-plane, segment 1 cm, clearance 0.05 mm: the ends outside are the
    // directions with |u·n| <= (0.15 - 0.05)/10 = 0.01, a band of ±0.57°
    // about a great circle, narrower than the lattice's 13° spacing.
    class TiltedSlab final : public Collider {
      public:
        TiltedSlab(const Vec3f& n, float gap) : n_(n.normalized()), gap_(gap) {}
        float signedDistance(const Vec3f& p, Vec3f* normal) const override {
            const float below = p.dot(n_) + 0.5f * gap_, above = 0.5f * gap_ - p.dot(n_);
            if (normal) *normal = below <= above ? n_ : Vec3f(-n_);
            return std::min(below, above);
        }
        Vec3f n_;
        float gap_;
    };
    const TiltedSlab slab(Vec3f(-0.42f, 0.6f, -0.33f), 3e-4f);  // no lattice direction within 0.037 of the band
    const float L = 0.01f, r = 5e-5f;
    const Vec3f parent = Vec3f::Zero(), wanted = L * slab.n_;  // straight out of the lower side
    const SegmentEscape e = escapeSegment(slab, parent, L, r, wanted, nullptr);
    EXPECT_TRUE(e.outside);
    EXPECT_NEAR(e.position.norm() / L, 1.f, 1e-5f);
    EXPECT_GE(slab.signedDistance(e.position, nullptr), r * 0.99f);
    // Nearest the wanted direction among those outside: |u·n| at the band's edge.
    EXPECT_NEAR(e.position.dot(slab.n_) / L, (0.5f * slab.gap_ - r) / L, 2e-3f);
}

TEST(SegmentEscape, WithNoPlaceOutsideTheLeastDeepIsTakenAtItsLength) {
    // A closed pocket, a free ball of 4 mm about the parent, its depth
    // at 1 cm least toward +x (φ = 0.004 - |p| + 0.001·p_x/|p|: -5 mm there,
    // -7 mm toward -x): no place at the segment's length is outside, and the
    // vertex goes to the least deep one, climbing from its held place.
    class Ball final : public Collider {
      public:
        float signedDistance(const Vec3f& p, Vec3f* normal) const override {
            if (normal) *normal = -p.normalized();
            return 0.004f - p.norm() + 0.001f * p.x() / std::max(p.norm(), 1e-9f);
        }
    };
    const Ball pocket;
    const float L = 0.01f;
    const Vec3f held(0.f, 0.f, 0.003f);
    const SegmentEscape e = escapeSegment(pocket, Vec3f::Zero(), L, 1e-4f, Vec3f(0.f, L, 0.f), &held);
    EXPECT_FALSE(e.outside);
    EXPECT_NEAR(e.position.norm() / L, 1.f, 1e-5f);
    EXPECT_NEAR(e.distance, -0.005f, 2e-6f) << "the least deep place, +x, found by climbing from the held one";
    EXPECT_GT(e.position.x() / L, 0.99f);
}

TEST(SegmentEscape, TheRodPinsAVertexCaughtInAWedgeOutsideBothParts) {
    // A wedge of free space 10° wide between two half-spaces, each a part
    // of one head (the union's outside is the wedge): a guide rooted on its
    // bisector 3 mm from the apex, its 9.6 mm segments pointing back past
    // the apex, deep in the upper part, at rest, no gravity. rod::rodStep's
    // slide along one face runs into the other, so the vertex is pinned;
    // straight out from the surface under its parent (the old pin) points
    // across the wedge into the other part. Held at its length, it is
    // outside both.
    class HalfSpace final : public Collider {
      public:
        explicit HalfSpace(const Vec3f& n) : n_(n.normalized()) {}
        float signedDistance(const Vec3f& p, Vec3f* normal) const override {
            if (normal) *normal = n_;
            return p.dot(n_);
        }
        Vec3f n_;
    };
    const float beta = 5.f * kPi / 180.f, L = 0.0096f, r = 1e-4f;
    // Solid above y = x tan β and below y = -x tan β: outward normals (sin β, ∓cos β, 0).
    const auto upper = std::make_shared<HalfSpace>(Vec3f(std::sin(beta), -std::cos(beta), 0.f));
    const auto lower = std::make_shared<HalfSpace>(Vec3f(std::sin(beta), std::cos(beta), 0.f));
    const PartsCollider wedge({upper, lower});
    strand::HeadQuery head;
    head.collider = &wedge;
    const int n = 3;
    std::vector<float> rest(size_t(n - 1), L), invMass(size_t(n), 1.f / (1e-4f * L));
    invMass[0] = 0.f;
    std::vector<rod::Vec2f> curvature(size_t(n - 1), rod::Vec2f::Zero());
    rod::RodStrand strand;
    strand.vertices = n;
    strand.restLength = rest.data();
    strand.invMass = invMass.data();
    strand.restCurvature = curvature.data();
    strand.ghostDir = Vec3f::UnitX();
    std::vector<Vec3f> x(static_cast<size_t>(n), Vec3f::Zero()), v(static_cast<size_t>(n), Vec3f::Zero());
    x[0] = Vec3f(0.003f, 0.f, 0.f);
    const Vec3f back = Vec3f(-1.f, 0.2f, 0.f).normalized();
    for (int i = 1; i < n; ++i) x[size_t(i)] = x[size_t(i - 1)] + L * back;
    ASSERT_LT(upper->signedDistance(x[1], nullptr), -0.001f);
    rod::RodScratch scratch;
    const int pinned = rod::rodStep(strand, x.data(), v.data(), x[0], rod::Mat3f::Identity(), Vec3f::Zero(), 1.f / 72,
                                    0.f, 0.f, &head, r, scratch);
    EXPECT_GE(pinned, 1) << "the case the pin rule is for";
    for (int i = 1; i < n; ++i) {
        const Vec3f& p = x[size_t(i)];
        EXPECT_NEAR((p - x[size_t(i - 1)]).norm() / L, 1.f, 1e-4f) << "vertex " << i << " at its length";
        EXPECT_GE(upper->signedDistance(p, nullptr), -1e-3f) << "vertex " << i << " within 1 mm of outside the upper part";
        EXPECT_GE(lower->signedDistance(p, nullptr), -1e-3f) << "vertex " << i << " within 1 mm of outside the lower part";
    }
    std::printf("rod: %d pinned; vertex 1 %.3f / %.3f mm, vertex 2 %.3f / %.3f mm outside upper / lower\n", pinned,
                1e3f * upper->signedDistance(x[1], nullptr), 1e3f * lower->signedDistance(x[1], nullptr),
                1e3f * upper->signedDistance(x[2], nullptr), 1e3f * lower->signedDistance(x[2], nullptr));
}
