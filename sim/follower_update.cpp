// The per-step part of the followers: guide rotation tables, then every
// follower rebuilt from its own root frame (sim/followers.h explains the model,
// sim/follower_kernels.h has the equations).
//
// Performance notes: the work is ~F × S segment updates (100k × 23 = 2.3M per
// step), each a slerp, a rotation and a frame change. Each follower's segments
// are computed in one loop over segment index y whose arrays are contiguous
// rows of per-guide tables (no gathers), so it vectorizes; the loop is built
// twice (AVX2 and baseline x86-64) and picked at load time. Positions are
// then a running sum along the strand (sequential, three adds per vertex),
// written straight into the output frame. Nothing is allocated per step.
#include "sim/followers.h"

#include "core/errors.h"
#include "sim/follower_kernels.h"
#include "sim/follower_state.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>

namespace hp {

namespace {

using Impl = Followers::Impl;

struct StepContext {
    const Impl* im;
    const SurfaceFrame* roots;
    const Collider* collider;  ///< null: no collision
    Vec3f* positions;          ///< the follower block of the output
    Vec3f* velocities;
    bool difference;           ///< finite-difference velocities
    float invDt;
};

struct Counters {
    size_t projected = 0, queries = 0;
};

/// Unit segment directions of follower f scaled by the segment lengths,
/// world space, into dx/dy/dz; the slerp weight of each segment into w
/// (not written in cluster mode, where it is 0).
template <FollowerMode M, bool Own>
[[gnu::always_inline]] inline void followerSegments(const Impl& im, const FollowerClass& c, uint32_t f,
                                                    const SurfaceFrame& root, float* __restrict dx,
                                                    float* __restrict dy, float* __restrict dz,
                                                    float* __restrict w) {
    // One pointer per table row, indexed by a size_t: with 32-bit index
    // arithmetic (k * P + y) the compiler must allow for wrap-around and
    // falls back to gathering element by element.
    const size_t P = c.pad;
    const FollowerNeighbours& nb = im.neighbours[f];
    const float* h1 = c.hot.data() + size_t(nb.guide1) * FollowerClass::kHot * P;
    const float* h2 = c.hot.data() + size_t(nb.guide2) * FollowerClass::kHot * P;
    const float* __restrict aW = h1;
    const float* __restrict aX = h1 + P;
    const float* __restrict aY = h1 + 2 * P;
    const float* __restrict aZ = h1 + 3 * P;
    const float* __restrict speed1 = h1 + 4 * P;
    const float* __restrict bW = h2;
    const float* __restrict bX = h2 + P;
    const float* __restrict bY = h2 + 2 * P;
    const float* __restrict bZ = h2 + 3 * P;
    const float* own = Own ? im.ownRestData.data() + im.ownRest[f] : h1 + 5 * P;
    const float* __restrict restX = own;
    const float* __restrict restY = own + P;
    const float* __restrict restZ = own + 2 * P;
    const float* __restrict restLength = Own ? own + 3 * P : nullptr;
    const float* __restrict df = c.df.data();

    // Effective root frame E = [t', n, z']: the current frame turned by the
    // rest twist toward guide 1 (see followers.h).
    const Vec3f& t = root.tangent;
    const Vec3f& n = root.normal;
    const Vec3f z = t.cross(n);
    const float ac = im.alignC[f], as = im.alignS[f];
    const float tx = ac * t.x() - as * z.x(), ty = ac * t.y() - as * z.y(), tz = ac * t.z() - as * z.z();
    const float zx = as * t.x() + ac * z.x(), zy = as * t.y() + ac * z.y(), zz = as * t.z() + ac * z.z();
    const float nx = n.x(), ny = n.y(), nz = n.z();
    const float kc = im.twistC[f], ks = im.twistS[f];
    const float wInterp = im.weight[f];
    const float fixedOffset = im.settings.fixedOffset, maxVelocity = im.settings.maxVelocity;
    const uint32_t hash = follower::followerHash(im.settings.seed, f);
    const float length = im.segmentLength[f];

    for (size_t y = 0; y < P; ++y) {
        const float aw = aW[y], ax = aX[y], ay = aY[y], az = aZ[y];
        float qw = aw, qx = ax, qy = ay, qz = az, weight = 0.f;
        if constexpr (M != FollowerMode::Cluster) {
            // Guide 2's rotation turned into guide 1's frame: K q2 K⁻¹, K about y.
            const float bw = bW[y], by = bY[y];
            const float bx = kc * bX[y] + ks * bZ[y];
            const float bz = -ks * bX[y] + kc * bZ[y];
            if constexpr (M == FollowerMode::Interpolate) {
                weight = wInterp;
            } else {
                const float dv = follower::variableOffset(speed1[y], maxVelocity);
                weight = follower::variedWeight(fixedOffset, df[y], follower::segmentRandom(hash, uint32_t(y)), dv);
            }
            float c0, c1;
            follower::slerpWeights(aw * bw + ax * bx + ay * by + az * bz, weight, c0, c1);
            qw = c0 * aw + c1 * bw;
            qx = c0 * ax + c1 * bx;
            qy = c0 * ay + c1 * by;
            qz = c0 * az + c1 * bz;
        }
        const float rx = restX[y], ry = restY[y], rz = restZ[y];
        float lx, ly, lz;
        follower::rotate(qw, qx, qy, qz, rx, ry, rz, lx, ly, lz);
        const float wx = tx * lx + nx * ly + zx * lz;
        const float wy = ty * lx + ny * ly + zy * lz;
        const float wz = tz * lx + nz * ly + zz * lz;
        // Renormalise: slerp's series and float rounding leave |q| = 1 ± 1e-6;
        // segment lengths come out exact to float precision.
        const float scale = (Own ? restLength[y] : length) / std::sqrt(wx * wx + wy * wy + wz * wz);
        dx[y] = wx * scale;
        dy[y] = wy * scale;
        dz[y] = wz * scale;
        if constexpr (M != FollowerMode::Cluster) w[y] = weight;
    }
}

template <FollowerMode M, bool Own>
[[gnu::always_inline]] inline void processFollower(const StepContext& ctx, uint32_t f, Counters& counters) {
    const Impl& im = *ctx.im;
    const FollowerClass& c = im.classes[im.classOf[f]];
    alignas(32) float dx[kMaxFollowerVertices], dy[kMaxFollowerVertices], dz[kMaxFollowerVertices],
        w[kMaxFollowerVertices];
    const SurfaceFrame& root = ctx.roots[f];
    followerSegments<M, Own>(im, c, f, root, dx, dy, dz, w);

    // Vertices: a running sum from the root, into a local buffer laid out
    // like the output (x y z per vertex).
    const uint32_t S = c.segments, n3 = 3 * (S + 1);
    alignas(32) float x[3 * kMaxFollowerVertices];
    float px = root.position.x(), py = root.position.y(), pz = root.position.z();
    x[0] = px;
    x[1] = py;
    x[2] = pz;
    for (uint32_t v = 1; v <= S; ++v) {
        px += dx[v - 1];
        py += dy[v - 1];
        pz += dz[v - 1];
        x[3 * v] = px;
        x[3 * v + 1] = py;
        x[3 * v + 2] = pz;
    }

    const FollowerNeighbours& nb = im.neighbours[f];
    const float* cold1 = c.cold.data() + size_t(nb.guide1) * (S + 1) * FollowerClass::kCold;
    if (ctx.collider) {
        // Follow the leader: a vertex pushed out moves every later vertex by
        // the same amount (`shift`), so segment directions are kept elsewhere.
        // Scalars in registers on the common path; a Vec3f only for queries
        // (an address-taken vector made every vertex a store-forwarding stall).
        const float rootRadius = c.radii[0];
        float sx = 0.f, sy = 0.f, sz = 0.f;
        bool shifted = false;
        for (uint32_t v = 1; v <= S; ++v) {
            const float* g1 = cold1 + v * FollowerClass::kCold;
            const float qx = x[3 * v] + sx, qy = x[3 * v + 1] + sy, qz = x[3 * v + 2] + sz;
            // The distance is 1-Lipschitz: a vertex closer to guide 1's vertex
            // than that vertex's clearance is outside; skip the query.
            const float clear = g1[3] - rootRadius;
            const float gx = qx - g1[0], gy = qy - g1[1], gz = qz - g1[2];
            if (!(clear > 0.f && gx * gx + gy * gy + gz * gz < clear * clear)) {
                ++counters.queries;
                Vec3f p(qx, qy, qz), normal;
                const float d = ctx.collider->signedDistance(p, &normal);
                if (d < c.radii[v]) {
                    const Vec3f previous(x[3 * v - 3], x[3 * v - 2], x[3 * v - 1]);
                    const float length = std::sqrt(dx[v - 1] * dx[v - 1] + dy[v - 1] * dy[v - 1] + dz[v - 1] * dz[v - 1]);
                    follower::projectSegmentOut(*ctx.collider, previous, length, c.radii[v], d, normal, p);
                    sx += p.x() - qx;
                    sy += p.y() - qy;
                    sz += p.z() - qz;
                    shifted = true;
                    ++counters.projected;
                }
            }
            if (shifted) {
                x[3 * v] = x[3 * v] + sx;
                x[3 * v + 1] = x[3 * v + 1] + sy;
                x[3 * v + 2] = x[3 * v + 2] + sz;
            }
        }
    }

    float* __restrict pos = ctx.positions[0].data() + 3 * size_t(im.vertexOffset[f]);
    float* __restrict vel = ctx.velocities[0].data() + 3 * size_t(im.vertexOffset[f]);
    if (ctx.difference) {
        const float invDt = ctx.invDt;
        for (uint32_t i = 0; i < n3; ++i) {
            vel[i] = (x[i] - pos[i]) * invDt;
            pos[i] = x[i];
        }
    } else {
        const float* cold2 = c.cold.data() + size_t(nb.guide2) * (S + 1) * FollowerClass::kCold;
        for (uint32_t v = 0; v <= S; ++v) {
            const float* g1 = cold1 + v * FollowerClass::kCold;
            const float* g2 = cold2 + v * FollowerClass::kCold;
            const float b = M == FollowerMode::Cluster ? 0.f : w[v > 0 ? v - 1 : 0];
            for (int k = 0; k < 3; ++k) vel[3 * v + k] = (1.f - b) * g1[4 + k] + b * g2[4 + k];
        }
        for (uint32_t i = 0; i < n3; ++i) pos[i] = x[i];
    }
}

template <FollowerMode M, bool Own>
[[gnu::always_inline]] inline void processRangeT(const StepContext& ctx, size_t begin, size_t end, Counters& counters) {
    const uint32_t* order = ctx.im->order.data();
    for (size_t i = begin; i < end; ++i) processFollower<M, Own>(ctx, order[i], counters);
}

// Two builds of the follower loop, chosen once by the loader (GCC ifunc):
// AVX2 (8 floats per instruction) and baseline x86-64 (SSE2, 4). Only the ISA
// differs ("arch=haswell" would also allow FMA contraction but then GCC will
// not inline the default-target kernels into it); without FMA both builds
// round identically, so results are the same bits on any x86-64 machine and
// any thread count.
[[gnu::target_clones("avx2", "default")]] void processRange(const StepContext& ctx, size_t begin, size_t end,
                                                                      Counters& counters) {
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

/// Rotations, speeds and vertices of guide g this step, resampled into every class's rows.
void fillGuide(Impl& im, const FollowerStep& step, const Collider* collider, size_t g) {
    const StrandFrame& guides = step.guides;
    const uint32_t first = guides.offsets[g], count = guides.offsets[g + 1] - first;
    const uint32_t segOffset = im.guideSegmentOffsets[g];
    const uint32_t gs = im.guideSegmentOffsets[g + 1] - segOffset;
    if (count != gs + 1)
        throw Error(cat("followers: guide ", g, " has ", count, " vertices in this step but ", gs + 1,
                        " in the groom"));
    const Vec3f* x = guides.positions.data() + first;
    const Vec3f* v = guides.velocities.empty() ? nullptr : guides.velocities.data() + first;

    const SurfaceFrame& rf = step.guideRoots[g];
    const Vec3f n = rf.normal.normalized();
    const Vec3f t = (rf.tangent - n * n.dot(rf.tangent)).normalized();
    const Vec3f z = t.cross(n);
    if (!t.allFinite() || !n.allFinite()) throw Error(cat("followers: guide ", g, " has a degenerate root frame"));

    float q[kMaxFollowerVertices][4], speed[kMaxFollowerVertices], clearance[kMaxFollowerVertices + 1];
    // NaN or infinity anywhere makes the sum non-finite: one test per guide.
    float sum = 0.f;
    for (uint32_t k = 0; k <= gs; ++k) sum += x[k].x() + x[k].y() + x[k].z();
    if (!std::isfinite(sum))
        for (uint32_t k = 0; k <= gs; ++k)
            if (!x[k].allFinite()) throw Error(cat("followers: guide ", g, " vertex ", k, " is not finite"));
    follower::Quat frame;
    Vec3f previous = Vec3f::UnitY();
    for (uint32_t y = 0; y < gs; ++y) {
        const Vec3f e = x[y + 1] - x[y];
        Vec3f d(t.dot(e), n.dot(e), z.dot(e));  // root-frame coordinates
        const float len2 = d.squaredNorm();
        d = len2 > 0.f ? Vec3f(d / std::sqrt(len2)) : previous;  // a collapsed segment keeps the last direction
        frame = follower::transportStep(frame, previous, d);
        previous = d;
        const follower::Quat r = follower::segmentRotation(frame, im.restInverse[segOffset + y]);
        q[y][0] = r.w;
        q[y][1] = r.x;
        q[y][2] = r.y;
        q[y][3] = r.z;
        speed[y] = v ? 0.5f * (v[y] + v[y + 1]).norm() : 0.f;
    }
    for (uint32_t k = 0; k <= gs; ++k)
        clearance[k] = collider ? collider->signedDistance(x[k]) : std::numeric_limits<float>::max();

    for (FollowerClass& c : im.classes) {
        const size_t P = c.pad;
        const uint32_t S = c.segments;
        float* row = c.hot.data() + g * FollowerClass::kHot * P;
        const bool same = S == gs;  // the usual case: no resampling
        for (uint32_t y = 0; y < S; ++y) {
            const uint32_t s = same ? y : FollowerClass::guideSegment(y, S, gs);
            for (int k = 0; k < 4; ++k) row[k * P + y] = q[s][k];
            row[4 * P + y] = speed[s];
        }
        float* cold = c.cold.data() + g * (S + 1) * FollowerClass::kCold;
        for (uint32_t k = 0; k <= S; ++k) {
            const uint32_t gv = same || k == 0 ? k : FollowerClass::guideSegment(k - 1, S, gs) + 1;
            float* o = cold + k * FollowerClass::kCold;
            o[0] = x[gv].x();
            o[1] = x[gv].y();
            o[2] = x[gv].z();
            o[3] = clearance[gv];
            o[4] = v ? v[gv].x() : 0.f;
            o[5] = v ? v[gv].y() : 0.f;
            o[6] = v ? v[gv].z() : 0.f;
        }
    }
}

template <typename T>
bool sameRange(const std::vector<T>& a, size_t aFrom, const std::vector<T>& b, size_t bFrom, size_t n, T bias = T()) {
    if (a.size() < aFrom + n || b.size() < bFrom + n) return false;
    for (size_t i = 0; i < n; ++i)
        if (a[aFrom + i] != b[bFrom + i] + bias) return false;
    return true;
}

}  // namespace

FollowerStats Followers::update(const FollowerStep& step, StrandFrame& out) {
    Impl& im = *impl_;
    const StrandFrame& guides = step.guides;
    const size_t G = im.guides, F = im.followers;
    if (guides.strandCount() < G)
        throw Error(cat("followers: the step has ", guides.strandCount(), " strands but the groom ", G, " guides"));
    if (step.guideRoots.size() != G)
        throw Error(cat("followers: ", step.guideRoots.size(), " guide root frames for ", G, " guides"));
    if (step.followerRoots.size() != F)
        throw Error(cat("followers: ", step.followerRoots.size(), " follower root frames for ", F, " followers"));
    const bool inPlace = &guides == &out;
    const uint32_t guideVertices = guides.offsets[G];
    if (guides.positions.size() < guideVertices || guides.radii.size() < guideVertices ||
        (!guides.velocities.empty() && guides.velocities.size() < guideVertices))
        throw Error("followers: the guide frame's vertex arrays are shorter than its offsets");
    const size_t total = size_t(guideVertices) + im.vertexOffset[F];
    if (total > 0xffffffffu) throw Error("followers: more than 2^32 vertices in one frame");

    // Does `out` hold this object's layout already (offsets, ids, radii)?
    const bool laidOut = out.guideCount == G && out.strandCount() == G + F && out.positions.size() == total &&
                         out.velocities.size() == total && out.radii.size() == total &&
                         (inPlace || sameRange(out.offsets, 0, guides.offsets, 0, G + 1)) &&
                         sameRange(out.offsets, G, im.vertexOffset, 0, F + 1, guideVertices) &&
                         sameRange(out.ids, G, im.ids, 0, F);
    FollowerStats stats;
    stats.differenceVelocities = laidOut && step.dt > 0.0 && out.positions.data() == im.lastPositions &&
                                 im.lastVertexCount == total;
    if (!laidOut) {
        stats.layoutWritten = true;
        // Keep the guide block, drop anything after it, append the followers.
        if (inPlace) {
            out.offsets.resize(G + 1);
            out.ids.resize(G);
            out.positions.resize(guideVertices);
            out.radii.resize(guideVertices);
            out.velocities.resize(guideVertices, Vec3f::Zero());
        } else {
            out.offsets.assign(guides.offsets.begin(), guides.offsets.begin() + G + 1);
            out.ids.assign(guides.ids.begin(), guides.ids.begin() + G);
        }
        out.guideCount = uint32_t(G);
        out.offsets.resize(G + F + 1);
        for (size_t f = 0; f <= F; ++f) out.offsets[G + f] = guideVertices + im.vertexOffset[f];
        out.ids.resize(G + F);
        std::copy(im.ids.begin(), im.ids.end(), out.ids.begin() + G);
        out.positions.resize(total);
        out.velocities.resize(total, Vec3f::Zero());
        out.radii.resize(total);
        for (size_t f = 0; f < F; ++f) {
            const FollowerClass& c = im.classes[im.classOf[f]];
            std::copy(c.radii.begin(), c.radii.end(), out.radii.begin() + guideVertices + im.vertexOffset[f]);
        }
    }
    if (!inPlace) {
        out.frame = guides.frame;
        out.time = guides.time;
        std::copy(guides.positions.begin(), guides.positions.begin() + guideVertices, out.positions.begin());
        std::copy(guides.radii.begin(), guides.radii.begin() + guideVertices, out.radii.begin());
        if (guides.velocities.empty()) std::fill(out.velocities.begin(), out.velocities.begin() + guideVertices, Vec3f::Zero());
        else std::copy(guides.velocities.begin(), guides.velocities.begin() + guideVertices, out.velocities.begin());
    }

    const Collider* collider = im.settings.collide ? step.collider : nullptr;
    auto guidesLoop = [&](const tbb::blocked_range<size_t>& r) {
        for (size_t g = r.begin(); g != r.end(); ++g) fillGuide(im, step, collider, g);
    };
    StepContext ctx{&im, step.followerRoots.data(), collider, out.positions.data() + guideVertices,
                    out.velocities.data() + guideVertices, stats.differenceVelocities,
                    step.dt > 0.0 ? float(1.0 / step.dt) : 0.f};
    std::atomic<size_t> projected{0}, queries{0};
    auto followersLoop = [&](const tbb::blocked_range<size_t>& r) {
        Counters counters;
        processRange(ctx, r.begin(), r.end(), counters);
        projected += counters.projected;
        queries += counters.queries;
    };
    // Each follower depends only on the tables, so any partition gives the
    // same bits; the counters are integer sums.
    if (im.settings.parallel) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, G, 16), guidesLoop);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, F, 256), followersLoop);
    } else {
        guidesLoop(tbb::blocked_range<size_t>(0, G));
        followersLoop(tbb::blocked_range<size_t>(0, F));
    }
    stats.projected = projected;
    stats.collisionQueries = queries;
    im.lastPositions = out.positions.data();
    im.lastVertexCount = total;
    return stats;
}

}  // namespace hp
