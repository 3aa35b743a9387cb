// rod::bandedSolve. The rows' envelope repeats with the joints (three row
// kinds: bend a, bend b, stretch), so away from the ends every row's loops
// have bounds known at compile time: those rows are unrolled by templates
// (RowKind), the partial sums stay in registers, and the four lanes' long
// dependency chains (each pivot waits on the rows above) overlap. The first
// and last rows take the generic loops. Both compute the same sums in the
// same order, so the result is the generic loops' bit for bit.
#include "sim/guides/rod_band.h"

#include <utility>

// See rod_lanes.h: D4 values never cross a library boundary.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace hp::rod {

using lanes::D4;

namespace {

/// i - envelopeStart(i) for a row of kind k = i mod 3, away from the root
/// (rows i ≥ 6: the envelope is not clipped at column 0).
constexpr int widthOf(int k) { return k == 2 ? 5 : k == 0 ? 6 : 7; }
/// Kind of the row `back` rows above (negative: below) a row of kind k.
constexpr int kindOf(int k, int back) { return ((k - back) % 3 + 3) % 3; }
/// First row whose envelope and whose envelope rows' envelopes are unclipped.
constexpr int kSteadyFrom = 12;

/// sum -= Σ_{mm = M..JJ-1} t[mm]·Lj[JJ - mm], in increasing mm.
template <int M, int JJ>
[[gnu::always_inline]] inline void subtractTerms(D4& sum, const D4* t, const D4* Lj) {
    if constexpr (M < JJ) {
        sum -= t[M] * Lj[JJ - M];
        subtractTerms<M + 1, JJ>(sum, t, Lj);
    }
}

/// Column j = lo + JJ of row i (kind K): L_ij and its share of D_i.
template <int K, int JJ>
[[gnu::always_inline]] inline void factorColumn(D4* __restrict Li, const D4* __restrict band,
                                                const D4* __restrict invD, int i, D4* t, D4& d) {
    constexpr int back = widthOf(K) - JJ;  // i - j
    constexpr int reach = widthOf(kindOf(K, back));
    constexpr int first = JJ - reach > 0 ? JJ - reach : 0;  // max(lo, envelopeStart(j)) - lo
    const D4* Lj = band + size_t(i - back) * kRowLen;
    D4 sum = Li[back];
    subtractTerms<first, JJ>(sum, t, Lj);
    t[JJ] = sum;
    const D4 lij = sum * invD[i - back];
    Li[back] = lij;
    d -= sum * lij;
}

template <int K, size_t... JJ>
[[gnu::always_inline]] inline void factorSteadyRow(D4* __restrict band, D4* __restrict invD, int i,
                                                   std::index_sequence<JJ...>) {
    D4* Li = band + size_t(i) * kRowLen;
    D4 t[widthOf(K)];
    D4 d = Li[0];
    (factorColumn<K, int(JJ)>(Li, band, invD, i, t, d), ...);
    invD[i] = 1.0 / d;
}

/// Row i of the factorization, any i (the generic loops).
inline void factorRow(D4* __restrict band, D4* __restrict invD, int i) {
    D4 t[kBand];  // t[m - lo] = L_im·D_m of the current row
    const int lo = envelopeStart(i);
    D4* Li = band + size_t(i) * kRowLen;
    D4 d = Li[0];
    for (int j = lo; j < i; ++j) {
        const D4* Lj = band + size_t(j) * kRowLen;
        D4 sum = Li[i - j];
        for (int m = std::max(lo, envelopeStart(j)); m < j; ++m) sum -= t[m - lo] * Lj[j - m];
        t[j - lo] = sum;
        const D4 lij = sum * invD[j];
        Li[i - j] = lij;
        d -= sum * lij;
    }
    invD[i] = 1.0 / d;
}

/// Back substitution of row i of kind K, far from the last row: the rows
/// k = i + B below whose envelope reaches column i (B ≤ widthOf(kind of k)).
template <int K, int B>
[[gnu::always_inline]] inline void backTerm(D4& acc, const D4* __restrict band, const D4* __restrict x, int i) {
    if constexpr (B <= kBand) {
        if constexpr (B <= widthOf(kindOf(K, -B))) acc -= band[size_t(i + B) * kRowLen + size_t(B)] * x[i + B];
        backTerm<K, B + 1>(acc, band, x, i);
    }
}

/// backTerm's terms in the opposite order, B from kBand down to 1: the
/// newest unknown x[i+1] enters last, so a row waits on the one below it for
/// one product and one difference, not for the whole sum (the
/// preconditioner's substitutions, where the order of rounding is free).
template <int K, int B>
[[gnu::always_inline]] inline void backTermLatest(D4& acc, const D4* __restrict band, const D4* __restrict x, int i) {
    if constexpr (B >= 1) {
        if constexpr (B <= widthOf(kindOf(K, -B))) acc -= band[size_t(i + B) * kRowLen + size_t(B)] * x[i + B];
        backTermLatest<K, B - 1>(acc, band, x, i);
    }
}

/// Forward substitution's row i of kind K away from the root: acc -= L_im z_m
/// over the envelope's B = widthOf(K) columns, in increasing m (the
/// generic loop's order).
template <int K, int B>
[[gnu::always_inline]] inline void forwardTerms(D4& acc, const D4* __restrict Li, const D4* __restrict z, int i) {
    if constexpr (B >= 1) {
        acc -= Li[B] * z[i - B];
        forwardTerms<K, B - 1>(acc, Li, z, i);
    }
}

template <int K>
[[gnu::always_inline]] inline void forwardRow(const D4* __restrict band, D4* __restrict z, int i) {
    D4 acc = z[i];
    forwardTerms<K, widthOf(K)>(acc, band + size_t(i) * kRowLen, z, i);
    z[i] = acc;
}

}  // namespace

HP_ROD_LANES_CLONES void bandedSolve(D4* __restrict band, D4* __restrict invD, D4* __restrict rhs, int n) {
    bandedFactor(band, invD, n);
    bandedSubstitute(band, invD, rhs, n);
}

HP_ROD_LANES_CLONES void bandedFactor(D4* __restrict band, D4* __restrict invD, int n) {
    // Factorization: rows of the three kinds in turn once steady.
    int i = 0;
    for (; i < std::min(n, kSteadyFrom); ++i) factorRow(band, invD, i);
    for (; i + 3 <= n; i += 3) {
        factorSteadyRow<0>(band, invD, i, std::make_index_sequence<widthOf(0)>());
        factorSteadyRow<1>(band, invD, i + 1, std::make_index_sequence<widthOf(1)>());
        factorSteadyRow<2>(band, invD, i + 2, std::make_index_sequence<widthOf(2)>());
    }
    for (; i < n; ++i) factorRow(band, invD, i);
}

namespace {

template <bool Latest>
[[gnu::always_inline]] inline void substitute(const D4* __restrict band, const D4* __restrict invD, D4* __restrict rhs,
                                             int n) {
    // L z = rhs (z in rhs); rows from 6 on (envelopes not clipped at the
    // root) unrolled by kind, the same sums in the same order.
    auto forwardGeneric = [&](int r) {
        const D4* Li = band + size_t(r) * kRowLen;
        D4 acc = rhs[r];
        for (int m = envelopeStart(r); m < r; ++m) acc -= Li[r - m] * rhs[m];
        rhs[r] = acc;
    };
    int f = 0;
    for (; f < std::min(n, 6); ++f) forwardGeneric(f);
    for (; f + 3 <= n; f += 3) {
        forwardRow<0>(band, rhs, f);
        forwardRow<1>(band, rhs, f + 1);
        forwardRow<2>(band, rhs, f + 2);
    }
    for (; f < n; ++f) forwardGeneric(f);
    // Lᵀ x = D⁻¹ z, from the last row up.
    auto generic = [&](int r) {
        D4 acc = rhs[r] * invD[r];
        for (int k = r + 1; k <= std::min(n - 1, r + kBand); ++k)
            if (envelopeStart(k) <= r) acc -= band[size_t(k) * kRowLen + size_t(k - r)] * rhs[k];
        rhs[r] = acc;
    };
    int r = n - 1;
    for (; r >= 0 && r + kBand >= n; --r) generic(r);  // rows whose band reaches past the end
    // Steady rows: r + kBand < n and r ≥ 6, whole kinds in turn (r mod 3 = 2, 1, 0).
    for (; r >= 6 && r % 3 != 2; --r) generic(r);
    for (; r >= 8; r -= 3) {
        D4 acc = rhs[r] * invD[r];
        if constexpr (Latest) backTermLatest<2, kBand>(acc, band, rhs, r);
        else backTerm<2, 1>(acc, band, rhs, r);
        rhs[r] = acc;
        acc = rhs[r - 1] * invD[r - 1];
        if constexpr (Latest) backTermLatest<1, kBand>(acc, band, rhs, r - 1);
        else backTerm<1, 1>(acc, band, rhs, r - 1);
        rhs[r - 1] = acc;
        acc = rhs[r - 2] * invD[r - 2];
        if constexpr (Latest) backTermLatest<0, kBand>(acc, band, rhs, r - 2);
        else backTerm<0, 1>(acc, band, rhs, r - 2);
        rhs[r - 2] = acc;
    }
    for (; r >= 0; --r) generic(r);
}

}  // namespace

HP_ROD_LANES_CLONES void bandedSubstitute(const D4* __restrict band, const D4* __restrict invD, D4* __restrict rhs,
                                          int n) {
    substitute<false>(band, invD, rhs, n);
}

HP_ROD_LANES_CLONES void bandedPrecondition(const D4* __restrict band, const D4* __restrict invD, D4* __restrict rhs,
                                            int n) {
    substitute<true>(band, invD, rhs, n);
}

}  // namespace hp::rod
