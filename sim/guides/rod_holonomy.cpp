// rod::holonomyIterate: the rod step's solve for the lanes of curled
// strands, with the transported frame's holonomy in the constraint
// gradients (rod_kernels.h constraintJacobian gives the equations). The
// prefix sums ∇ψ_j = -Σ_{k<j} ∇m_k couple each joint to every vertex
// root-ward of it, so J W Jᵀ is dense (a dense Cholesky of its 3(n-1) rows
// made B-sim's step 19-21 times dearer, docs/physics.md). Conjugate
// gradients (Hestenes and Stiefel, "Methods of conjugate gradients for
// solving linear systems", 1952) need only products with it, each O(n) by
// the prefix sums, and the banded factorization of the frame-fixed system,
// which the step has made anyway, preconditions them: 3 to 5 iterations.
// Each lane runs its own iterations to its own residual (the others held
// by masks), so a strand's result is the same in any lane or batch.
#include "sim/guides/rod_kernels.h"
#include "sim/guides/rod_band.h"

#include <algorithm>
#include <cmath>
#include <type_traits>

// See rod_lanes.h: D4 values never cross a library boundary.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace hp::rod {

namespace {

using lanes::D4;
using lanes::F4;
typedef long long M4 __attribute__((vector_size(32)));  ///< a lane mask of D4 comparisons

[[gnu::always_inline]] inline D4 pick(M4 m, D4 a, D4 b) { return m ? a : b; }

/// The step's float data widened once per call (the iterations read each
/// entry ten times or more): gradients g[(3r + slot)·3 + c], the twist's
/// gradients te/tp[3k + c], K_{j,1}, K_{j,2}, the inverse masses. Widening is
/// exact, so the products are those of the float data.
struct Wide {
    const D4* g;
    const D4* te;
    const D4* tp;
    const D4* ka;
    const D4* kb;
    const D4* w;
    const D4* alpha;
};

[[gnu::always_inline]] inline Wide widenData(RodScratch& sc, int n) {
    const int S = n - 1, N = 3 * S;
    sc.wide.resize(size_t(9 * N + 6 * S + 2 * S + n));
    D4* out = lanes::view(sc.wide);
    Wide d{};
    using lanes::widen;
    d.g = out;
    for (int i = 0; i < 3 * N; ++i) {
        const lanes::V3<F4>& v = sc.grad[size_t(i)];
        *out++ = widen(v.x);
        *out++ = widen(v.y);
        *out++ = widen(v.z);
    }
    auto put3 = [&](const std::vector<lanes::V3<F4>>& src, const D4*& dst) {
        dst = out;
        for (int k = 0; k < S; ++k) {
            *out++ = widen(src[size_t(k)].x);
            *out++ = widen(src[size_t(k)].y);
            *out++ = widen(src[size_t(k)].z);
        }
    };
    put3(sc.twistEdge, d.te);
    put3(sc.twistParent, d.tp);
    d.ka = out;
    for (int k = 0; k < S; ++k) *out++ = widen(sc.curlA[size_t(k)]);
    d.kb = out;
    for (int k = 0; k < S; ++k) *out++ = widen(sc.curlB[size_t(k)]);
    d.w = out;
    for (int v = 0; v < n; ++v) *out++ = widen(sc.w[size_t(v)]);
    d.alpha = lanes::view(sc.alphaRow);
    return d;
}

/// out = (J W Jᵀ + α̃)·p for the four lanes, J with the holonomy
/// (constraintJacobian): Jᵀp = Σ_r p_r ∇C_r|frame fixed - Σ_k T_k ∇m_k with
/// T_k = Σ_{j>k} σ_j, σ_j = K_{j,2} p_{j,a} - K_{j,1} p_{j,b} (suffix sums);
/// (J q)_r = ∇C_r|frame fixed·q + (K_{j,2}, -K_{j,1})·ψ_j with
/// ψ_j = -Σ_{k<j} ∇m_k·q (prefix sums). q: scratch of 3n (vertex 0, the
/// root, is not read). Returns p·out.
/// Two passes: q = W Jᵀp vertex by vertex from the tip (each vertex's sum
/// complete when written: rows in increasing order, then the twist's terms
/// of joints v+1, v, v-1), then J q and p·out joint by joint from the root.
[[gnu::always_inline]] inline D4 applySystem(const Wide& d, int n, const D4* p, D4* out, D4* q) {
    const int S = n - 1;
    // T[k] for k = v+1, v, v-1 as the pass reaches vertex v.
    auto sigma = [&](int k) { return d.kb[k] * p[3 * k] - d.ka[k] * p[3 * k + 1]; };
    // From the tip, v = S: T_{v+1} and T_v are unused (no joints S, S+1), T_{S-1} = 0.
    D4 tNext{}, tHere{}, tPrev{};
    // One vertex; `full`: an interior vertex, every term present (the
    // conditions fold away and the loops unroll with fixed offsets).
    auto vertex = [&](int v, auto full) __attribute__((always_inline)) {
        constexpr bool F = decltype(full)::value;
        // v's rows: joint v-1 (slot 2), v (slot 1), v+1 (slot 0), k = 0..2 each.
        D4 qx{}, qy{}, qz{};
        for (int jj = 0; jj < 3; ++jj) {
            const int j = v - 1 + jj;
            if (!F && j > S - 1) break;
            const int slot = 2 - jj;
            for (int k = 0; k < (jj == 2 ? 2 : 3); ++k) {  // joint v+1's stretch row does not touch v
                const int r = 3 * j + k;
                const D4* g = d.g + 3 * (3 * r + slot);
                qx += g[0] * p[r];
                qy += g[1] * p[r];
                qz += g[2] * p[r];
            }
        }
        // Twist: joint v+1's parent term, joint v's edge and parent terms,
        // joint v-1's edge term (tHere = T_v, tNext = T_{v+1}, tPrev = T_{v-1}).
        if (F || (v + 1 <= S - 1 && v + 1 >= 2)) {
            const D4* g = d.tp + 3 * (v + 1);
            qx += g[0] * tNext;
            qy += g[1] * tNext;
            qz += g[2] * tNext;
        }
        if (F || v <= S - 1) {
            const D4* ge = d.te + 3 * v;
            qx += ge[0] * tHere;
            qy += ge[1] * tHere;
            qz += ge[2] * tHere;
            const D4* gp = d.tp + 3 * v;
            const D4 m = -tHere;
            qx += gp[0] * m;
            qy += gp[1] * m;
            qz += gp[2] * m;
        }
        {
            const D4* ge = d.te + 3 * (v - 1);
            const D4 m = -tPrev;
            qx += ge[0] * m;
            qy += ge[1] * m;
            qz += ge[2] * m;
        }
        q[3 * v] = qx * d.w[v];
        q[3 * v + 1] = qy * d.w[v];
        q[3 * v + 2] = qz * d.w[v];
        // Slide: T_{v-2} = T_{v-1} + σ_{v-1}.
        tNext = tHere;
        tHere = tPrev;
        if (F || v >= 2) tPrev = tPrev + sigma(v - 1);
    };
    int vi = S;
    for (; vi >= 1 && vi >= S - 1; --vi) vertex(vi, std::false_type());
    for (; vi >= 2; --vi) vertex(vi, std::true_type());
    for (; vi >= 1; --vi) vertex(vi, std::false_type());
    auto dotAt = [&](int v, const D4* g) { return g[0] * q[3 * v] + (g[1] * q[3 * v + 1] + g[2] * q[3 * v + 2]); };
    D4 psi{}, pap[3] = {};
    auto joint = [&](int j, auto full) __attribute__((always_inline)) {
        constexpr bool F = decltype(full)::value;
        D4 o[3];
        for (int k = 0; k < 3; ++k) {
            const int r = 3 * j + k;
            o[k] = d.alpha[r] * p[r];
            for (int slot = 0; slot < 3; ++slot) {
                const int vtx = j - 1 + slot;
                if (F || vtx >= 1) o[k] += dotAt(vtx, d.g + 3 * (3 * r + slot));
            }
        }
        o[0] += d.kb[j] * psi;
        o[1] -= d.ka[j] * psi;
        for (int k = 0; k < 3; ++k) {
            out[3 * j + k] = o[k];
            pap[k] += p[3 * j + k] * o[k];
        }
        // ∇m_j·q = ∂m_j/∂e_j·(q_{j+1} - q_j) + ∂m_j/∂e_{j-1}·(q_j - q_{j-1}); q_0 = 0 (the root).
        D4 dm = dotAt(j + 1, d.te + 3 * j);
        if (F || j >= 1) dm -= dotAt(j, d.te + 3 * j) - dotAt(j, d.tp + 3 * j);
        if (F || j >= 2) dm -= dotAt(j - 1, d.tp + 3 * j);
        psi -= dm;
    };
    int j = 0;
    for (; j < std::min(S, 2); ++j) joint(j, std::false_type());
    for (; j < S; ++j) joint(j, std::true_type());
    return (pap[0] + pap[1]) + pap[2];
}

/// a·b over N rows.
[[gnu::always_inline]] inline D4 dotRows(const D4* a, const D4* b, int N) {
    D4 s{};
    for (int i = 0; i < N; ++i) s += a[i] * b[i];
    return s;
}

}  // namespace

HP_ROD_LANES_CLONES int holonomyIterate(RodScratch& sc, int n, const bool curled[kLanes]) {
    const int N = 3 * (n - 1);
    for (auto* v : {&sc.r, &sc.z, &sc.p, &sc.ap}) v->resize(size_t(N));
    sc.q.resize(size_t(3 * n));
    const Wide d = widenData(sc, n);
    D4* x = lanes::view(sc.rhs);
    const D4* b = lanes::view(sc.b);
    D4* r = lanes::view(sc.r);
    D4* z = lanes::view(sc.z);
    D4* p = lanes::view(sc.p);
    D4* ap = lanes::view(sc.ap);
    D4* q = lanes::view(sc.q);
    const D4* band = lanes::view(sc.band);
    const D4* invD = lanes::view(sc.invD);
    // r = b - A x, from the frame-fixed system's solution x.
    applySystem(d, n, x, ap, q);
    for (int i = 0; i < N; ++i) z[i] = r[i] = b[i] - ap[i];
    D4 rr = dotRows(r, r, N);
    const D4 tol = 1e-10 * dotRows(b, b, N);  // |r|² ≤ 10⁻¹⁰|b|²: |r| ≤ 10⁻⁵|C|
    M4 active = {curled[0] ? -1 : 0, curled[1] ? -1 : 0, curled[2] ? -1 : 0, curled[3] ? -1 : 0};
    active &= rr > tol;
    auto anyActive = [&] {
        bool any = false;
        for (int l = 0; l < kLanes; ++l) any = any || active[l] != 0;
        return any;
    };
    int iterations = 0;
    if (!anyActive()) return 0;  // the frame-fixed solution already meets the tolerance
    bandedPrecondition(band, invD, z, N);
    for (int i = 0; i < N; ++i) p[i] = z[i];
    D4 rz = dotRows(r, z, N);
    for (int it = 0; it < 100; ++it) {
        for (int l = 0; l < kLanes; ++l) iterations += active[l] != 0 ? 1 : 0;
        const D4 a = rz / applySystem(d, n, p, ap, q);
        for (int i = 0; i < N; ++i) {
            x[i] = pick(active, x[i] + a * p[i], x[i]);
            r[i] = pick(active, r[i] - a * ap[i], r[i]);
            z[i] = r[i];
        }
        rr = dotRows(r, r, N);
        active &= rr > tol;
        if (!anyActive()) break;  // (the next direction would go unused)
        bandedPrecondition(band, invD, z, N);
        const D4 rz2 = dotRows(r, z, N);
        const D4 beta = rz2 / rz;
        for (int i = 0; i < N; ++i) p[i] = pick(active, z[i] + beta * p[i], p[i]);
        rz = pick(active, rz2, rz);
    }
    return iterations;
}

}  // namespace hp::rod
