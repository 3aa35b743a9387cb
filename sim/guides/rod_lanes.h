// Arithmetic of the rod kernels written once for two lane types: `float`
// (one strand) and `F4` (four strands side by side in one SIMD register,
// GCC/Clang vector extensions). A strand's step is a long chain of
// dependent operations (square roots and divisions along the strand, each
// joint's frame waiting on its parent's); lanes run four such chains for the
// price of one.
//
// Bit for bit: every operation here is the one Eigen performs for the same
// expression on Vector3f (a sum of three products as x0 + (x1 + x2), its
// redux order; cross as in Eigen's OrthoMethods; normalized() dividing by the
// root), and a vector lane computes exactly what the scalar does (IEEE add,
// multiply, divide and square root, no fused multiply-add on the x86-64
// baseline). So a strand's result does not depend on its lane, on how strands
// are batched, or on the thread count, and matches the scalar kernels.
#pragma once

// HP_ROD_LANES_CLONES: a function built twice, for the x86-64 baseline
// (SSE2: a D4 takes two instructions) and for AVX2 (one), the loader picking
// the one the processor runs (GCC function multi-versioning). The results
// are the same bit for bit: AVX2 adds wider registers, not other arithmetic
// (no fused multiply-add: that is the separate FMA extension, not enabled).
// Not under AddressSanitizer: an ifunc resolver can run before the
// sanitizer's runtime is up, and the baseline clone gives the same bits.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
#define HP_ROD_LANES_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define HP_ROD_LANES_CLONES
#endif

#include <cmath>
#include <vector>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

// D4 is 32 bytes: GCC notes that passing it by value would change the ABI
// between SSE and AVX builds. Everything here is inline, inside one library,
// so no such call crosses a boundary.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

namespace hp::rod::lanes {

typedef float F4 __attribute__((vector_size(16)));   ///< four strands' floats
/// Four strands' doubles. Aligned to 16 bytes, not the vector's natural 32:
/// they live in D4Store vectors (16-byte aligned), which code built for AVX
/// (rod_step.cpp's clones) then reads with unaligned loads; may_alias
/// because they view that storage.
typedef double D4 __attribute__((vector_size(32), aligned(16), may_alias));
/// Storage for D4 in containers (a template argument drops a typedef's
/// attributes, so std::vector<D4> would not be the D4 above).
struct alignas(16) D4Store {
    double v[4];
};
inline D4* view(std::vector<D4Store>& s) { return reinterpret_cast<D4*>(s.data()); }

template <class T>
inline T splat(float v) {
    return T{} + v;
}

inline float sqrtOf(float v) { return std::sqrt(v); }
inline F4 sqrtOf(F4 v) {
#if defined(__SSE2__)
    return F4(_mm_sqrt_ps(__m128(v)));
#else
    return F4{std::sqrt(v[0]), std::sqrt(v[1]), std::sqrt(v[2]), std::sqrt(v[3])};
#endif
}
/// Exact float → double and double → float (rounding) per lane.
inline D4 widen(F4 v) { return __builtin_convertvector(v, D4); }
inline F4 narrow(D4 v) { return __builtin_convertvector(v, F4); }

/// A 3-vector of lanes.
template <class T>
struct V3 {
    T x, y, z;
};

template <class T>
inline V3<T> operator+(const V3<T>& a, const V3<T>& b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class T>
inline V3<T> operator-(const V3<T>& a, const V3<T>& b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T>
inline V3<T> operator-(const V3<T>& a) {
    return {-a.x, -a.y, -a.z};
}
template <class T, class S>
inline V3<T> operator*(const S& s, const V3<T>& a) {
    return {s * a.x, s * a.y, s * a.z};
}
template <class T, class S>
inline V3<T> operator/(const V3<T>& a, const S& s) {
    return {a.x / s, a.y / s, a.z / s};
}
/// Eigen's redux order for three terms: x0 + (x1 + x2).
template <class T>
inline T dot(const V3<T>& a, const V3<T>& b) {
    return a.x * b.x + (a.y * b.y + a.z * b.z);
}
template <class T>
inline V3<T> cross(const V3<T>& a, const V3<T>& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
inline T norm(const V3<T>& a) {
    return sqrtOf(dot(a, a));
}
/// Per lane: m ? a : b (m a bool for float, a lane mask for F4).
template <class M, class T>
inline T select(const M& m, const T& a, const T& b) {
    return m ? a : b;
}
template <class M, class T>
inline V3<T> select(const M& m, const V3<T>& a, const V3<T>& b) {
    return {m ? a.x : b.x, m ? a.y : b.y, m ? a.z : b.z};
}
/// Eigen's normalized(): a / |a|, or a itself when |a|² is not positive.
template <class T>
inline V3<T> normalized(const V3<T>& a) {
    const T z = dot(a, a);
    return select(z > 0.f, a / sqrtOf(z), a);
}

/// The bending constraint of one joint (rod::bendConstraint, whose comment
/// gives the equations), for any lane type. Writes C's two rows into C and
/// their gradients into g[row][slot] (slots: vertices j-1, j, j+1; slot 0 is
/// left alone at the ghost joint).
template <class T>
inline void bendRows(const V3<T>& u, const T& parentLen, const V3<T>& e, const V3<T>& a, const T c[2], bool ghost,
                     T C[2], V3<T> g[2][3]) {
    const T len = norm(e);
    const V3<T> d = e / len;
    const T cosTurn = 1.f + dot(u, d);
    const T denom = select(cosTurn < 1e-4f, splat<T>(1e-4f), cosTurn);  // std::max(cosTurn, 1e-4f)
    const V3<T> kb = cross(u, d);
    const V3<T> kbv = (2.f * kb) / denom;
    const V3<T> axes[2] = {a, cross(u, a)};
    for (int k = 0; k < 2; ++k) {
        const V3<T>& ax = axes[k];
        const T kbAx = dot(kbv, ax);
        C[k] = kbAx - c[k];
        const V3<T> td = ((-2.f) * cross(u, ax) - kbAx * u) / denom;
        const V3<T> gd = (td - dot(d, td) * d) / len;
        g[k][2] = gd;
        if (ghost) {
            g[k][1] = -gd;
        } else {
            const V3<T> tu = (2.f * cross(d, ax) - kbAx * d) / denom;
            const V3<T> gu = (tu - dot(u, tu) * u) / parentLen;
            g[k][1] = gu - gd;
            g[k][0] = -gu;
        }
    }
}

/// The transported frame's step from a joint to the next (rod_kernels.cpp's
/// forJoints): the parent direction u becomes d = e/|e| (u when e is null),
/// the frame vector a is carried by parallel transport unless the segment
/// folds back (1 + u·d ≤ 1e-4), then re-orthonormalised against d in float.
template <class T>
inline void advanceFrame(V3<T>& u, T& ulen, V3<T>& a, const V3<T>& e) {
    const T len = norm(e);
    const V3<T> d = select(len > 0.f, e / len, u);
    const T cosTurn = 1.f + dot(u, d);
    // Parallel transport of a ⊥ u onto d: a - (d·a)/(1 + u·d) · (u + d)
    const V3<T> moved = a - (dot(d, a) / cosTurn) * (u + d);
    a = select(cosTurn > 1e-4f, moved, a);
    a = normalized(a - dot(a, d) * d);
    u = d;
    ulen = len;
}

}  // namespace hp::rod::lanes

#pragma GCC diagnostic pop
