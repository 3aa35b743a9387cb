// The rod step's head contact (sim/guides/rod_step.cpp) against energy
// balance: a curled strand lying on a sphere must come to rest under drag
// and never gain energy from the contact, under both integrators and at
// several rod substeps.
#include "rod_cases.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

using namespace hp;
using namespace hp::rodcases;

namespace {

constexpr float kSphere = 0.1f;    ///< sphere radius (the benchmark head), m
constexpr float kWisp = 0.22f;     ///< the default scene's guide length, m
constexpr float kDrag = 10.f;      ///< the groom settling's drag, 1/s
constexpr float kStep = 0.02f;     ///< the solver step, s

struct Settled {
    double kineticEnd = 0;  ///< kinetic energy at the end, J
    double released = 0;    ///< E(0) - min E over the run: what gravity and bending gave up, J
    double rise = 0;        ///< max over the run of E(t) - min E(s ≤ t): energy regained, J
    double floor = 0;       ///< float-resolution kinetic energy of the strand, J
};

/// The strands below: straight, or curled in the vertical plane (x, y) and
/// falling in it (gravity straight down: the motion stays planar), or
/// curled and falling out of that plane (gravity tilted 3° toward +x and
/// +z: the motion is three-dimensional).
enum class Shape { Straight, CurledPlanar, Curled3d };

/// A 22 cm wisp of the default fibre (23 segments) rooted on the top of a
/// sphere of radius 10 cm, its root segment along the surface (+x). Curled,
/// its rest curvature turns it up and back 3.5 rad over its first 30% (a
/// crown hook combed forward and arcing over its root), then it runs
/// straight, back over the crown and clear of the sphere. It starts in its
/// rest shape (E(0): gravitational only, at rest) and falls onto the
/// sphere. Friction 0, drag kDrag, the root still; `seconds` of steps of
/// kStep/substeps.
/// E = Σ ½ m_i |v_i|² - Σ m_i g·x_i + Σ EI/(2 l̄_j)|C_j|² (rod::bendEnergy).
Settled onSphere(Shape shape, bool bdf2, int substeps, bool sphereOn, double seconds) {
    const GuideSettings gs;
    const rod::Material m = material(gs);
    const int segs = 23, n = segs + 1;
    const float l = kWisp / float(segs), radius = gs.collisionRadius;
    std::vector<float> rest(size_t(segs), l), invMass(static_cast<size_t>(n));
    const double mSeg = m.massPerLength() * l;
    for (int i = 0; i < n; ++i) invMass[size_t(i)] = float(1.0 / (i == n - 1 ? 0.5 * mSeg : mSeg));
    invMass[0] = 0.f;
    // The rest shape: the first 30% of the arc turns 3.5 rad about +y.
    const int curled = int(std::lround(0.3 * segs));
    const float turn = (shape == Shape::Straight ? 0.f : 3.5f) / float(curled);
    const size_t nv = size_t(n);
    std::vector<Vec3f> x(nv), v(nv, Vec3f::Zero()), xb(nv), vb(nv);
    x[0] = Vec3f(0.f, kSphere + radius, 0.f);
    float angle = 0.f;
    for (int j = 0; j < segs; ++j) {
        if (j > 0 && j <= curled) angle += turn;
        x[size_t(j) + 1] = x[size_t(j)] + l * Vec3f(std::cos(angle), std::sin(angle), 0.f);
    }
    std::vector<rod::Vec2f> curvature(static_cast<size_t>(segs));
    rod::RodStrand s;
    s.vertices = n;
    s.restLength = rest.data();
    s.invMass = invMass.data();
    s.restCurvature = curvature.data();
    s.ghostDir = Vec3f::UnitX();  // root frame = world
    s.bendStiffness = m.bendStiffness();
    rod::restCurvature(s, x.data(), rod::Mat3f::Identity(), curvature.data());

    const SphereCollider sphere(Vec3f::Zero(), kSphere);
    strand::HeadQuery head;
    head.collider = &sphere;
    const float tilt = shape == Shape::Curled3d ? 3.f * float(M_PI) / 180.f : 0.f;
    const Vec3f g = float(kG) * Vec3f(std::sin(tilt), -std::cos(tilt), 0.5f * std::sin(tilt));
    const float h = kStep / float(substeps);
    rod::bdf2Start(x.data(), v.data(), n, h, xb.data(), vb.data());
    auto energy = [&] {
        double e = rod::bendEnergy(s, x.data(), rod::Mat3f::Identity());
        for (int i = 1; i < n; ++i) {
            const double mi = 1.0 / invMass[size_t(i)];
            e += 0.5 * mi * double(v[size_t(i)].squaredNorm()) - mi * double(g.dot(x[size_t(i)]));
        }
        return e;
    };
    Settled out;
    const double e0 = energy();
    double low = e0;
    rod::RodScratch scratch;
    const long steps = std::lround(seconds / double(h));
    for (long k = 0; k < steps; ++k) {
        rod::RodStepTarget t{&s, x.data(), v.data(), x[0], rod::Mat3f::Identity()};
        if (bdf2) {
            t.xBack = xb.data();
            t.vBack = vb.data();
        }
        rod::rodSteps(&t, 1, g, h, kDrag, 0.f, sphereOn ? &head : nullptr, radius, scratch);
        const double e = energy();
        out.rise = std::max(out.rise, e - low);
        low = std::min(low, e);
    }
    out.released = e0 - low;
    for (int i = 1; i < n; ++i) out.kineticEnd += 0.5 / invMass[size_t(i)] * double(v[size_t(i)].squaredNorm());
    // A vertex's position is resolved to ε·R (R ~ 0.1 m, the coordinates'
    // size), its velocity so to ε·R/h', a kinetic-energy floor of
    // Σ ½ m (ε R/h')² the step cannot go below.
    const double dv = std::numeric_limits<float>::epsilon() * kSphere / (2.0 / 3.0 * h);
    for (int i = 1; i < n; ++i) out.floor += 0.5 / invMass[size_t(i)] * dv * dv;
    return out;
}

struct Case {
    bool bdf2;
    int substeps;
};

std::string name(const Case& c) { return std::string(c.bdf2 ? "bdf2" : "euler") + "_" + std::to_string(c.substeps); }

const Case kCases[] = {{true, 1}, {true, 2}, {true, 8}, {false, 1}, {false, 2}, {false, 8}};

/// Kinetic energy left after 5 s. The drag multiplies every velocity by
/// e^(-c·h) each step, so once gravity and bending have released what they
/// will (a second to land), a strand's kinetic energy decays at least like
/// e^(-2c·t): released·e^(-2c·4 s) is 10⁻⁴⁰ J here. A frictionless contact
/// with a still sphere does no work (it holds the weight, takes nothing
/// along the surface and gives nothing back), so with the sphere the strand
/// must come to rest as it does without. What remains is the float floor
/// of the velocities (onSphere: Σ ½ m (ε R/h')²), allowed 100 times.
double restBound(const Settled& r) { return r.released * std::exp(-2.0 * kDrag * 4.0) + 100.0 * r.floor; }

void report(const std::string& label, const Settled& r) {
    std::printf("%s: released %.3g J, kinetic at the end %.3g J (floor %.3g J), largest rise %.3g J\n", label.c_str(),
                r.released, r.kineticEnd, r.floor, r.rise);
}

/// The strand of `shape` settled 5 s on the sphere under case c, printed and
/// recorded as the test's properties (kinetic energy left, largest rise).
Settled settledOnSphere(Shape shape, const std::string& label, const Case& c) {
    const Settled r = onSphere(shape, c.bdf2, c.substeps, true, 5.0);
    report(label + " " + name(c), r);
    ::testing::Test::RecordProperty(name(c) + "_kinetic_end_fJ", std::to_string(r.kineticEnd * 1e15));
    ::testing::Test::RecordProperty(name(c) + "_rise_per_mille", std::to_string(1e3 * r.rise / r.released));
    return r;
}

}  // namespace

TEST(RodContact, StraightStrandOnASphereComesToRestAndNeverGainsEnergy) {
    // Energy: the total E = kinetic + gravitational + bending can only fall
    // (drag, the implicit step's dissipation, the inelastic contact); it may
    // come back from its lowest value so far by no more than 1% of what was
    // released: the placement lifts a resting vertex by one step's sag h²g
    // before the next step lets it down (measured ≤ 0.19%).
    for (const Case& c : kCases) {
        const Settled r = settledOnSphere(Shape::Straight, "straight", c);
        EXPECT_GT(r.released, 0.0) << name(c) << ": the strand did not fall onto the sphere";
        EXPECT_LT(r.kineticEnd, restBound(r)) << name(c) << ": the strand on the sphere does not come to rest";
        EXPECT_LT(r.rise, 0.01 * r.released) << name(c) << ": the contact gave the strand energy";
    }
}

TEST(RodContact, PlanarCurledStrandOnASphereComesToRest) {
    // The curled hook falling in its own plane comes to rest on the sphere.
    // Its energy rises from its lowest by up to 8% of the release (measured,
    // recorded here, not bounded), where the hook lands and presses on the
    // sphere; not yet attributed (the step's solve does not see the
    // contact, and the placement after it changes the bending energy the
    // solve assumed: a candidate, not measured phase by phase).
    for (const Case& c : kCases) {
        const Settled r = settledOnSphere(Shape::CurledPlanar, "planar curled", c);
        EXPECT_GT(r.released, 0.0) << name(c);
        EXPECT_LT(r.kineticEnd, restBound(r)) << name(c) << ": the strand on the sphere does not come to rest";
    }
}

TEST(RodContact, CurledStrandComesToRestOnASphereAndNeverGainsEnergyInTheAir) {
    // The hook falling out of its plane (the default groom's settling in
    // one strand): its frame turns with the motion (the holonomy), which the
    // step's gradient includes for a curled strand (rod::constraintJacobian),
    // so its force is the gradient of the energy it reports. In the air it
    // must not gain energy (1% of the release, both integrators, 1, 2 and 8
    // substeps: measured ≤ 10⁻⁵ of it; without the holonomy it gained 5 to 7
    // times the release). On the sphere it must come to rest: it still
    // slides slowly at 5 s (6·10⁻¹⁵ J at 1 substep, 2·10⁻¹⁰ of the release),
    // so 10 s. Its energy there rises from its lowest by up to 10% of the
    // release, as the planar hook's does (above: the contact's rise, not
    // the holonomy's), recorded, not bounded.
    for (const Case& c : kCases) {
        const Settled r = onSphere(Shape::Curled3d, c.bdf2, c.substeps, true, 10.0);
        report("curled on the sphere, 10 s, " + name(c), r);
        ::testing::Test::RecordProperty(name(c) + "_sphere_rise_per_mille", std::to_string(1e3 * r.rise / r.released));
        EXPECT_GT(r.released, 0.0) << name(c);
        EXPECT_LT(r.kineticEnd, restBound(r)) << name(c) << ": the strand on the sphere does not come to rest";
        const Settled air = onSphere(Shape::Curled3d, c.bdf2, c.substeps, false, 5.0);
        report("curled in the air " + name(c), air);
        ::testing::Test::RecordProperty(name(c) + "_air_rise_per_mille", std::to_string(1e3 * air.rise / air.released));
        EXPECT_GT(air.released, 0.0) << name(c);
        EXPECT_LT(air.kineticEnd, restBound(air)) << name(c) << ": the strand in the air does not come to rest";
        EXPECT_LT(air.rise, 0.01 * air.released) << name(c) << ": the strand gained energy in the air";
    }
}
