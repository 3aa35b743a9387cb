// The hair grid's implicit volume step (sim/volume/excess_diffusion.h):
// Jacobi sweeps of (I − c·L)·E = e against the analytic solution on the
// Dirichlet eigenmodes of a box, its stability for any c (where the
// explicit step diverges), the nodes without hair, and the same bits on any
// thread count.
#include "sim/volume/excess_diffusion.h"

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <random>

using namespace hp::volume;

namespace {

const ParallelFor serial = [](size_t count, const std::function<void(size_t, size_t)>& f) { f(0, count); };

/// A Dirichlet eigenmode of the 7-point Laplacian on the box (zero beyond
/// it): e(i, j, k) = Π sin(π·p_a·(i_a + 1)/(N_a + 1)), eigenvalue
/// μ = Σ_a (2·cos(π·p_a/(N_a + 1)) − 2), in units of Δ⁻².
struct Mode {
    NodeBox box;
    std::vector<float> e;
    double mu = 0;
    Mode(int n, int px, int py, int pz) {
        box.nx = box.ny = box.nz = n;
        const int p[3] = {px, py, pz};
        for (int a = 0; a < 3; ++a) mu += 2 * std::cos(M_PI * p[a] / (n + 1)) - 2;
        for (int k = 0; k < n; ++k)
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i)
                    e.push_back(float(std::sin(M_PI * px * (i + 1) / (n + 1)) * std::sin(M_PI * py * (j + 1) / (n + 1)) *
                                      std::sin(M_PI * pz * (k + 1) / (n + 1))));
    }
};

/// E^K / e on a mode after K sweeps from 0: the Neumann series' partial sum.
double partialSum(double mu, double c, int sweeps) {
    const double rho = c * (mu + 6) / (1 + 6 * c);
    double sum = 0, term = 1;
    for (int j = 0; j < sweeps; ++j, term *= rho) sum += term;
    return sum / (1 + 6 * c);
}

/// The largest |E_n − s·e_n| over the box.
double maxError(const std::vector<float>& E, const std::vector<float>& e, double s) {
    double worst = 0;
    for (size_t n = 0; n < e.size(); ++n) worst = std::max(worst, std::abs(double(E[n]) - s * e[n]));
    return worst;
}

/// A box of random excess: each node 0 with probability `zero`, else uniform
/// in [0, scale), and holding hair with probability `hair`.
struct RandomBox {
    NodeBox box;
    std::vector<float> e;
    std::vector<uint8_t> occupied;
    RandomBox(int nx, int ny, int nz, unsigned seed, float zero, float scale, float hair) {
        box.nx = nx;
        box.ny = ny;
        box.nz = nz;
        std::mt19937 rng(seed);
        std::uniform_real_distribution<float> u(0.f, 1.f);
        e.resize(box.size());
        occupied.resize(box.size());
        for (size_t n = 0; n < e.size(); ++n) {
            e[n] = u(rng) < zero ? 0.f : scale * u(rng);
            occupied[n] = u(rng) < hair;
        }
    }
};

}  // namespace

TEST(ExcessDiffusion, SweepsMatchTheNeumannSeriesOnEigenmodes) {
    // On an eigenmode every sweep scales the mode: E^K = e·partialSum(μ, c, K),
    // and many sweeps reach the backward-Euler solve e/(1 − c·μ).
    for (const auto& p : {std::array<int, 3>{1, 1, 1}, {3, 2, 5}, {8, 8, 8}, {8, 1, 8}}) {
        const Mode m(8, p[0], p[1], p[2]);
        const std::vector<uint8_t> occupied(m.box.size(), 1);
        std::vector<float> E(m.box.size());
        OccupiedNodes scratch;
        for (float c : {0.05f, 0.43f, 2.f})
            for (int sweeps : {1, 2, 3, 4, 8}) {
                relaxExcess(m.box, m.e.data(), occupied.data(), c, sweeps, E.data(), scratch, serial);
                EXPECT_LT(maxError(E, m.e, partialSum(m.mu, c, sweeps)), 2e-6)
                    << "mode " << p[0] << p[1] << p[2] << " c " << c << " sweeps " << sweeps;
            }
        relaxExcess(m.box, m.e.data(), occupied.data(), 0.43f, 200, E.data(), scratch, serial);
        EXPECT_LT(maxError(E, m.e, 1 / (1 - 0.43 * m.mu)), 2e-6) << "the implicit solve";
    }
}

TEST(ExcessDiffusion, TheStepNeverGrowsAModeWhereTheExplicitOneDoes) {
    // The step's new excess e + c·L·E on the grid-scale mode (μ near −12):
    // explicit (E = e) it is (1 + c·μ)·e, |1 + c·μ| > 1 for c > 1/6 and
    // growing; relaxed, never larger than e, for any c and sweep count.
    const Mode m(8, 8, 8, 8);
    ASSERT_LT(m.mu, -11.5);
    const std::vector<uint8_t> occupied(m.box.size(), 1);
    std::vector<float> E(m.box.size());
    OccupiedNodes scratch;
    for (float c : {0.1f, 0.25f, 0.5f, 2.f, 20.f}) {
        for (int sweeps = 1; sweeps <= 9; ++sweeps) {
            relaxExcess(m.box, m.e.data(), occupied.data(), c, sweeps, E.data(), scratch, serial);
            // L·E from E's own values (the 7-point stencil, zero beyond the box).
            double worst = 0;
            const int n = m.box.nx;
            auto at = [&](int i, int j, int k) {
                return (i < 0 || j < 0 || k < 0 || i >= n || j >= n || k >= n) ? 0.0 : double(E[size_t((k * n + j) * n + i)]);
            };
            for (int k = 0; k < n; ++k)
                for (int j = 0; j < n; ++j)
                    for (int i = 0; i < n; ++i) {
                        const double lap = at(i - 1, j, k) + at(i + 1, j, k) + at(i, j - 1, k) + at(i, j + 1, k) +
                                           at(i, j, k - 1) + at(i, j, k + 1) - 6 * at(i, j, k);
                        const double e = m.e[size_t((k * n + j) * n + i)];
                        if (std::abs(e) > 1e-3) worst = std::max(worst, std::abs((e + c * lap) / e));
                    }
            EXPECT_LE(worst, 1.0 + 1e-4) << "c " << c << " sweeps " << sweeps;
        }
        if (c > 1.f / 6.f) {
            EXPECT_GT(std::abs(1 + c * m.mu), 1.0) << "the explicit step grows this mode";
        }
    }
}

TEST(ExcessDiffusion, NodesWithoutHairHoldNoExcessAndBlockIt) {
    // A line of occupied nodes broken by an empty one: E is 0 there
    // (Dirichlet), and the excess of one side never reaches the other.
    NodeBox box;
    box.nx = 9;
    box.ny = box.nz = 1;
    std::vector<float> e(9, 0.f), E(9);
    OccupiedNodes scratch;
    std::vector<uint8_t> occupied(9, 1);
    e[1] = 5.f;
    occupied[4] = 0;
    e[4] = 7.f;  // ignored: no hair there
    relaxExcess(box, e.data(), occupied.data(), 0.5f, 12, E.data(), scratch, serial);
    EXPECT_EQ(E[4], 0.f);
    for (int i = 5; i < 9; ++i) EXPECT_EQ(E[size_t(i)], 0.f) << i;
    EXPECT_GT(E[3], 0.f) << "the excess spreads on its side";
    EXPECT_LT(E[1], e[1]);
}

TEST(ExcessDiffusion, SameBitsOnAnyThreadCountAndChunkOrder) {
    const RandomBox random(17, 13, 29, 5, 0.5f, 3.f, 0.8f);
    const NodeBox& box = random.box;
    const std::vector<float>& e = random.e;
    const std::vector<uint8_t>& occupied = random.occupied;
    const ParallelFor reversed = [](size_t count, const std::function<void(size_t, size_t)>& f) {
        for (size_t b = count; b > 0; --b) f(b - 1, b);
    };
    std::vector<float> ref(box.size());
    OccupiedNodes scratch;
    relaxExcess(box, e.data(), occupied.data(), 0.43f, 6, ref.data(), scratch, serial);
    for (int threads : {1, 2}) {
        tbb::task_arena arena(threads);
        const ParallelFor tbbFor = [&](size_t count, const std::function<void(size_t, size_t)>& f) {
            arena.execute([&] {
                tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 1),
                                  [&](const tbb::blocked_range<size_t>& r) { f(r.begin(), r.end()); });
            });
        };
        std::vector<float> E(box.size());
        relaxExcess(box, e.data(), occupied.data(), 0.43f, 6, E.data(), scratch, tbbFor);
        EXPECT_EQ(0, std::memcmp(E.data(), ref.data(), E.size() * sizeof(float))) << threads << " threads";
    }
    std::vector<float> E(box.size());
    relaxExcess(box, e.data(), occupied.data(), 0.43f, 6, E.data(), scratch, reversed);
    EXPECT_EQ(0, std::memcmp(E.data(), ref.data(), E.size() * sizeof(float))) << "reversed chunks";
}

TEST(ExcessDiffusion, ListedSweepsMatchWholeBoxSweeps) {
    // relaxExcess sweeps the occupied nodes from a list; the reference here
    // is jacobiSweep over the whole box, K times from E⁰ = 0: the same bits,
    // nodes without hair 0, on a box whose faces hold hair (the neighbours
    // outside count 0).
    const RandomBox random(11, 7, 9, 11, 0.4f, 2.f, 0.35f);
    const NodeBox& box = random.box;
    const std::vector<float>& e = random.e;
    const std::vector<uint8_t>& occupied = random.occupied;
    for (int sweeps : {1, 2, 3, 4, 7}) {
        std::vector<float> a(box.size(), 0.f), b(box.size());
        for (int s = 0; s < sweeps; ++s) {
            jacobiSweep(box, e.data(), occupied.data(), 0.43f, a.data(), b.data(), 0, box.nz);
            std::swap(a, b);
        }
        std::vector<float> E(box.size(), -1.f);
        OccupiedNodes scratch;
        relaxExcess(box, e.data(), occupied.data(), 0.43f, sweeps, E.data(), scratch, serial);
        EXPECT_EQ(0, std::memcmp(E.data(), a.data(), E.size() * sizeof(float))) << sweeps << " sweeps";
    }
}
