// Voxelizer and DensityGrid: volume conservation, analytic profiles of a
// straight strand, ray integrals, affine (light-space) grids, velocity,
// thread-count invariance and error messages.
#include "core/errors.h"
#include "render/volume/voxelizer.h"
#include "sim/strands/synthetic.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <random>

using namespace hp;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// `count` random strands in a 4 cm box around `centre`: random walks of
/// 2..30 vertices with steps from 0 to 6 mm (some shorter than a voxel, some
/// crossing several, a few of zero length), radii tapering from 20-80 µm.
StrandFrame randomStrands(size_t count, unsigned seed, const Vec3f& centre = Vec3f(0.01f, -0.02f, 0.005f)) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(-1.f, 1.f), u01(0.f, 1.f);
    StrandFrame frame;
    for (size_t s = 0; s < count; ++s) {
        const int n = 2 + int(u01(rng) * 28.f);
        std::vector<Vec3f> p(static_cast<size_t>(n)), v(static_cast<size_t>(n));
        std::vector<float> r(static_cast<size_t>(n));
        p[0] = centre + 0.02f * Vec3f(unit(rng), unit(rng), unit(rng));
        const float root = 20e-6f + 60e-6f * u01(rng), tip = root * u01(rng);
        for (int k = 0; k < n; ++k) {
            if (k > 0) {
                const float step = u01(rng) < 0.05f ? 0.f : 0.006f * u01(rng);
                p[size_t(k)] = p[size_t(k - 1)] + step * Vec3f(unit(rng), unit(rng), unit(rng)).normalized();
            }
            r[size_t(k)] = taperedRadius(root, tip, float(k) / float(n - 1));
            v[size_t(k)] = Vec3f(unit(rng), unit(rng), unit(rng));
        }
        frame.addStrand(uint32_t(s), p.data(), r.data(), size_t(n), v.data());
    }
    return frame;
}

/// One straight strand from `a` to `b` with `n` vertices and radius r0 → r1.
StrandFrame straightStrand(const Vec3f& a, const Vec3f& b, int n, float r0, float r1,
                           const Vec3f& velocity = Vec3f::Zero()) {
    std::vector<Vec3f> p(static_cast<size_t>(n)), v(size_t(n), velocity);
    std::vector<float> r(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k) {
        const float t = float(k) / float(n - 1);
        p[size_t(k)] = a + t * (b - a);
        r[size_t(k)] = taperedRadius(r0, r1, t);
    }
    StrandFrame frame;
    frame.addStrand(0, p.data(), r.data(), size_t(n), v.data());
    return frame;
}

/// A light-space grid: index z along `direction`, voxel edge h, rotated
/// arbitrarily about it, origin off the lattice.
GridTransform lightGrid(const Vec3d& direction, double h) {
    const Vec3d z = direction.normalized();
    const Vec3d x = z.unitOrthogonal();
    const Vec3d y = z.cross(x);
    Eigen::Matrix3d axes;
    axes.col(0) = x * h;
    axes.col(1) = y * h;
    axes.col(2) = z * h;
    return GridTransform::fromAxes(axes, Vec3d(0.0013, -0.0021, 0.0007));
}

bool identical(const DensityGrid& a, const DensityGrid& b) {
    if (a.blockCount() != b.blockCount() || a.hasVelocity() != b.hasVelocity()) return false;
    for (size_t i = 0; i < a.blockCount(); ++i) {
        if (a.blockOrigin(i) != b.blockOrigin(i)) return false;
        if (std::memcmp(a.blockDensity(i), b.blockDensity(i), sizeof(float) * DensityGrid::kBlockVoxels)) return false;
        if (a.hasVelocity() &&
            std::memcmp(a.blockVelocity(i), b.blockVelocity(i), sizeof(Vec3f) * DensityGrid::kBlockVoxels))
            return false;
    }
    return true;
}

}  // namespace

TEST(Voxelizer, ConservesHairVolumeForRandomStrands) {
    const StrandFrame strands = randomStrands(400, 7);
    const double volume = hairVolume(strands);
    ASSERT_GT(volume, 0);
    const GridTransform grids[] = {GridTransform::uniform(0.001), GridTransform::uniform(0.00037),
                                   lightGrid(Vec3d(-1, -1, -1), 0.0008)};
    for (const GridTransform& t : grids)
        for (VoxelFilter f : {VoxelFilter::Trilinear, VoxelFilter::Box}) {
            VoxelizeSettings s;
            s.filter = f;
            const DensityGrid grid = voxelize(strands, t, s);
            const double error = std::abs(grid.totalVolume() - volume) / volume;
            EXPECT_LT(error, 1e-6) << "filter " << int(f) << ", voxel volume " << t.voxelVolume();
            EXPECT_GT(grid.activeVoxelCount(), 1000u);
        }
}

TEST(Voxelizer, ConservesHairVolumeWithVoxelsMuchSmallerThanSegments) {
    // Segments up to 100 voxels long are split into parts internally; the
    // parts must still add up to the whole tapered segments.
    const StrandFrame strands = randomStrands(12, 19);
    const double volume = hairVolume(strands);
    for (VoxelFilter f : {VoxelFilter::Trilinear, VoxelFilter::Box}) {
        VoxelizeSettings s;
        s.filter = f;
        const DensityGrid grid = voxelize(strands, GridTransform::uniform(0.00006), s);
        EXPECT_LT(std::abs(grid.totalVolume() - volume) / volume, 1e-6) << "filter " << int(f);
    }
}

TEST(Voxelizer, HairVolumeIsTheSumOfTruncatedCones) {
    // A 4 cm strand tapering 50 → 10 µm: π L (r0² + r0 r1 + r1²) / 3.
    const StrandFrame s = straightStrand(Vec3f(0, 0, 0), Vec3f(0, 0.04f, 0), 9, 50e-6f, 10e-6f);
    const double r0 = 50e-6, r1 = 10e-6;
    EXPECT_NEAR(hairVolume(s), kPi * 0.04 * (r0 * r0 + r0 * r1 + r1 * r1) / 3, 1e-15);
}

TEST(Voxelizer, StraightStrandCrossSectionTrilinear) {
    // A strand along z through (0.3 h, -0.2 h): every interior slice holds the
    // tent weights (0.7, 0.3) × (0.8, 0.2) of π r² / h², and nothing else.
    const double h = 0.001, r = 40e-6;
    const StrandFrame s = straightStrand(Vec3f(0.3f * 0.001f, -0.2f * 0.001f, -0.0102f),
                                         Vec3f(0.3f * 0.001f, -0.2f * 0.001f, 0.0102f), 5, float(r), float(r));
    const DensityGrid grid = voxelize(s, GridTransform::uniform(h));
    const double full = kPi * r * r / (h * h);
    const double wx[2] = {0.7, 0.3}, wy[2] = {0.2, 0.8};  // x voxels 0, 1; y voxels -1, 0
    for (int k = -8; k <= 8; ++k) {
        double slice = 0;
        for (int i = -2; i <= 3; ++i)
            for (int j = -3; j <= 2; ++j) {
                const double d = grid.density(Vec3i(i, j, k));
                slice += d;
                const bool inside = (i == 0 || i == 1) && (j == -1 || j == 0);
                const double expected = inside ? full * wx[i] * wy[j + 1] : 0.0;
                EXPECT_NEAR(d, expected, 2e-4 * full) << "voxel " << i << " " << j << " " << k;
            }
        EXPECT_NEAR(slice * h * h, kPi * r * r, 1e-6 * kPi * r * r) << "slice " << k;
    }
}

TEST(Voxelizer, StraightStrandCrossSectionBoxAndTaper) {
    // Box filter: the strand's voxel column holds (π/h³) ∫ r(z)² dz over each
    // voxel's z extent, with r tapering linearly along z.
    const double h = 0.0005, r0 = 60e-6, r1 = 20e-6, z0 = -0.00401, z1 = 0.00399;
    const StrandFrame s = straightStrand(Vec3f(0.00011f, 0.00004f, float(z0)), Vec3f(0.00011f, 0.00004f, float(z1)),
                                         7, float(r0), float(r1));
    VoxelizeSettings box;
    box.filter = VoxelFilter::Box;
    const DensityGrid grid = voxelize(s, GridTransform::uniform(h), box);
    auto radiusAt = [&](double z) { return r0 + (r1 - r0) * (z - z0) / (z1 - z0); };
    auto integralR2 = [&](double a, double b) {  // exact ∫ r² dz of a linear r
        const double ra = radiusAt(a), rb = radiusAt(b);
        return (b - a) * (ra * ra + ra * rb + rb * rb) / 3.0;
    };
    size_t active = 0;
    for (int k = -9; k <= 9; ++k) {
        const double lo = std::max(z0, (k - 0.5) * h), hi = std::min(z1, (k + 0.5) * h);
        const double expected = hi > lo ? kPi * integralR2(lo, hi) / (h * h * h) : 0.0;
        EXPECT_NEAR(grid.density(Vec3i(0, 0, k)), expected, 1e-6 * kPi * r0 * r0 / (h * h)) << "voxel " << k;
        EXPECT_EQ(grid.density(Vec3i(1, 0, k)), 0.f);
        EXPECT_EQ(grid.density(Vec3i(0, 1, k)), 0.f);
        if (expected > 0) ++active;
    }
    EXPECT_EQ(grid.activeVoxelCount(), active);
}

TEST(Voxelizer, DiagonalStrandAcrossTilesMatchesTheTentKernelIntegral) {
    // A straight strand of constant radius, 90 voxels long on a diagonal, so
    // it crosses several of the voxelizer's 32³ tiles (each tile walks only
    // its own part of the segment) in every direction of travel. Reference:
    // density(v) = π r² L / V · ∫₀¹ Π_a max(0, 1 − |p_a(t) − v_a|) dt (p in
    // voxel units), by the midpoint rule on 400 000 samples.
    const double h = 0.001, r = 30e-6;
    const Vec3d ends[][2] = {{Vec3d(-40.3, -3.7, 5.2), Vec3d(45.1, 30.6, -20.9)},
                             {Vec3d(31.9, 60.2, -7.4), Vec3d(-33.6, 2.5, 40.7)}};
    for (const auto& e : ends) {
        const StrandFrame s = straightStrand((e[0] * h).cast<float>(), (e[1] * h).cast<float>(), 2, float(r), float(r));
        const DensityGrid grid = voxelize(s, GridTransform::uniform(h));
        const Vec3d a = s.positions[0].cast<double>() / h, d = s.positions[1].cast<double>() / h - a;
        const double scale = kPi * r * r * (d.norm() * h) / (h * h * h);
        std::map<std::array<int, 3>, double> reference;
        const int samples = 400000;
        for (int i = 0; i < samples; ++i) {
            const Vec3d p = a + d * ((i + 0.5) / samples);
            const Vec3i c(int(std::floor(p.x())), int(std::floor(p.y())), int(std::floor(p.z())));
            for (int corner = 0; corner < 8; ++corner) {
                const Vec3i v = c + Vec3i(corner >> 2, (corner >> 1) & 1, corner & 1);
                double w = scale / samples;
                for (int k = 0; k < 3; ++k) w *= std::max(0.0, 1.0 - std::abs(p[k] - v[k]));
                reference[{v.x(), v.y(), v.z()}] += w;
            }
        }
        double peak = 0;
        for (const auto& [v, value] : reference) peak = std::max(peak, value);
        size_t compared = 0;
        for (const auto& [v, value] : reference) {
            EXPECT_NEAR(grid.density(Vec3i(v[0], v[1], v[2])), value, 2e-4 * peak) << v[0] << " " << v[1] << " " << v[2];
            ++compared;
        }
        EXPECT_GT(compared, 500u);
        // Nothing outside the voxels the line reaches.
        size_t active = 0;
        for (const auto& [v, value] : reference) active += grid.density(Vec3i(v[0], v[1], v[2])) > 0;
        EXPECT_EQ(grid.activeVoxelCount(), active);
    }
}

/// Coefficients of a polynomial in t, lowest first.
using Poly = std::vector<long double>;
Poly times(const Poly& p, const Poly& q) {
    Poly r(p.size() + q.size() - 1, 0.0L);
    for (size_t i = 0; i < p.size(); ++i)
        for (size_t j = 0; j < q.size(); ++j) r[i + j] += p[i] * q[j];
    return r;
}
long double integral(const Poly& p, long double a, long double b) {
    long double sum = 0;
    for (size_t n = 0; n < p.size(); ++n) sum += p[n] * (std::pow(b, n + 1) - std::pow(a, n + 1)) / (n + 1);
    return sum;
}

TEST(Voxelizer, TaperedSegmentMatchesTheExactPolynomialIntegral) {
    // A short segment whose radius falls from 80 to 4 µm (r² changes 400×
    // along it), so the integrand of each voxel, r(t)² times three tent
    // weights, is a polynomial of degree 5 between the planes where the
    // segment crosses a voxel centre plane; a 2-point rule (exact to degree 3)
    // misses its r² curvature. Reference: those polynomials expanded and
    // integrated exactly, piece by piece (long double), for every voxel the
    // segment reaches: density(v) = π L / V · ∫₀¹ r(t)² Π_a max(0, 1 − |p_a(t) − v_a|) dt.
    // The second segment crosses the voxelizer's tile planes (x, y = 32, z = 0).
    const double h = 0.001;
    const Vec3d ends[][2] = {{Vec3d(0.3, -1.2, 2.7), Vec3d(2.9, 0.4, 0.6)},
                             {Vec3d(30.6, 31.2, -1.4), Vec3d(33.3, 32.9, 1.2)}};
    // Both deposit kernels (AVX2 where the CPU has it, the SSE2 reference).
    for (const VoxelKernel kernel : {VoxelKernel::Auto, VoxelKernel::Sse2})
    for (const auto& e : ends) {
        SCOPED_TRACE(kernel == VoxelKernel::Auto ? "kernel auto" : "kernel sse2");
        VoxelizeSettings settings;
        settings.kernel = kernel;
        const StrandFrame s = straightStrand((e[0] * h).cast<float>(), (e[1] * h).cast<float>(), 2, 80e-6f, 4e-6f);
        const DensityGrid grid = voxelize(s, GridTransform::uniform(h), settings);
        const Vec3d a = s.positions[0].cast<double>() / h, d = s.positions[1].cast<double>() / h - a;
        const long double r0 = s.radii[0], dr = (long double)s.radii[1] - r0;
        const long double scale = (long double)kPi * (d.norm() * h) / (h * h * h);
        // Pieces: [0, 1] cut where a coordinate crosses an integer.
        std::vector<long double> cuts = {0.0L, 1.0L};
        for (int k = 0; k < 3; ++k)
            for (int c = int(std::floor(std::min(a[k], a[k] + d[k]))); c <= int(std::ceil(std::max(a[k], a[k] + d[k]))); ++c) {
                const long double t = ((long double)c - a[k]) / d[k];
                if (t > 0 && t < 1) cuts.push_back(t);
            }
        std::sort(cuts.begin(), cuts.end());
        const Poly r2 = times(Poly{r0, dr}, Poly{r0, dr});
        std::map<std::array<int, 3>, long double> reference;
        for (size_t i = 0; i + 1 < cuts.size(); ++i) {
            const long double t0 = cuts[i], t1 = cuts[i + 1], tm = 0.5L * (t0 + t1);
            if (!(t1 > t0)) continue;
            int lo[3];
            for (int k = 0; k < 3; ++k) lo[k] = int(std::floor(a[k] + d[k] * tm));
            for (int corner = 0; corner < 8; ++corner) {
                const int v[3] = {lo[0] + (corner >> 2), lo[1] + ((corner >> 1) & 1), lo[2] + (corner & 1)};
                Poly p = r2;
                for (int k = 0; k < 3; ++k) {
                    // Tent weight, linear on the piece: 1 − |a + d t − v| with the sign at the midpoint.
                    const long double sign = a[k] + d[k] * tm >= v[k] ? -1.0L : 1.0L;
                    p = times(p, Poly{1.0L + sign * ((long double)a[k] - v[k]), sign * (long double)d[k]});
                }
                reference[{v[0], v[1], v[2]}] += scale * integral(p, t0, t1);
            }
        }
        long double peak = 0;
        for (const auto& [v, value] : reference) peak = std::max(peak, value);
        for (const auto& [v, value] : reference)
            EXPECT_NEAR(grid.density(Vec3i(v[0], v[1], v[2])), double(value), 1e-6 * double(peak))
                << v[0] << " " << v[1] << " " << v[2];
        size_t active = 0;
        for (const auto& [v, value] : reference) active += value > 0;
        EXPECT_EQ(grid.activeVoxelCount(), active);
        EXPECT_GT(active, 20u);
    }
}

TEST(Voxelizer, ConservesHairVolumeOfAHeadOfHairToFloatRounding) {
    // 20,000 synthetic strands at 1 mm: 6.5M voxels, most of them filled
    // by several tiles' walks (the padded tile borders). Each voxel's sum
    // is formed in double and stored as a float; that rounding (unbiased,
    // ~2.4e-8 of a value rms) leaves a relative mass error of ~1e-11 rms
    // over 6.5M voxels of uneven values (7.5e-12 measured), far below the
    // bound of 1e-10. A voxel lost or counted twice at a tile border, or a
    // deposit left in the buffer for the next tile, is ≥ 1e-6.
    SyntheticHairSettings hs;
    hs.strands = 20000;
    const StrandFrame hair = makeSyntheticHair(hs);
    const double volume = hairVolume(hair);
    const DensityGrid grid = voxelize(hair, GridTransform::uniform(0.001));
    EXPECT_GT(grid.activeVoxelCount(), 5000000u);
    EXPECT_LT(std::abs(grid.totalVolume() - volume) / volume, 1e-10);
}

TEST(Voxelizer, ActiveBoundsContainEveryVertex) {
    SyntheticHairSettings hs;
    hs.strands = 300;
    const StrandFrame hair = makeSyntheticHair(hs);
    const double h = 0.002;
    for (VoxelFilter f : {VoxelFilter::Trilinear, VoxelFilter::Box}) {
        VoxelizeSettings s;
        s.filter = f;
        const DensityGrid grid = voxelize(hair, GridTransform::uniform(h), s);
        Vec3i lo, hi;
        ASSERT_TRUE(grid.activeBounds(&lo, &hi));
        for (const Vec3f& p : hair.positions) {
            const Vec3d i = p.cast<double>() / h;  // voxel (i) covers [i - ½, i + ½)
            for (int a = 0; a < 3; ++a) {
                EXPECT_GE(i[a], lo[a] - 0.5) << "vertex " << p.transpose();
                EXPECT_LT(i[a], hi[a] + 0.5) << "vertex " << p.transpose();
            }
            // And the vertex's own voxel holds hair.
            EXPECT_GT(grid.sample(p, Reconstruction::Nearest), 0.f) << "vertex " << p.transpose();
        }
    }
}

TEST(Voxelizer, IdenticalForOneAndTwoThreads) {
    StrandFrame strands = randomStrands(1500, 11);
    for (bool velocity : {false, true}) {
        VoxelizeSettings s;
        s.velocity = velocity;
        DensityGrid one, two;
        tbb::task_arena(1).execute([&] { one = voxelize(strands, GridTransform::uniform(0.0005), s); });
        tbb::task_arena(2).execute([&] { two = voxelize(strands, GridTransform::uniform(0.0005), s); });
        EXPECT_GT(one.blockCount(), 50u);
        EXPECT_TRUE(identical(one, two)) << "velocity " << velocity;
    }
}

TEST(Voxelizer, Avx2KernelGivesTheReferenceGridBitForBit) {
    // The AVX2 deposit (four pieces in the lanes of a vector) performs the
    // SSE2 reference's operations in its order, without FMA, and adds the
    // corners in piece order: the grids must be equal bit for bit (tolerance
    // 0), on random strands (pieces of every length, segments crossing tile
    // planes, zero-length and tapering ones) at 0.5 mm and on synthetic hair
    // at 1 mm, on 1 and 2 threads. A lane mixed up, a piece dropped or
    // deposited twice, or a fused multiply-add changes some voxels.
    VoxelizeSettings reference;
    reference.kernel = VoxelKernel::Sse2;
    const bool avx2 = avx2KernelAvailable();
    if (!avx2) GTEST_SKIP() << "this CPU has no AVX2: only the reference kernel runs";
    SyntheticHairSettings hs;
    hs.strands = 3000;
    const std::pair<StrandFrame, double> cases[] = {{randomStrands(1500, 23), 0.0005},
                                                    {makeSyntheticHair(hs), 0.001}};
    for (const auto& [strands, h] : cases) {
        const DensityGrid expected = voxelize(strands, GridTransform::uniform(h), reference);
        EXPECT_GT(expected.activeVoxelCount(), 10000u);
        for (int threads : {1, 2}) {
            DensityGrid wide;
            tbb::task_arena(threads).execute([&] { wide = voxelize(strands, GridTransform::uniform(h)); });
            EXPECT_TRUE(identical(wide, expected)) << "voxel " << h << " m, " << threads << " threads";
        }
    }
}

TEST(Voxelizer, FarApartClumpsGiveEachClumpsOwnGrid) {
    // Two clumps 12 m apart at 1 mm: the box of tiles they reach (375³)
    // exceeds the dense tile table's 2^22 slots, so binning takes its hash
    // map path. Each voxel only receives its own clump's segments, in the
    // same order, so the grid must hold each clump's grid alone, bit for bit:
    // a tile's segments binned out of order, lost or put in another tile
    // changes voxels. The clumps alone fit the dense table.
    const StrandFrame a = randomStrands(300, 5, Vec3f(0.01f, 0.02f, -0.03f));
    const StrandFrame b = randomStrands(300, 6, Vec3f(12.f, -12.f, 12.f));
    StrandFrame both = a;
    for (size_t s = 0; s < b.strandCount(); ++s)
        both.addStrand(uint32_t(a.strandCount() + s), &b.positions[b.first(s)], &b.radii[b.first(s)], b.vertexCount(s),
                       &b.velocities[b.first(s)]);
    const GridTransform grid = GridTransform::uniform(0.001);
    const DensityGrid together = voxelize(both, grid), alone[2] = {voxelize(a, grid), voxelize(b, grid)};
    ASSERT_EQ(together.blockCount(), alone[0].blockCount() + alone[1].blockCount());
    size_t checked = 0;
    for (const DensityGrid& g : alone)
        for (size_t i = 0; i < g.blockCount(); ++i)
            for (int v = 0; v < DensityGrid::kBlockVoxels; ++v) {
                const Vec3i voxel = g.blockOrigin(i) + Vec3i(v >> 6, (v >> 3) & 7, v & 7);
                ASSERT_EQ(together.density(voxel), g.density(voxel)) << voxel.transpose();
                checked += g.density(voxel) > 0;
            }
    EXPECT_GT(checked, 10000u);
}

TEST(Voxelizer, EmptyFrameGivesEmptyGrid) {
    const DensityGrid grid = voxelize(StrandFrame(), GridTransform::uniform(0.001));
    EXPECT_EQ(grid.blockCount(), 0u);
    EXPECT_EQ(grid.totalVolume(), 0.0);
    Vec3i lo, hi;
    EXPECT_FALSE(grid.activeBounds(&lo, &hi));
    EXPECT_EQ(grid.integrate(Vec3f(-1, 0, 0), Vec3f(1, 0, 0)), 0.0);
}

TEST(DensityGrid, RayIntegralsAcrossAStrandRecoverItsCrossSection) {
    // Rays along x through every voxel-centre row y = j h of a slice cut
    // through a strand along z: Σ_j (∫ density dx) · h = π r², for both
    // reconstructions; transmittance is exp(-σ ∫).
    const double h = 0.001, r = 50e-6;
    const StrandFrame s = straightStrand(Vec3f(0.00037f, 0.00021f, -0.01f), Vec3f(0.00037f, 0.00021f, 0.01f), 3,
                                         float(r), float(r));
    const DensityGrid grid = voxelize(s, GridTransform::uniform(h));
    for (Reconstruction mode : {Reconstruction::Nearest, Reconstruction::Trilinear}) {
        double sum = 0;
        for (int j = -3; j <= 3; ++j) {
            const Vec3f from(-0.0052f, float(j * h), 0.f), to(0.0049f, float(j * h), 0.f);
            const double i = grid.integrate(from, to, mode);
            EXPECT_NEAR(grid.integrate(to, from, mode), i, 1e-12) << "reversed";
            sum += i * h;
            EXPECT_NEAR(grid.transmittance(from, to, 2e4, mode), std::exp(-2e4 * i), 1e-12);
        }
        EXPECT_NEAR(sum, kPi * r * r, 1e-5 * kPi * r * r) << "mode " << int(mode);
    }
    EXPECT_EQ(grid.integrate(Vec3f(-0.01f, 0.005f, 0), Vec3f(0.01f, 0.005f, 0)), 0.0);  // misses
}

TEST(DensityGrid, SampleMatchesVoxelsAndInterpolates) {
    const double h = 0.001;
    const StrandFrame s = straightStrand(Vec3f(0.0003f, 0, -0.005f), Vec3f(0.0003f, 0, 0.005f), 2, 4e-5f, 4e-5f);
    const DensityGrid grid = voxelize(s, GridTransform::uniform(h));
    const float d0 = grid.density(Vec3i(0, 0, 0)), d1 = grid.density(Vec3i(1, 0, 0));
    ASSERT_GT(d0, d1);
    ASSERT_GT(d1, 0.f);
    EXPECT_FLOAT_EQ(grid.sample(Vec3f(0, 0, 0)), d0);
    EXPECT_FLOAT_EQ(grid.sample(Vec3f(0.001f, 0, 0)), d1);
    EXPECT_NEAR(grid.sample(Vec3f(0.0005f, 0, 0)), 0.5f * (d0 + d1), 1e-6f * d0);
    EXPECT_FLOAT_EQ(grid.sample(Vec3f(0.0004f, 0, 0), Reconstruction::Nearest), d0);
    EXPECT_FLOAT_EQ(grid.sample(Vec3f(0.0006f, 0, 0), Reconstruction::Nearest), d1);
}

TEST(DensityGrid, MatrixAndAxesTransformsAgree) {
    // A texel-style grid: 64 texels over [-0.05, 0.05]³, index = u·N − ½.
    const double n = 64, lo = -0.05, size = 0.1;
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() *= n / size;
    m.topRightCorner<3, 1>() = Vec3d::Constant(-lo * n / size - 0.5);
    const GridTransform a = GridTransform::fromMatrix(m);
    const GridTransform b = GridTransform::fromAxes(Eigen::Matrix3d::Identity() * (size / n),
                                                    Vec3d::Constant(lo + 0.5 * size / n));
    EXPECT_TRUE(a.linear.isApprox(b.linear, 1e-12));
    EXPECT_TRUE(a.offset.isApprox(b.offset, 1e-12));
    EXPECT_TRUE(a.toIndex(Vec3d::Constant(lo)).isApprox(Vec3d::Constant(-0.5), 1e-12));  // texel 0's corner
    EXPECT_NEAR(a.voxelVolume(), std::pow(size / n, 3), 1e-18);
    EXPECT_NEAR(a.uniformVoxelSize(), size / n, 1e-15);
}

TEST(DensityGrid, LightSpaceColumnsIntegrateToTheHairVolume) {
    // In a grid whose index z runs along the light, each column of voxels is
    // one light ray: Σ over columns of (∫ density ds) × voxel cross-section =
    // hair volume. This is the check the GL preview's shadow voxels use.
    const StrandFrame strands = randomStrands(200, 3);
    const Vec3d dir(-1, -1, -1);
    const double h = 0.0008;
    const GridTransform t = lightGrid(dir, h);
    const DensityGrid grid = voxelize(strands, t);
    Vec3i lo, hi;
    ASSERT_TRUE(grid.activeBounds(&lo, &hi));
    double sum = 0;
    for (int i = lo.x(); i <= hi.x(); ++i)
        for (int j = lo.y(); j <= hi.y(); ++j) {
            const Vec3d a = t.toWorld(Vec3d(i, j, lo.z() - 2)), b = t.toWorld(Vec3d(i, j, hi.z() + 2));
            sum += grid.integrate(a.cast<float>(), b.cast<float>(), Reconstruction::Nearest) * h * h;
        }
    const double volume = hairVolume(strands);
    EXPECT_NEAR(sum, volume, 1e-5 * volume);
}

TEST(Voxelizer, VelocityIsTheDensityWeightedMean) {
    // One strand moving uniformly: every voxel carries its velocity. Two
    // strands of equal radius through the same voxels: the mean.
    const double h = 0.001;
    const Vec3f v1(0.5f, -1.f, 2.f), v2(-0.5f, 1.f, 0.f);
    VoxelizeSettings s;
    s.velocity = true;
    StrandFrame one = straightStrand(Vec3f(0.0002f, 0, -0.004f), Vec3f(0.0002f, 0, 0.004f), 4, 3e-5f, 3e-5f, v1);
    const DensityGrid a = voxelize(one, GridTransform::uniform(h), s);
    ASSERT_TRUE(a.hasVelocity());
    for (int k = -3; k <= 3; ++k) EXPECT_LT((a.velocity(Vec3i(0, 0, k)) - v1).norm(), 1e-5f) << k;

    StrandFrame two = one;
    const StrandFrame other = straightStrand(Vec3f(0.0002f, 0, -0.004f), Vec3f(0.0002f, 0, 0.004f), 4, 3e-5f, 3e-5f, v2);
    two.addStrand(1, other.positions.data(), other.radii.data(), other.positions.size(), other.velocities.data());
    const DensityGrid b = voxelize(two, GridTransform::uniform(h), s);
    for (int k = -3; k <= 3; ++k)
        EXPECT_LT((b.velocity(Vec3i(1, 0, k)) - 0.5f * (v1 + v2)).norm(), 1e-5f) << k;
    // No velocity channel unless asked.
    EXPECT_FALSE(voxelize(two, GridTransform::uniform(h)).hasVelocity());
}

TEST(Voxelizer, ErrorsNameTheProblem) {
    StrandFrame bad = straightStrand(Vec3f(0, 0, 0), Vec3f(0, 0.01f, 0), 3, 1e-5f, 1e-5f);
    bad.positions[1].x() = std::nanf("");
    EXPECT_THROW(voxelize(bad, GridTransform::uniform(0.001)), Error);

    const StrandFrame far = straightStrand(Vec3f(0, 0, 0), Vec3f(500.f, 0, 0), 2, 1e-5f, 1e-5f);
    try {
        voxelize(far, GridTransform::uniform(1e-5));
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("voxel size far too small"), std::string::npos) << e.what();
    }

    VoxelizeSettings tight;
    tight.maxMemoryGiB = 0.001;
    try {
        voxelize(randomStrands(300, 5), GridTransform::uniform(0.0002), tight);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("use a larger voxel size"), std::string::npos) << e.what();
    }
    EXPECT_THROW(GridTransform::uniform(0.0), Error);
    Eigen::Matrix4d projective = Eigen::Matrix4d::Identity();
    projective(3, 2) = -1;
    EXPECT_THROW(GridTransform::fromMatrix(projective), Error);
    EXPECT_THROW(GridTransform::fromAxes(Eigen::Matrix3d::Zero(), Vec3d::Zero()), Error);
}
