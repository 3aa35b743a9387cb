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
/// entry ten times or more), by edge: the constraints depend on the
/// vertices through the edges e_j = x_{j+1} - x_j, so joint j's gradients
/// are those on e_{j-1} and e_j (the vertex gradient g_{j-1} = -∂C/∂e_{j-1},
/// g_{j+1} = ∂C/∂e_j, g_j their negated sum). Per joint, 7 vectors of 3
/// components: ∂C_a/∂e_{j-1}, ∂C_a/∂e_j, ∂C_b/∂e_{j-1}, ∂C_b/∂e_j, the
/// stretch row's d_j, the reference twist's ∂m_j/∂e_j, ∂m_j/∂e_{j-1} (none at
/// the ghost joint); K_{j,1}, K_{j,2}; the inverse masses. Widening is exact.
struct Wide {
    const D4* e;  ///< joint j's vectors at e[21j + 3m + c]
    const D4* ka;
    const D4* kb;
    const D4* w;
    const D4* alpha;
};

[[gnu::always_inline]] inline Wide widenData(RodScratch& sc, int n) {
    const int S = n - 1;
    sc.wide.resize(size_t(21 * S + 2 * S + n));
    D4* out = lanes::view(sc.wide);
    Wide d{};
    using lanes::widen;
    auto put = [&](const lanes::V3<F4>& v, F4 sign) __attribute__((always_inline)) {
        *out++ = widen(sign * v.x);
        *out++ = widen(sign * v.y);
        *out++ = widen(sign * v.z);
    };
    const F4 plus = lanes::splat<F4>(1.f), minus = lanes::splat<F4>(-1.f), zero{};
    const lanes::V3<F4>* g = sc.grad.data();
    d.e = out;
    for (int j = 0; j < S; ++j) {
        const int ra = 3 * j, rb = 3 * j + 1, rs = 3 * j + 2;
        // Slot 0 (vertex j-1) is not written at the ghost joint.
        put(g[3 * ra], j == 0 ? zero : minus);
        put(g[3 * ra + 2], plus);
        put(g[3 * rb], j == 0 ? zero : minus);
        put(g[3 * rb + 2], plus);
        put(g[3 * rs + 2], plus);
        put(sc.twistEdge[size_t(j)], plus);
        put(sc.twistParent[size_t(j)], plus);
    }
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
/// ψ_j = -Σ_{k<j} ∇m_k·q (prefix sums). Returns p·out.
/// By edges: Jᵀp is f_{v-1} - f_v at vertex v with f_e the sum of
/// p_r ∂C_r/∂e_e - T_k ∂m_k/∂e_e over the rows of joints e, e+1 (f_{-1}: the
/// root's, unused; f_{S} = 0), q = W Jᵀp from the tip; then J q from the
/// root through Δq_e = q_{e+1} - q_e (q_0 = 0, the root held).
[[gnu::always_inline]] inline D4 applySystem(const Wide& d, int n, const D4* p, D4* out, D4* q) {
    const int S = n - 1;
    D4 fx{}, fy{}, fz{};  // f_{e+1}
    D4 T{}, Tn{};         // T_e (T_{S-1} = 0), T_{e+1}
    for (int e = S - 1; e >= 0; --e) {
        const D4* g = d.e + 21 * e;
        const D4 pa = p[3 * e], pb = p[3 * e + 1], ps = p[3 * e + 2], mt = -T;
        D4 x = (g[3] * pa + g[9] * pb) + (g[12] * ps + g[15] * mt);
        D4 y = (g[4] * pa + g[10] * pb) + (g[13] * ps + g[16] * mt);
        D4 z = (g[5] * pa + g[11] * pb) + (g[14] * ps + g[17] * mt);
        if (e + 1 <= S - 1) {
            const D4* h = g + 21;
            const D4 qa = p[3 * e + 3], qb = p[3 * e + 4], mtn = -Tn;
            x += (h[0] * qa + h[6] * qb) + h[18] * mtn;
            y += (h[1] * qa + h[7] * qb) + h[19] * mtn;
            z += (h[2] * qa + h[8] * qb) + h[20] * mtn;
        }
        const D4 w = d.w[e + 1];
        q[3 * e + 3] = (x - fx) * w;
        q[3 * e + 4] = (y - fy) * w;
        q[3 * e + 5] = (z - fz) * w;
        fx = x;
        fy = y;
        fz = z;
        Tn = T;
        T += d.kb[e] * pa - d.ka[e] * pb;  // T_{e-1} = T_e + σ_e
    }
    auto dot = [](const D4* g, const D4* v) { return g[0] * v[0] + (g[1] * v[1] + g[2] * v[2]); };
    D4 psi{}, pap{};
    D4 prev[3] = {}, cur[3];  // Δq_{j-1}, Δq_j
    for (int j = 0; j < S; ++j) {
        const D4* g = d.e + 21 * j;
        for (int c = 0; c < 3; ++c) cur[c] = j == 0 ? q[3 + c] : q[3 * j + 3 + c] - q[3 * j + c];
        const int r = 3 * j;
        const D4 oa = (d.alpha[r] * p[r] + (dot(g + 3, cur) + dot(g, prev))) + d.kb[j] * psi;
        const D4 ob = (d.alpha[r + 1] * p[r + 1] + (dot(g + 9, cur) + dot(g + 6, prev))) - d.ka[j] * psi;
        const D4 os = d.alpha[r + 2] * p[r + 2] + dot(g + 12, cur);
        out[r] = oa;
        out[r + 1] = ob;
        out[r + 2] = os;
        pap += (p[r] * oa + p[r + 1] * ob) + p[r + 2] * os;
        psi -= dot(g + 15, cur) + dot(g + 18, prev);  // ∇m_j·q
        for (int c = 0; c < 3; ++c) prev[c] = cur[c];
    }
    return pap;
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
