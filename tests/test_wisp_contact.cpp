// The wisp contact (sim/volume/wisp_contact.h): its kernel against the
// properties it promises (the wisp radius packs the hairs at the target,
// momentum kept pair by pair, roots never moved, approaching vertices kept
// a wisp diameter apart while start overlaps are held, a crossed pair sent
// back, the same bits on any thread count). The guide solver with it on:
// Volume.WispContactKeepsCrossingWispsApart in test_hair_volume.cpp.
#include "sim/volume/wisp_contact.h"

#include "volume_support.h"

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

using Vec3f = Eigen::Vector3f;
using namespace hp;
using namespace hp::test;

namespace {

/// Guides of `per` vertices, vertex 0 of each a root (mass 0), the rest
/// scattered in a 3 cm box; x0 a slightly shifted copy (the substep's start).
struct Wisps {
    std::vector<Vec3f> x, x0;
    std::vector<float> m;
    size_t per;
    Wisps(size_t guides, size_t perGuide, unsigned seed = 7) : per(perGuide) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<float> u(-1.f, 1.f);
        for (size_t g = 0; g < guides; ++g)
            for (size_t k = 0; k < per; ++k) {
                x.push_back(0.015f * Vec3f(u(rng), u(rng), u(rng)));
                x0.push_back(x.back() + 0.002f * Vec3f(u(rng), u(rng), u(rng)));
                m.push_back(k == 0 ? 0.f : 1e-6f * (1.25f + 0.75f * u(rng)));
            }
    }
    volume::ContactInput input(float d) {
        volume::ContactInput in;
        in.x = x.data();
        in.x0 = x0.data();
        in.mass = m.data();
        in.count = x.size();
        in.verticesPerGuide = per;
        in.distance = d;
        in.iterations = 8;
        return in;
    }
    /// Closest pair of vertices of different guides, one of them free
    /// (two roots never move).
    float closest() const {
        float best = INFINITY;
        for (size_t i = 0; i < x.size(); ++i)
            for (size_t j = i + 1; j < x.size(); ++j)
                if (i / per != j / per && (m[i] > 0.f || m[j] > 0.f)) best = std::min(best, (x[i] - x[j]).norm());
        return best;
    }
};

}  // namespace

TEST(WispContact, WispRadiusPacksTheHairsAtTheTarget) {
    // N hairs in a disc of radius r cross it at N/(πr²) per unit area.
    const float r = volume::wispRadius(100.f, 223.f);
    EXPECT_NEAR(100.0 / (M_PI * double(r) * r) * 1e-4, 223.0, 1e-3);
}

TEST(WispContact, PairsKeepMomentumAndRootsStay) {
    Wisps w(60, 6);
    const std::vector<Vec3f> before = w.x;
    volume::WispContact contact;
    const size_t touching = contact.apply(w.input(0.004f), reversedFor);
    EXPECT_GT(touching, 100u);
    double moved = 0;
    for (size_t i = 0; i < w.x.size(); ++i) {
        const Eigen::Vector3d dx = (w.x[i] - before[i]).cast<double>();
        moved += double(w.m[i]) * dx.norm();
        if (w.m[i] == 0.f) {
            EXPECT_EQ(w.x[i], before[i]) << "a root is kinematic";
        }
    }
    // Roots take no share; a pair with a root moves the free vertex alone,
    // so only free-free pairs are counted: measure them without roots.
    Wisps free(60, 6);
    for (float& m : free.m) m = std::max(m, 1e-6f);
    const std::vector<Vec3f> fb = free.x;
    volume::WispContact c2;
    c2.apply(free.input(0.004f), reversedFor);
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    double scale = 0;
    for (size_t i = 0; i < free.x.size(); ++i) {
        p += double(free.m[i]) * (free.x[i] - fb[i]).cast<double>();
        scale += double(free.m[i]) * (free.x[i] - fb[i]).cast<double>().norm();
    }
    EXPECT_GT(moved, 0.0);
    EXPECT_LT(p.norm(), 1e-5 * scale) << "Σ m Δx = 0: every pair keeps momentum";
}

TEST(WispContact, SeparatesApproachingPairsAndHoldsStartOverlaps) {
    const float d = 0.004f;
    {
        // Coming together from ten times further apart: pushed back to d.
        Wisps w(40, 5);
        EXPECT_LT(w.closest(), 0.3f * d);
        for (size_t i = 0; i < w.x.size(); ++i) w.x0[i] = 10.f * w.x[i];
        volume::WispContact contact;
        volume::ContactInput in = w.input(d);
        in.iterations = 60;
        contact.apply(in, reversedFor);
        EXPECT_GT(w.closest(), 0.9f * d);
    }
    {
        // Already that close at the start: held, not thrown apart.
        Wisps w(40, 5);
        w.x0 = w.x;
        const std::vector<Vec3f> before = w.x;
        volume::WispContact contact;
        contact.apply(w.input(d), reversedFor);
        for (size_t i = 0; i < w.x.size(); ++i) EXPECT_EQ(w.x[i], before[i]);
    }
}

TEST(WispContact, ACrossedPairGoesBackToItsSide) {
    // Vertex 1 (guide 0) passed vertex 3 (guide 1) along x within the substep.
    std::vector<Vec3f> x0 = {{0, 1, 0}, {-0.003f, 0, 0}, {0, 1, 1}, {0, 0, 0}};
    std::vector<Vec3f> x = {{0, 1, 0}, {0.001f, 0, 0}, {0, 1, 1}, {0, 0, 0}};
    std::vector<float> m = {0.f, 1e-6f, 0.f, 1e-6f};
    volume::ContactInput in;
    in.x = x.data();
    in.x0 = x0.data();
    in.mass = m.data();
    in.count = 4;
    in.verticesPerGuide = 2;
    in.distance = 0.004f;
    in.iterations = 30;
    volume::WispContact contact;
    contact.apply(in, reversedFor);
    EXPECT_LT(x[1].x(), x[3].x() - 0.0029f) << x[1].transpose() << " / " << x[3].transpose();
}

TEST(WispContact, SameBitsOnAnyThreadCountAndChunkOrder) {
    std::vector<Wisps> runs(4, Wisps(2000, 6, 9));  // 12,000 vertices: the parallel passes run
    const volume::ParallelFor fors[4] = {arenaFor(1, 1), arenaFor(2, 1), arenaFor(2, 64), reversedFor};
    for (int r = 0; r < 4; ++r) {
        volume::WispContact contact;
        contact.apply(runs[r].input(0.002f), fors[r]);
    }
    for (int r = 1; r < 4; ++r)
        EXPECT_EQ(0, std::memcmp(runs[r].x.data(), runs[0].x.data(), runs[0].x.size() * sizeof(Vec3f))) << r;
}

