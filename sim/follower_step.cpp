// The per-step work of the followers that scales with their number: the
// guide-pair tables, then every follower's shape, head collision and output
// (sim/followers.h explains the model, sim/follower_kernels.h has the
// equations, sim/follower_update.cpp the step around it).
//
// Performance (100k followers × 24 vertices: ~2.3M segments per step):
// - Everything that depends only on a follower's two guides is computed once
//   per guide pair and segment (slerp arc θ, e and the quadratic form (2) of
//   the guide's rotated rest direction), a few thousand pairs against 100k
//   followers. Per segment a follower then evaluates its weight t (hash,
//   Algorithm 1), sin and cos of tθ (polynomials), (2) and its root frame:
//   about 40 vector operations for 8 segments.
// - A follower's segments run 8 at a time in vector lanes (slots, see
//   FollowerClass); the positions are a prefix sum across lanes, the output
//   an interleave of the x, y, z lanes; no per-segment scalar work.
// - Collision: one vector test per 8 vertices against guide 1's bound
//   (collisionBound); only followers with a vertex that fails it take the
//   sequential follow-the-leader loop, from that vertex on.
// - Built twice, for x86-64-v3 (AVX2 + FMA) and baseline x86-64, picked at
//   load time. Multiply-adds contract into FMA in the v3 build
//   (-ffp-contract=fast on this file), so the two builds differ in the last
//   bits; within one machine every follower runs the same code whatever the
//   thread count or partition, which is the determinism the project needs.
#include "core/errors.h"
#include "sim/follower_simd.h"
#include "sim/follower_state.h"

#include <cmath>

namespace hp::follower {

namespace {

using namespace simd;
using Impl = Followers::Impl;

template <bool Own>
[[gnu::always_inline]] inline void buildPairRows(const Impl& im, FollowerClass& c, size_t begin, size_t end) {
    const size_t P = c.pad;
    const float maxVelocity = im.settings.maxVelocity;
    for (size_t p = begin; p < end; ++p) {
        const GuidePair& gp = c.pairs[p];
        // One pointer per row: the loop below then reads and writes
        // contiguous rows and vectorizes over the slots.
        const float* h1 = c.hot.data() + size_t(gp.guide1) * FollowerClass::kHot * P;
        const float* h2 = c.hot.data() + size_t(gp.guide2) * FollowerClass::kHot * P;
        const float* __restrict aW = h1;
        const float* __restrict aX = h1 + P;
        const float* __restrict aY = h1 + 2 * P;
        const float* __restrict aZ = h1 + 3 * P;
        const float* __restrict speed = h1 + 4 * P;
        const float* __restrict fX = h1 + 5 * P;
        const float* __restrict fY = h1 + 6 * P;
        const float* __restrict fZ = h1 + 7 * P;
        const float* __restrict bW = h2;
        const float* __restrict bX = h2 + P;
        const float* __restrict bY = h2 + 2 * P;
        const float* __restrict bZ = h2 + 3 * P;
        float* const row = c.pairTable.data() + p * FollowerClass::kPair * P;
        float* __restrict o0 = row;
        float* __restrict o1 = row + P;
        float* __restrict o2 = row + 2 * P;
        float* __restrict o3 = row + 3 * P;
        float* __restrict o4 = row + 4 * P;
        float* __restrict o5 = row + 5 * P;
        float* __restrict o6 = row + 6 * P;
        float* __restrict o7 = row + 7 * P;
        float* __restrict o8 = row + 8 * P;
        float* __restrict o9 = row + 9 * P;
        float* __restrict o10 = row + 10 * P;
        const float kc = gp.twistC, ks = gp.twistS;
        // Rows never overlap; restrict alone does not tell GCC once inlined here.
#pragma GCC ivdep
        for (size_t j = 0; j < P; ++j) {
            const Quat a{aW[j], aX[j], aY[j], aZ[j]};
            // Guide 2's rotation turned into guide 1's frame: K q2 K⁻¹, K about y.
            const Quat b{bW[j], kc * bX[j] + ks * bZ[j], bY[j], -ks * bX[j] + kc * bZ[j]};
            float theta;
            Quat e;
            slerpArc(a, b, theta, e);
            o0[j] = theta;
            o1[j] = variableOffset(speed[j], maxVelocity);
            if constexpr (Own) {
                o2[j] = a.w;
                o3[j] = a.x;
                o4[j] = a.y;
                o5[j] = a.z;
                o6[j] = e.w;
                o7[j] = e.x;
                o8[j] = e.y;
                o9[j] = e.z;
            } else {
                Eigen::Vector3f A, BminusA, D;
                slerpedDirection(a, e, Eigen::Vector3f(fX[j], fY[j], fZ[j]), A, BminusA, D);
                o2[j] = A.x();
                o3[j] = A.y();
                o4[j] = A.z();
                o5[j] = BminusA.x();
                o6[j] = BminusA.y();
                o7[j] = BminusA.z();
                o8[j] = D.x();
                o9[j] = D.y();
                o10[j] = D.z();
            }
        }
    }
}

HP_SIMD bool anyLane(i8 m) {
    uint64_t q[4];
    std::memcpy(q, &m, sizeof q);
    return (q[0] | q[1] | q[2] | q[3]) != 0;
}

/// Follow the leader (positions px/py/pz, slots = vertices): a vertex the
/// bound cannot clear is queried; one inside is projected out keeping its
/// segment's length, and every later vertex moves by the same shift, so
/// segment directions are kept elsewhere. `cleared[v]` is the vector pass's
/// bound test of the unshifted vertex, valid until the first projection;
/// after it, shifted vertices are tested again.
void collide(const StepContext& ctx, const FollowerClass& c, const float* g1, const int32_t* cleared,
             const float* segmentLengths, float segmentLength, float* px, float* py, float* pz, Counters& counters) {
    const size_t P = c.pad;
    float sx = 0.f, sy = 0.f, sz = 0.f;
    bool shifted = false;
    for (uint32_t v = 1; v <= c.segments; ++v) {
        if (!shifted && cleared[v]) continue;
        const float qx = px[v] + sx, qy = py[v] + sy, qz = pz[v] + sz;
        const float gx = qx - g1[v], gy = qy - g1[P + v], gz = qz - g1[2 * P + v];
        if (!shifted || !(gx * gx + gy * gy + gz * gz < g1[3 * P + v])) {
            ++counters.queries;
            Vec3f p(qx, qy, qz), normal;
            const float d = ctx.collider->signedDistance(p, &normal);
            if (d < c.radii[v]) {
                const Vec3f previous(px[v - 1], py[v - 1], pz[v - 1]);
                const float length = segmentLengths ? segmentLengths[v] : segmentLength;
                projectSegmentOut(*ctx.collider, previous, length, c.radii[v], d, normal, p);
                sx += p.x() - qx;
                sy += p.y() - qy;
                sz += p.z() - qz;
                shifted = true;
                ++counters.projected;
            }
        }
        if (shifted) {
            px[v] += sx;
            py[v] += sy;
            pz[v] += sz;
        }
    }
}

template <FollowerMode M, bool Own>
[[gnu::always_inline]] inline void processFollower(const StepContext& ctx, uint32_t f, Counters& counters) {
    const Impl& im = *ctx.im;
    const FollowerClass& c = im.classes[im.classOf[f]];
    const size_t P = c.pad;
    const uint32_t S = c.segments;
    const float* __restrict T = c.pairTable.data() + size_t(im.pairOf[f]) * FollowerClass::kPair * P;
    const float* __restrict own = Own ? im.ownRestData.data() + im.ownRest[f] : nullptr;
    const FollowerNeighbours& nb = im.neighbours[f];
    const float* g1 = c.cold.data() + size_t(nb.guide1) * FollowerClass::kCold * P;

    // Effective root frame E = [t', n, z']: the current frame, orthonormalised,
    // turned about n by the rest twist toward guide 1 (see followers.h);
    // times the segment length for followers with the guides' rest shape.
    const SurfaceFrame& root = ctx.roots[f];
    const Vec3f n = root.normal / root.normal.norm();
    Vec3f t = root.tangent - n * n.dot(root.tangent);
    t /= t.norm();
    const Vec3f z = t.cross(n);
    const float ac = im.alignC[f], as = im.alignS[f], scale = Own ? 1.f : im.segmentLength[f];
    const Vec3f e0 = scale * (ac * t - as * z), e1 = scale * n, e2 = scale * (as * t + ac * z);
    const f8 m00 = splat(e0.x()), m01 = splat(e1.x()), m02 = splat(e2.x());
    const f8 m10 = splat(e0.y()), m11 = splat(e1.y()), m12 = splat(e2.y());
    const f8 m20 = splat(e0.z()), m21 = splat(e1.z()), m22 = splat(e2.z());

    alignas(32) float px[kMaxFollowerVertices], py[kMaxFollowerVertices], pz[kMaxFollowerVertices],
        w[kMaxFollowerVertices];
    alignas(32) int32_t cleared[kMaxFollowerVertices];
    f8 carryX = splat(root.position.x()), carryY = splat(root.position.y()), carryZ = splat(root.position.z());
    const u8 hash = splat(followerHash(im.settings.seed, f));
    const f8 weight = splat(im.weight[f]);
    i8 outside = i8{} - 1;
    for (size_t j = 0; j < P; j += 8) {
        // Slerp weight t (Algorithm 1: d_r = fixedOffset d_f + rand_xy d_v),
        // then sin and cos of φ = tθ.
        f8 s{}, co = splat(1.f), tw{};
        if constexpr (M != FollowerMode::Cluster) {
            if constexpr (M == FollowerMode::Interpolate) {
                tw = weight;
            } else {
                const u8 y = u8{0u - 1u, 0, 1, 2, 3, 4, 5, 6} + uint32_t(j);  // segment j - 1
                tw = load(c.weightedCurve.data() + j) + toSignedUnit(segmentHash(hash, y)) * load(T + P + j);
            }
            sinCos(reduceHalfTurns(tw * load(T + j)), s, co);
        }
        store(w + j, tw);
        // Rotated rest direction in guide 1's root frame.
        f8 vx, vy, vz;
        if constexpr (!Own) {
            vx = load(T + 2 * P + j);
            vy = load(T + 3 * P + j);
            vz = load(T + 4 * P + j);
            if constexpr (M != FollowerMode::Cluster) {  // (2): A + s² (B - A) + cs D
                const f8 ss = s * s, cs = co * s;
                vx += ss * load(T + 5 * P + j) + cs * load(T + 8 * P + j);
                vy += ss * load(T + 6 * P + j) + cs * load(T + 9 * P + j);
                vz += ss * load(T + 7 * P + j) + cs * load(T + 10 * P + j);
            }
        } else {  // (1): q = cos φ a + sin φ e, then q f q*
            f8 q[4];
            for (int k = 0; k < 4; ++k)
                q[k] = co * load(T + (2 + k) * P + j) + s * load(T + (6 + k) * P + j);
            rotate(q[0], q[1], q[2], q[3], load(own + j), load(own + P + j), load(own + 2 * P + j), vx, vy, vz);
        }
        // World space, then positions: a running sum from the root.
        const f8 wx = m00 * vx + m01 * vy + m02 * vz;
        const f8 wy = m10 * vx + m11 * vy + m12 * vz;
        const f8 wz = m20 * vx + m21 * vy + m22 * vz;
        const f8 x = prefixSum(wx, carryX), y = prefixSum(wy, carryY), zz = prefixSum(wz, carryZ);
        store(px + j, x);
        store(py + j, y);
        store(pz + j, zz);
        if (ctx.collider) {
            const f8 dx = x - load(g1 + j), dy = y - load(g1 + P + j), dz = zz - load(g1 + 2 * P + j);
            const i8 ok = dx * dx + dy * dy + dz * dz < load(g1 + 3 * P + j);
            std::memcpy(cleared + j, &ok, sizeof ok);
            outside &= ok;
        }
    }
    if (ctx.collider && anyLane(~outside)) {
        float lengths[kMaxFollowerVertices];
        if constexpr (Own)
            for (uint32_t v = 1; v <= S; ++v)
                lengths[v] = std::sqrt(own[v] * own[v] + own[P + v] * own[P + v] + own[2 * P + v] * own[2 * P + v]);
        collide(ctx, c, g1, cleared, Own ? lengths : nullptr, im.segmentLength[f], px, py, pz, counters);
    }

    // Output: x y z per vertex, with velocities; 8 vertices (24 floats) a block.
    float* __restrict pos = ctx.positions[0].data() + 3 * size_t(im.vertexOffset[f]);
    float* __restrict vel = ctx.velocities[0].data() + 3 * size_t(im.vertexOffset[f]);
    const size_t n3 = 3 * size_t(S + 1);
    const f8 invDt = splat(ctx.invDt);
    for (size_t j = 0; 3 * j < n3; j += 8) {
        f8 xyz[3];
        interleave3(load(px + j), load(py + j), load(pz + j), xyz);
        float* __restrict p = pos + 3 * j;
        float* __restrict u = vel + 3 * j;
        if (3 * j + 24 <= n3) {
            for (int k = 0; k < 3; ++k) {
                if (ctx.difference) store(u + 8 * k, (xyz[k] - load(p + 8 * k)) * invDt);
                store(p + 8 * k, xyz[k]);
            }
        } else {  // the strand's last, partial block
            const float* x = reinterpret_cast<const float*>(xyz);
            for (size_t r = 0; r < n3 - 3 * j; ++r) {
                if (ctx.difference) u[r] = (x[r] - p[r]) * ctx.invDt;
                p[r] = x[r];
            }
        }
    }
    if (!ctx.difference) {
        // No previous positions: the slerp-weighted blend of the guides' vertex velocities.
        const float* g2 = c.cold.data() + size_t(nb.guide2) * FollowerClass::kCold * P;
        for (uint32_t v = 0; v <= S; ++v) {
            const float b = w[v > 0 ? v : 1];
            for (int k = 0; k < 3; ++k) vel[3 * v + k] = (1.f - b) * g1[(4 + k) * P + v] + b * g2[(4 + k) * P + v];
        }
    }
}

template <FollowerMode M, bool Own>
[[gnu::always_inline]] inline void processRangeT(const StepContext& ctx, size_t begin, size_t end, Counters& counters) {
    const uint32_t* order = ctx.im->order.data();
    for (size_t i = begin; i < end; ++i) processFollower<M, Own>(ctx, order[i], counters);
}

[[gnu::target_clones("arch=x86-64-v3", "default")]] void processRange(const StepContext& ctx, size_t begin,
                                                                      size_t end, Counters& counters) {
    const bool own = !ctx.im->ownRestData.empty();
    switch (ctx.im->settings.mode) {
        case FollowerMode::Cluster:
            return own ? processRangeT<FollowerMode::Cluster, true>(ctx, begin, end, counters)
                       : processRangeT<FollowerMode::Cluster, false>(ctx, begin, end, counters);
        case FollowerMode::Interpolate:
            return own ? processRangeT<FollowerMode::Interpolate, true>(ctx, begin, end, counters)
                       : processRangeT<FollowerMode::Interpolate, false>(ctx, begin, end, counters);
        case FollowerMode::Varied:
            return own ? processRangeT<FollowerMode::Varied, true>(ctx, begin, end, counters)
                       : processRangeT<FollowerMode::Varied, false>(ctx, begin, end, counters);
    }
}

[[gnu::target_clones("arch=x86-64-v3", "default")]] void pairRange(const Impl& im, FollowerClass& c, size_t begin,
                                                                   size_t end) {
    if (im.ownRestData.empty()) buildPairRows<false>(im, c, begin, end);
    else buildPairRows<true>(im, c, begin, end);
}

}  // namespace

void buildPairs(const Impl& im, FollowerClass& c, size_t begin, size_t end) { pairRange(im, c, begin, end); }

void processFollowers(const StepContext& ctx, size_t begin, size_t end, Counters& counters) {
    processRange(ctx, begin, end, counters);
}

}  // namespace hp::follower
