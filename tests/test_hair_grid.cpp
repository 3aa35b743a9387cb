// The hair-hair grid's kernel (sim/volume/hair_grid.h) against the
// properties the method promises: momentum kept, no kinetic energy added,
// uniform motion untouched, the density it measures, the same bits on any
// thread count. The guide solver with the grid on is tests/test_hair_volume.cpp.
#include "sim/strands/strand.h"
#include "sim/volume/hair_grid.h"

#include "volume_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

using namespace hp;
using namespace hp::test;
using volume::GridInput;
using volume::HairGrid;

namespace {

/// The grid's view of particle arrays (x, v, mass), one substep of h seconds.
GridInput gridInput(std::vector<Vec3f>& x, std::vector<Vec3f>& v, const std::vector<float>& m, float lengthPerMass,
                    float h) {
    GridInput in;
    in.x = x.data();
    in.v = v.data();
    in.mass = m.data();
    in.count = x.size();
    in.lengthPerMass = lengthPerMass;
    in.h = h;
    return in;
}

/// Random particles in a 6 cm box, masses 0.5-2 mg, velocities ±1 m/s.
struct Cloud {
    std::vector<Vec3f> x, v;
    std::vector<float> m;
    explicit Cloud(size_t n, unsigned seed = 3) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<float> u(-1.f, 1.f);
        for (size_t i = 0; i < n; ++i) {
            x.push_back(0.03f * Vec3f(u(rng), u(rng), u(rng)));
            v.push_back(Vec3f(u(rng), u(rng), u(rng)));
            m.push_back(1e-6f * (1.25f + 0.75f * u(rng)));
        }
    }
    GridInput input(float lengthPerMass = 1e4f) { return gridInput(x, v, m, lengthPerMass, 1.f / 72.f); }
    Eigen::Vector3d momentum() const {
        Eigen::Vector3d p = Eigen::Vector3d::Zero();
        for (size_t i = 0; i < x.size(); ++i) p += double(m[i]) * v[i].cast<double>();
        return p;
    }
    double kinetic() const {
        double e = 0;
        for (size_t i = 0; i < x.size(); ++i) e += 0.5 * double(m[i]) * v[i].cast<double>().squaredNorm();
        return e;
    }
};

VolumeSettings frictionOnly(float rate) {
    VolumeSettings s;
    s.enabled = true;
    s.friction = rate;
    s.relaxTime = 0.f;
    return s;
}

}  // namespace

TEST(HairGrid, FrictionKeepsMomentumMassWeighted) {
    Cloud c(2000);
    const Eigen::Vector3d before = c.momentum();
    const std::vector<Vec3f> v0 = c.v;
    HairGrid grid(frictionOnly(50.f));
    grid.apply(c.input(), reversedFor);
    double moved = 0, scale = 0;
    for (size_t i = 0; i < c.x.size(); ++i) {
        moved += c.m[i] * (c.v[i] - v0[i]).norm();
        scale += c.m[i] * v0[i].norm();
    }
    EXPECT_GT(moved, 0.1 * scale) << "the blend changes velocities";
    EXPECT_LT((c.momentum() - before).norm(), 1e-5 * scale)
        << "momentum " << before.transpose() << " -> " << c.momentum().transpose();
}

TEST(HairGrid, FrictionNeverAddsKineticEnergy) {
    for (float rate : {1.f, 10.f, 100.f, 1e4f}) {
        Cloud c(1500, 11);
        const double before = c.kinetic();
        HairGrid grid(frictionOnly(rate));
        grid.apply(c.input(), reversedFor);
        EXPECT_LT(c.kinetic(), before) << "rate " << rate;
    }
}

TEST(HairGrid, UniformMotionIsUntouched) {
    // Friction acts on motion relative to the hair around: a cloud moving as
    // one keeps its velocity (V_c = v at every node, so V̄_i = v).
    Cloud c(1000);
    const Vec3f u(0.3f, -1.2f, 0.7f);
    for (Vec3f& v : c.v) v = u;
    HairGrid grid(frictionOnly(1e4f));
    grid.apply(c.input(), reversedFor);
    for (const Vec3f& v : c.v) EXPECT_LT((v - u).norm(), 1e-5f * u.norm());
}

TEST(HairGrid, MeasuresHairLengthPerVolume) {
    // A lattice of spacing a, each point carrying hair length ℓ: inside it
    // the density is ℓ/a³ whatever the grid's offset (trilinear weights of a
    // lattice aligned with the grid sum to one per node).
    const float a = 0.0025f, mass = 1e-6f, lengthPerMass = 2e4f;  // ℓ = 0.02 m per point
    std::vector<Vec3f> x, v;
    for (int i = 0; i < 24; ++i)
        for (int j = 0; j < 24; ++j)
            for (int k = 0; k < 24; ++k) x.push_back(a * Vec3f(float(i), float(j), float(k)));
    v.assign(x.size(), Vec3f::Zero());
    std::vector<float> m(x.size(), mass);
    GridInput in = gridInput(x, v, m, lengthPerMass, 0.01f);
    VolumeSettings s = frictionOnly(0.f);
    s.cellSize = 0.01f;
    HairGrid grid(s);
    const volume::GridStats st = grid.apply(in, reversedFor);
    const double expected = double(mass) * lengthPerMass / (double(a) * a * a) * 1e-4;  // hairs per cm²
    EXPECT_NEAR(st.maxDensity, expected, 1e-4 * expected);
}

TEST(HairGrid, MeasuresTheNodeTheWeightsFavour) {
    // N vertices at one point: the grid's lattice starts at the cell
    // holding it (origin ⌊p/Δ⌋·Δ), so its trilinear fractions are
    // t = p/Δ − ⌊p/Δ⌋ and the densest node is the corner of largest weight,
    // here (i + 1, j, k + 1) with w = tx·(1 − ty)·tz, holding N·m·w of
    // mass: density N·m·(ℓ/m)·w/Δ³. That corner lies at the far x end of
    // its row, where the grid stores one node beyond the vertices' cells.
    const float d = 0.01f, mass = 1e-6f, lengthPerMass = 2e4f;
    const Vec3f t(0.9f, 0.2f, 0.7f), p = d * (Vec3f(12.f, 5.f, 23.f) + t);
    const size_t n = 100;
    std::vector<Vec3f> x(n, p), v(n, Vec3f::Zero());
    std::vector<float> m(n, mass);
    GridInput in = gridInput(x, v, m, lengthPerMass, 0.01f);
    VolumeSettings s = frictionOnly(0.f);
    s.cellSize = d;
    HairGrid grid(s);
    const volume::GridStats st = grid.apply(in, reversedFor);
    const Eigen::Vector3d f = (p.cast<double>() / double(d)).array() - (p.cast<double>() / double(d)).array().floor();
    const double w = f.x() * (1.0 - f.y()) * f.z();
    const double expected = double(n) * mass * lengthPerMass * w / (double(d) * d * d) * 1e-4;  // hairs per cm²
    EXPECT_NEAR(st.maxDensity, expected, 1e-4 * expected);
}

TEST(HairGrid, VolumeStepSpreadsADenseBlobAndLeavesThinHairAlone) {
    Cloud c(3000);
    for (Vec3f& p : c.x) p *= 0.5f;  // a 3 cm blob
    for (Vec3f& v : c.v) v.setZero();
    VolumeSettings s;
    s.enabled = true;
    s.friction = 0.f;
    s.targetDensity = 50.f;
    auto spread = [&] {
        double r = 0;
        for (const Vec3f& p : c.x) r += p.squaredNorm();
        return std::sqrt(r / double(c.x.size()));
    };
    // Thin: the blob's density (3000 points of 1 cm of hair in 27 cm³, about
    // 110 per cm²) below a target of 1000 per cm²: nothing moves.
    s.targetDensity = 1000.f;
    {
        const std::vector<Vec3f> x0 = c.x;
        HairGrid grid(s);
        const volume::GridStats st = grid.apply(c.input(), reversedFor);
        EXPECT_LT(st.maxDensity, s.targetDensity);
        EXPECT_EQ(st.pushed, 0u);
        for (size_t i = 0; i < c.x.size(); ++i) EXPECT_EQ(c.x[i], x0[i]);
    }
    s.targetDensity = 10.f;
    HairGrid grid(s);
    const double r0 = spread();
    size_t outward = 0;
    const std::vector<Vec3f> x0 = c.x;
    const volume::GridStats st = grid.apply(c.input(), reversedFor);
    EXPECT_GT(st.maxDensity, 10.f * s.targetDensity);
    for (size_t i = 0; i < c.x.size(); ++i) outward += (c.x[i] - x0[i]).dot(x0[i]) > 0.f;
    EXPECT_GT(spread(), r0 * 1.01) << "the blob spreads";
    EXPECT_GT(outward, c.x.size() * 9 / 10) << "down the density gradient: outward";
    for (const Vec3f& v : c.v) EXPECT_EQ(v, Vec3f::Zero()) << "positions only";
}

TEST(HairGrid, SameBitsOnAnyThreadCountAndChunkOrder) {
    VolumeSettings s;
    s.enabled = true;
    s.targetDensity = 50.f;
    std::vector<Cloud> runs(4, Cloud(20000, 5));  // above the serial threshold: the parallel passes run
    const volume::ParallelFor fors[4] = {arenaFor(1, 1), arenaFor(2, 1), arenaFor(2, 64), reversedFor};
    Eigen::Isometry3f head = Eigen::Isometry3f::Identity();
    head.rotate(Eigen::AngleAxisf(0.7f, Vec3f(1, 2, 3).normalized()));
    head.translation() = Vec3f(0.01f, 0.2f, -0.03f);
    for (int r = 0; r < 4; ++r) {
        HairGrid grid(s);
        for (int step = 0; step < 3; ++step) {
            GridInput in = runs[r].input();
            in.head = head;
            grid.apply(in, fors[r]);
        }
    }
    for (int r = 1; r < 4; ++r) {
        EXPECT_EQ(0, std::memcmp(runs[r].x.data(), runs[0].x.data(), runs[0].x.size() * sizeof(Vec3f))) << r;
        EXPECT_EQ(0, std::memcmp(runs[r].v.data(), runs[0].v.data(), runs[0].v.size() * sizeof(Vec3f))) << r;
    }
}
