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

#include <cmath>

// See rod_lanes.h: D4 values never cross a library boundary.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace hp::rod {

namespace {

using lanes::D4;
using lanes::F4;
typedef long long M4 __attribute__((vector_size(32)));  ///< a lane mask of D4 comparisons

[[gnu::always_inline]] inline D4 pick(M4 m, D4 a, D4 b) { return m ? a : b; }

/// out = (J W Jᵀ + α̃)·p for the four lanes, J with the holonomy
/// (constraintJacobian): Jᵀp = Σ_r p_r ∇C_r|frame fixed - Σ_k T_k ∇m_k with
/// T_k = Σ_{j>k} σ_j, σ_j = K_{j,2} p_{j,a} - K_{j,1} p_{j,b} (suffix sums);
/// (J q)_r = ∇C_r|frame fixed·q + (K_{j,2}, -K_{j,1})·ψ_j with
/// ψ_j = -Σ_{k<j} ∇m_k·q (prefix sums). q: scratch of 3n.
[[gnu::always_inline]] inline void applySystem(const RodScratch& sc, int n, const D4* p, D4* out, D4* q) {
    const int S = n - 1, N = 3 * S;
    const lanes::V3<F4>* grad = sc.grad.data();
    const F4* w = sc.w.data();
    const F4* ka = sc.curlA.data();
    const F4* kb = sc.curlB.data();
    const lanes::V3<F4>* gE = sc.twistEdge.data();
    const lanes::V3<F4>* gP = sc.twistParent.data();
    using lanes::widen;
    for (int i = 0; i < 3 * n; ++i) q[i] = D4{};
    auto addTo = [&](int v, const lanes::V3<F4>& g, D4 s) {
        q[3 * v] += widen(g.x) * s;
        q[3 * v + 1] += widen(g.y) * s;
        q[3 * v + 2] += widen(g.z) * s;
    };
    for (int r = 0; r < N; ++r)
        for (int slot = 0; slot < 3; ++slot) {
            const int vtx = r / 3 - 1 + slot;
            if (vtx >= 1) addTo(vtx, grad[3 * r + slot], p[r]);
        }
    D4 T{};
    for (int k = S - 1; k >= 0; --k) {
        addTo(k + 1, gE[k], -T);
        if (k >= 1) addTo(k, gE[k], T);
        if (k >= 1) addTo(k, gP[k], -T);
        if (k >= 2) addTo(k - 1, gP[k], T);
        T += widen(kb[k]) * p[3 * k] - widen(ka[k]) * p[3 * k + 1];
    }
    for (int v = 0; v < n; ++v)
        for (int c = 0; c < 3; ++c) q[3 * v + c] *= widen(w[v]);
    auto dotAt = [&](int v, const lanes::V3<F4>& g) {
        return widen(g.x) * q[3 * v] + (widen(g.y) * q[3 * v + 1] + widen(g.z) * q[3 * v + 2]);
    };
    D4 psi{};
    const D4* alpha = lanes::view(const_cast<std::vector<lanes::D4Store>&>(sc.alphaRow));
    for (int j = 0; j < S; ++j) {
        for (int k = 0; k < 3; ++k) {
            const int r = 3 * j + k;
            D4 o = alpha[r] * p[r];
            for (int slot = 0; slot < 3; ++slot) {
                const int vtx = j - 1 + slot;
                if (vtx >= 1) o += dotAt(vtx, grad[3 * r + slot]);
            }
            out[r] = o;
        }
        out[3 * j] += widen(kb[j]) * psi;
        out[3 * j + 1] -= widen(ka[j]) * psi;
        // ∇m_j·q = ∂m_j/∂e_j·(q_{j+1} - q_j) + ∂m_j/∂e_{j-1}·(q_j - q_{j-1}); q_0 = 0 (the root).
        D4 dm = dotAt(j + 1, gE[j]);
        if (j >= 1) dm -= dotAt(j, gE[j]) - dotAt(j, gP[j]);
        if (j >= 2) dm -= dotAt(j - 1, gP[j]);
        psi -= dm;
    }
}

[[gnu::always_inline]] inline D4 dotRows(const D4* a, const D4* b, int N) {
    D4 s{};
    for (int r = 0; r < N; ++r) s += a[r] * b[r];
    return s;
}

}  // namespace

HP_ROD_LANES_CLONES int holonomyIterate(RodScratch& sc, int n, const bool curled[kLanes]) {
    const int N = 3 * (n - 1);
    for (auto* v : {&sc.r, &sc.z, &sc.p, &sc.ap}) v->resize(size_t(N));
    sc.q.resize(size_t(3 * n));
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
    applySystem(sc, n, x, ap, q);
    for (int i = 0; i < N; ++i) r[i] = b[i] - ap[i];
    const D4 tol = 1e-10 * dotRows(b, b, N);  // |r|² ≤ 10⁻¹⁰|b|²: |r| ≤ 10⁻⁵|C|
    M4 active = {curled[0] ? -1 : 0, curled[1] ? -1 : 0, curled[2] ? -1 : 0, curled[3] ? -1 : 0};
    active &= dotRows(r, r, N) > tol;
    for (int i = 0; i < N; ++i) z[i] = r[i];
    bandedSubstitute(band, invD, z, N);
    for (int i = 0; i < N; ++i) p[i] = z[i];
    D4 rz = dotRows(r, z, N);
    int iterations = 0;
    for (int it = 0; it < 100; ++it) {
        bool any = false;
        for (int l = 0; l < kLanes; ++l) {
            any = any || active[l] != 0;
            iterations += active[l] != 0 ? 1 : 0;
        }
        if (!any) break;
        applySystem(sc, n, p, ap, q);
        const D4 a = rz / dotRows(p, ap, N);
        for (int i = 0; i < N; ++i) {
            x[i] = pick(active, x[i] + a * p[i], x[i]);
            r[i] = pick(active, r[i] - a * ap[i], r[i]);
        }
        active &= dotRows(r, r, N) > tol;
        bool more = false;
        for (int l = 0; l < kLanes; ++l) more = more || active[l] != 0;
        if (!more) break;  // (the next direction would go unused)
        for (int i = 0; i < N; ++i) z[i] = r[i];
        bandedSubstitute(band, invD, z, N);
        const D4 rz2 = dotRows(r, z, N);
        const D4 beta = rz2 / rz;
        for (int i = 0; i < N; ++i) p[i] = pick(active, z[i] + beta * p[i], p[i]);
        rz = pick(active, rz2, rz);
    }
    return iterations;
}

}  // namespace hp::rod
