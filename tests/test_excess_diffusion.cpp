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
#include <limits>
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
        for (float c : {0.05f, 0.43f, 2.f})
            for (int sweeps : {1, 2, 3, 4, 8}) {
                relaxExcess(m.box, m.e.data(), occupied.data(), c, sweeps, E.data(), serial);
                EXPECT_LT(maxError(E, m.e, partialSum(m.mu, c, sweeps)), 2e-6)
                    << "mode " << p[0] << p[1] << p[2] << " c " << c << " sweeps " << sweeps;
            }
        relaxExcess(m.box, m.e.data(), occupied.data(), 0.43f, 200, E.data(), serial);
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
    for (float c : {0.1f, 0.25f, 0.5f, 2.f, 20.f}) {
        for (int sweeps = 1; sweeps <= 9; ++sweeps) {
            relaxExcess(m.box, m.e.data(), occupied.data(), c, sweeps, E.data(), serial);
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
    std::vector<uint8_t> occupied(9, 1);
    e[1] = 5.f;
    occupied[4] = 0;
    e[4] = 7.f;  // ignored: no hair there
    relaxExcess(box, e.data(), occupied.data(), 0.5f, 12, E.data(), serial);
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
    relaxExcess(box, e.data(), occupied.data(), 0.43f, 6, ref.data(), serial);
    for (int threads : {1, 2}) {
        tbb::task_arena arena(threads);
        const ParallelFor tbbFor = [&](size_t count, const std::function<void(size_t, size_t)>& f) {
            arena.execute([&] {
                tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 1),
                                  [&](const tbb::blocked_range<size_t>& r) { f(r.begin(), r.end()); });
            });
        };
        std::vector<float> E(box.size());
        relaxExcess(box, e.data(), occupied.data(), 0.43f, 6, E.data(), tbbFor);
        EXPECT_EQ(0, std::memcmp(E.data(), ref.data(), E.size() * sizeof(float))) << threads << " threads";
    }
    std::vector<float> E(box.size());
    relaxExcess(box, e.data(), occupied.data(), 0.43f, 6, E.data(), reversed);
    EXPECT_EQ(0, std::memcmp(E.data(), ref.data(), E.size() * sizeof(float))) << "reversed chunks";
}

TEST(ExcessDiffusion, StoredRowSweepsMatchWholeBoxSweeps) {
    // relaxExcess sweeps the box's rows stored whole; the reference here
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
        relaxExcess(box, e.data(), occupied.data(), 0.43f, sweeps, E.data(), serial);
        EXPECT_EQ(0, std::memcmp(E.data(), a.data(), E.size() * sizeof(float))) << sweeps << " sweeps";
    }
}

TEST(ExcessDiffusion, RaggedRowsMatchWholeBoxSweeps) {
    // The hair grid's layout: each row stores its own x span (some rows
    // none) between two zero slots, and the excess lies on a few planes
    // only, so the sweeps run on the planes it reaches and each row reads
    // its neighbour rows partly from slots, partly as 0 (the four-at-a-time
    // middle and the node-by-node ends). Against jacobiSweep on the whole
    // box whose nodes with hair are the stored ones with hair: the same
    // bits on every stored node, on any thread count.
    const int nx = 23, ny = 9, nz = 12;
    const NodeBox box{nx, ny, nz};
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    const size_t rowCount = size_t(ny) * size_t(nz);
    std::vector<ptrdiff_t> base(rowCount);
    std::vector<int> lo(rowCount), end(rowCount);
    std::vector<uint32_t> planeStart(size_t(nz) + 1);
    std::vector<float> e(box.size(), 0.f);
    std::vector<uint8_t> occupied(box.size(), 0);
    size_t slots = 0;
    for (size_t r = 0; r < rowCount; ++r) {
        if (r % size_t(ny) == 0) planeStart[r / size_t(ny)] = uint32_t(slots);
        lo[r] = int(u(rng) * 8);
        end[r] = u(rng) < 0.15f ? lo[r] : std::min(nx, lo[r] + 1 + int(u(rng) * 18));
        if (lo[r] >= end[r]) {
            base[r] = 0;
            continue;
        }
        base[r] = ptrdiff_t(slots) + 1 - lo[r];
        slots += size_t(end[r] - lo[r]) + 2;
        const int k = int(r / size_t(ny));
        for (int i = lo[r]; i < end[r]; ++i) {
            const size_t n = r * size_t(nx) + size_t(i);
            occupied[n] = u(rng) < 0.8f;
            if (occupied[n] && k >= 5 && k < 8 && u(rng) < 0.6f) e[n] = 3.f * u(rng);  // excess on planes 5–7
        }
    }
    planeStart[size_t(nz)] = uint32_t(slots);
    NodeRows rows;
    rows.nx = nx;
    rows.ny = ny;
    rows.nz = nz;
    rows.base = base.data();
    rows.lo = lo.data();
    rows.end = end.data();
    rows.planeStart = planeStart.data();
    const float c = 0.43f, inv = 1.f / (1.f + 6.f * c);
    std::vector<float> ex(slots, std::numeric_limits<float>::quiet_NaN());
    for (size_t r = 0; r < rowCount; ++r)
        for (int i = lo[r]; i < end[r]; ++i)
            if (occupied[r * size_t(nx) + size_t(i)]) ex[size_t(base[r] + i)] = e[r * size_t(nx) + size_t(i)];
    const ParallelFor reversed = [](size_t count, const std::function<void(size_t, size_t)>& f) {
        for (size_t b = count; b > 0; --b) f(b - 1, b);
    };
    size_t excessNodes = 0;
    for (int sweeps : {1, 2, 3, 4, 6}) {
        std::vector<float> ref(box.size(), 0.f), next(box.size());
        for (int s = 0; s < sweeps; ++s) {
            jacobiSweep(box, e.data(), occupied.data(), c, ref.data(), next.data(), 0, nz);
            std::swap(ref, next);
        }
        for (const ParallelFor* parallel : {&serial, &reversed}) {
            std::vector<float> a(slots), b(slots, -7.f);  // b's stale values must not leak in
            for (size_t q = 0; q < slots; ++q) a[q] = firstSweep(ex[q], inv);
            const float* E = relaxRows(rows, ex.data(), c, sweeps, 5, 8, a.data(), b.data(), *parallel);
            size_t nonzero = 0;
            for (size_t r = 0; r < rowCount; ++r) {
                if (lo[r] >= end[r]) continue;
                EXPECT_EQ(E[size_t(base[r] + lo[r] - 1)], 0.f) << "zero slot, row " << r;
                EXPECT_EQ(E[size_t(base[r] + end[r])], 0.f) << "zero slot, row " << r;
                for (int i = lo[r]; i < end[r]; ++i) {
                    const float want = ref[r * size_t(nx) + size_t(i)], got = E[size_t(base[r] + i)];
                    nonzero += want != 0.f;
                    EXPECT_EQ(0, std::memcmp(&want, &got, sizeof(float)))
                        << sweeps << " sweeps, row " << r << ", i " << i << ": " << got << " against " << want;
                }
            }
            if (sweeps == 1) {
                EXPECT_GT(nonzero, 50u) << "nodes with excess";
                excessNodes = nonzero;
            } else {
                EXPECT_GT(nonzero, excessNodes) << "the excess spread beyond its nodes, " << sweeps << " sweeps";
            }
        }
    }
}
