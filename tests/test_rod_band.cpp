// The rod step's banded LDLᵀ (sim/guides/rod_band.h) against Eigen's dense
// LDLᵀ of the same systems: the substitutions of the frame-fixed solve
// (bandedSubstitute) and of the holonomy's preconditioner
// (bandedPrecondition, its back substitution summed in the other order)
// both solve them, each of the four lanes its own system.
#include "sim/guides/rod_band.h"
#include "sim/guides/rod_kernels.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

using namespace hp::rod;

namespace {

/// Four symmetric systems of n rows with the rod's envelope (the entries
/// of row i from column envelopeStart(i) on), strictly diagonally
/// dominant, so positive definite with a condition number of order one.
struct Systems {
    int n;
    std::vector<lanes::D4Store> band, invD;
    Eigen::MatrixXd dense[kLanes];
    Eigen::VectorXd rhs[kLanes];
};

Systems makeSystems(int n, unsigned seed) {
    Systems s;
    s.n = n;
    s.band.assign(size_t(n) * kRowLen, lanes::D4Store{});
    s.invD.assign(size_t(n), lanes::D4Store{});
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int l = 0; l < kLanes; ++l) {
        Eigen::MatrixXd& A = s.dense[l];
        A.setZero(n, n);
        for (int i = 0; i < n; ++i)
            for (int j = envelopeStart(i); j < i; ++j) A(i, j) = A(j, i) = u(rng);
        for (int i = 0; i < n; ++i) A(i, i) = A.row(i).cwiseAbs().sum() + 1.0;
        s.rhs[l] = Eigen::VectorXd::NullaryExpr(n, [&] { return u(rng); });
        for (int i = 0; i < n; ++i)
            for (int k = 0; k <= std::min(i, kBand); ++k) s.band[size_t(i) * kRowLen + size_t(k)].v[l] = A(i, i - k);
    }
    return s;
}

/// Largest error of the four lanes' solutions in x against the dense solve,
/// relative to the largest component of the solution.
double worstError(const Systems& s, const std::vector<lanes::D4Store>& x) {
    double worst = 0;
    for (int l = 0; l < kLanes; ++l) {
        const Eigen::VectorXd ref = s.dense[l].ldlt().solve(s.rhs[l]);
        double err = 0;
        for (int i = 0; i < s.n; ++i) err = std::max(err, std::abs(x[size_t(i)].v[l] - ref[i]));
        worst = std::max(worst, err / ref.cwiseAbs().maxCoeff());
    }
    return worst;
}

}  // namespace

TEST(RodBand, BothSubstitutionsSolveTheFactoredSystem) {
    // 69 rows: the default 24-vertex strand's 3·23 (rows past the generic
    // first ones take the unrolled kinds); 8 and 13: the short strands'
    // generic paths and a partial last joint.
    for (int n : {69, 8, 13}) {
        Systems s = makeSystems(n, 29u + unsigned(n));
        bandedFactor(lanes::view(s.band), lanes::view(s.invD), n);
        std::vector<lanes::D4Store> a(static_cast<size_t>(n)), b(static_cast<size_t>(n));
        for (int i = 0; i < n; ++i)
            for (int l = 0; l < kLanes; ++l) a[size_t(i)].v[l] = b[size_t(i)].v[l] = s.rhs[l][i];
        bandedSubstitute(lanes::view(s.band), lanes::view(s.invD), lanes::view(a), n);
        bandedPrecondition(lanes::view(s.band), lanes::view(s.invD), lanes::view(b), n);
        // Diagonally dominant by 1: both within a few hundred ulps of the dense solve.
        EXPECT_LT(worstError(s, a), 1e-13) << n << " rows, bandedSubstitute";
        EXPECT_LT(worstError(s, b), 1e-13) << n << " rows, bandedPrecondition";
    }
}
