// The rod formulation (sim/guides/rod_kernels.h, sim/guides/rod_group.cpp) against the
// references tests/rod_cases.h computes: heavy elastica by shooting, the
// hanging chain's Bessel mode, energy balance; pre-load and sag.
#include "rod_cases.h"

#include <gtest/gtest.h>

using namespace hp;
using namespace hp::rodcases;

TEST(Rod, HeavyElasticaTipMatchesShootingWithinTwoPercentOfLength) {
    for (double beta : {0.5, 2.0, 8.0, 32.0, 128.0}) {
        const Cantilever one = cantilever(beta, 1), two = cantilever(beta, 2);
        RecordProperty("tip_error_beta_" + std::to_string(beta), std::to_string(one.error));
        EXPECT_LE(one.error, 0.02f) << "β = " << beta;
        EXPECT_LE(one.maxStretch, 1e-3) << "β = " << beta;
        EXPECT_LT(one.kineticEnergy, 1e-9) << "not at rest, β = " << beta;
        EXPECT_EQ(one.positions, two.positions) << "1 and 2 threads differ, β = " << beta;
    }
}

TEST(Rod, HangingChainFirstModePeriodMatchesBessel) {
    const Pendulum p = pendulum();
    RecordProperty("pendulum_period_error", std::to_string(p.error));
    ASSERT_GE(p.crossings, 6u) << "the tip should swing through the vertical";
    EXPECT_LE(p.error, 0.03) << "period " << p.period << " s, chain " << p.reference << " s";
    EXPECT_LE(p.maxStretch, 1e-3);
}

TEST(Rod, ReleasedFromHorizontalNeverGainsEnergyAndComesToRestWithDrag) {
    const Energy e = energy();
    RecordProperty("energy_drift", std::to_string(e.drift));
    EXPECT_LE(e.drift, 0.01);
    EXPECT_LT(e.dampedKinetic, 1e-6);
    EXPECT_LE(e.maxStretch, 1e-3);
}

TEST(Rod, PreloadHoldsTheGroomAndWithoutItHairHangs) {
    // A strand combed out sideways, turning down and slightly aside.
    GuideSettings s = rodSettings(3.8e9f, 1.f, true);
    std::vector<Vec3f> x(size_t(s.segments) + 1, Vec3f::Zero());
    const float l = kLength / float(s.segments);
    for (int i = 0; i < s.segments; ++i) {
        const float a = 0.6f * float(i) / float(s.segments);
        x[size_t(i) + 1] = x[size_t(i)] + l * Vec3f(std::cos(a), -std::sin(a), 0.2f * std::sin(2.f * a)).normalized();
    }
    Strand held(s, x);
    held.run(1.0);
    const StrandFrame f = held.frame();
    float moved = 0;
    for (size_t i = 0; i < x.size(); ++i) moved = std::max(moved, (f.positions[i] - x[i]).norm());
    RecordProperty("preload_motion_um", std::to_string(moved * 1e6f));
    EXPECT_LE(moved, 1e-3f) << "the pre-loaded groom moved " << moved * 1000 << " mm in 1 s";
    EXPECT_LE(held.worst.maxLengthError, 1e-3);

    s.preload = false;
    Strand hangs(s, x);
    hangs.run(1.0);
    EXPECT_GT(x.back().y() - hangs.frame().positions.back().y(), 0.05f)
        << "without pre-load the tip should fall under gravity";
}
