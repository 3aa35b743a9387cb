// Efficiency-aware Russian roulette and splitting of the indirect path
// (render/reference/path_splitting.h): the chosen rate minimises variance ×
// cost, the path count has the rate as its mean, the pooled statistics are
// box sums, and the renderer's image with per-pixel rates has the mean of
// the plain estimator's.
#include "render_support.h"
#include "test_support.h"

#include "render/reference/path_splitting.h"
#include "render/reference/reference.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace hp;
using namespace hp::test;

namespace {

/// Stats of n samples whose scalar value Y has variance V and whose indirect
/// part I has mean mu and variance W, all of it between paths from the same
/// first hit, at costs c0 + c1 and c1 a sample.
SplitStats statsOf(double V, double mu, double W, double c0, double c1, double n = 1000.0) {
    SplitStats s;
    s.n = n;
    s.sumY = 0.0, s.sumY2 = n * V;
    s.sumI2 = n * (W + mu * mu);
    s.sumSplit = n * W;
    s.cost = n * (c0 + c1), s.costIndirect = n * c1;
    s.devY = n * V;
    return s;
}

/// Variance × cost a sample at rate r, the model the rate is chosen under
/// (roulette exact, splitting with all of I's variance averaged out).
double inverseEfficiency(double r, double V, double mu, double W, double c0, double c1) {
    const double M = W + mu * mu;
    const double var = r <= 1.0 ? V + M * (1.0 - r) / r : (V - W) + W / r;
    return var * (c0 + r * c1);
}

}  // namespace

TEST(PathSplitting, RateMinimisesVarianceTimesCost) {
    // For random statistics, no rate on a fine grid of [1/4, 4] does better
    // than the chosen one (within the grid's step).
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int roulette = 0, splitting = 0;
    for (int trial = 0; trial < 500; ++trial) {
        const double W = 0.1 + 4.0 * u(rng), mu = 2.0 * u(rng);
        const double V = W + 0.05 + 6.0 * u(rng);  // Var(Y) ≥ Var(I) when D and I are uncorrelated
        const double c0 = 0.5 + 3.0 * u(rng), c1 = 0.5 + 3.0 * u(rng);
        const float r = efficientSplitRate(statsOf(V, mu, W, c0, c1), 0.25f, 4.f);
        const double chosen = inverseEfficiency(r, V, mu, W, c0, c1);
        double best = 1e300;
        for (double g = 0.25; g <= 4.0; g += 0.001) best = std::min(best, inverseEfficiency(g, V, mu, W, c0, c1));
        EXPECT_LE(chosen, best * (1.0 + 1e-4)) << "trial " << trial << " rate " << r;
        roulette += r < 0.99f, splitting += r > 1.01f;
    }
    EXPECT_GT(roulette, 50);  // both regimes occur
    EXPECT_GT(splitting, 50);
}

TEST(PathSplitting, RateLimitsAndDegenerateStats) {
    EXPECT_EQ(efficientSplitRate(SplitStats{}, 0.25f, 4.f), 1.f);                   // no samples
    EXPECT_EQ(efficientSplitRate(statsOf(1.0, 0.0, 0.0, 1.0, 1.0), 0.25f, 4.f), 1.f);  // no indirect light (M = 0)
    // All of the noise indirect (V = W): split as much as allowed.
    EXPECT_EQ(efficientSplitRate(statsOf(2.0, 0.0, 2.0, 1.0, 1.0), 0.25f, 4.f), 4.f);
    // Faint, costly indirect light next to noisy direct light: roulette to the floor.
    EXPECT_EQ(efficientSplitRate(statsOf(10.0, 0.01, 0.0001, 1.0, 10.0), 0.25f, 4.f), 0.25f);
    // r = √(M c0 / ((V − M) c1)) = √(1·2 / (3·1)).
    EXPECT_NEAR(efficientSplitRate(statsOf(4.0, 0.0, 1.0, 2.0, 1.0), 0.25f, 4.f), std::sqrt(2.0 / 3.0), 1e-5);
}

TEST(PathSplitting, CountHasTheRateAsMean) {
    for (float rate : {0.25f, 0.6f, 1.f, 1.5f, 2.75f, 4.f}) {
        const int n = 4096;
        double sum = 0.0;
        for (int i = 0; i < n; ++i) sum += splitCount(rate, (float(i) + 0.5f) / float(n));
        EXPECT_NEAR(sum / n, rate, 1e-3) << rate;  // stratified u: exact up to the grid
    }
}

TEST(PathSplitting, PooledStatsAreBoxSums) {
    const int w = 7, h = 5;
    std::vector<SplitStats> s(size_t(w) * h);
    // Two samples a pixel, y = k ± (k % 3): the pixel's squared deviations
    // sum to 2 (k % 3)², whatever its mean k; paths I₁ = k % 3, I₂ = 0.
    for (int k = 0; k < w * h; ++k)
        for (int sign : {-1, 1})
            s[k].add(double(k + sign * (k % 3)), double(k % 3), 0.0, double(k % 4 + 1), 1.0);
    const auto pooled = poolSplitStats(s, w, h, 2);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double n = 0.0, sumY = 0.0, cost = 0.0, devY = 0.0, split = 0.0;
            for (int yy = y - 2; yy <= y + 2; ++yy)
                for (int xx = x - 2; xx <= x + 2; ++xx)
                    if (xx >= 0 && xx < w && yy >= 0 && yy < h) {
                        const int k = yy * w + xx;
                        n += 2.0, sumY += 2.0 * k, cost += 2.0 * (k % 4 + 1), devY += 2.0 * (k % 3) * (k % 3);
                        split += (k % 3) * (k % 3);  // 2 × (I₁ − I₂)² / 2
                    }
            const SplitStats& p = pooled[size_t(y) * w + x];
            EXPECT_EQ(p.n, n);
            EXPECT_EQ(p.sumY, sumY);
            EXPECT_EQ(p.cost, cost);
            EXPECT_NEAR(p.devY, devY, 1e-9 * (1.0 + devY));  // not the spread of the pixels' means
            EXPECT_EQ(p.sumSplit, split);
        }
}

TEST(PathSplitting, ImageMeanMatchesThePlainEstimator) {
    // Unbiasedness: over 20 seeds, the mean of the image's total radiance
    // with rates matches the plain one-path estimator's within 4 standard
    // errors of the difference (a false alarm about once in 16,000 runs for
    // Gaussian means). Three rate policies: roulette everywhere (rate 0.5),
    // fractional splitting everywhere (2.5) and the efficiency-aware rates
    // (roulette and splitting both in use).
    const HairOnHead shot = hairOnHead(40, 30);
    ReferenceSettings s;
    s.mode = ReferenceMode::Physical;
    s.samplesPerPixel = 8;
    s.bounces = 3;
    // Blond fibres: the indirect light is a large part of the picture, so a
    // wrong weight on it shows.
    s.fiber.sigmaA = hairAbsorptionFromMelanin(0.3f, 0.1f);
    const int seeds = 20;
    struct Policy {
        const char* name;
        bool on;
        float minRate, maxRate;
    };
    const Policy policies[] = {{"plain", false, 1.f, 1.f},
                               {"roulette 0.5", true, 0.5f, 0.5f},
                               {"splitting 2.5", true, 2.5f, 2.5f},
                               {"efficiency", true, 0.25f, 4.f}};
    double mean[4], var[4];
    for (int p = 0; p < 4; ++p) {
        s.efficiencySplitting = policies[p].on;
        s.splitMinRate = policies[p].minRate, s.splitMaxRate = policies[p].maxRate;
        double sum = 0.0, sum2 = 0.0;
        float minRate = 1.f, maxRate = 1.f;
        for (int k = 0; k < seeds; ++k) {
            s.seed = uint64_t(100 + k);
            ReferenceStats st;
            const Image img = ReferenceRenderer().render(shot.view, &shot.strands, &shot.head, s, &st);
            double t = 0.0;
            for (int y = 0; y < img.height; ++y)
                for (int x = 0; x < img.width; ++x) t += img.at(x, y, 0) + img.at(x, y, 1) + img.at(x, y, 2);
            sum += t, sum2 += t * t;
            minRate = std::min(minRate, st.minSplitRate), maxRate = std::max(maxRate, st.maxSplitRate);
        }
        mean[p] = sum / seeds;
        var[p] = (sum2 / seeds - mean[p] * mean[p]) * seeds / (seeds - 1);
        if (p == 3) {
            EXPECT_LT(minRate, 0.9f);  // some pixels roulette their indirect paths
            EXPECT_GT(maxRate, 1.1f);  // and some split them
        }
        if (p == 0) {
            ASSERT_GT(mean[0], 1.0);  // the picture is lit
            continue;
        }
        const double se = std::sqrt((var[0] + var[p]) / seeds);
        EXPECT_LT(std::abs(mean[p] - mean[0]), 4.0 * se)
            << policies[p].name << ": plain " << mean[0] << ", with rates " << mean[p]
            << ", standard error of the difference " << se;
        std::printf("%s: plain %.3f, with rates %.3f (se of the difference %.3f), rates %.2f..%.2f\n",
                    policies[p].name, mean[0], mean[p], se, minRate, maxRate);
    }
}

TEST(PathSplitting, WhiteFibreUnderWhiteSkyStaysWhite) {
    // The furnace (Chiang et al. 2016's test, through the whole integrator):
    // a non-absorbing fibre under a uniform white sky shows exactly 1, and
    // here all of it arrives through the first hit's continuation (a
    // constant sky is gathered by BSDF sampling alone), so every weight of
    // the indirect path shows one to one: roulette counted 1/N instead of
    // 1/rate would show 0.5 at rate 0.5.
    View view = testView(64, 48, Vec3f(0.f, -1.f, 0.f));
    view.lights.clear();
    view.environment = Vec3f::Ones();
    StrandFrame strands;
    const int n = 9;
    std::vector<Vec3f> p(n);
    std::vector<float> radii(n, 0.03f);
    for (int i = 0; i < n; ++i) p[i] = Vec3f(-1.f + 2.f * float(i) / float(n - 1), 0.f, 0.f);
    strands.addStrand(0, p.data(), radii.data(), size_t(n));
    ReferenceSettings s;
    s.mode = ReferenceMode::Physical;
    s.samplesPerPixel = 32;
    s.bounces = 2;
    s.fiber.sigmaA = Vec3f::Zero();
    s.efficiencySplitting = true;
    for (const auto& [minRate, maxRate] : {std::pair{0.5f, 0.5f}, {2.5f, 2.5f}, {0.25f, 4.f}}) {
        s.splitMinRate = minRate, s.splitMaxRate = maxRate;
        const Image img = ReferenceRenderer().render(view, &strands, nullptr, s);
        double sum = 0.0;
        int covered = 0;
        for (int y = 21; y <= 26; ++y)
            for (int x = 4; x < 60; ++x)
                if (img.at(x, y, 3) == 1.f) sum += img.at(x, y, 1), ++covered;
        ASSERT_GT(covered, 100);
        EXPECT_NEAR(sum / covered, 1.0, 0.03) << "rates " << minRate << ".." << maxRate;
    }
}
