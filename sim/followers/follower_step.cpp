// The per-step work of the followers that scales with their number: the
// guide-pair records, then every packet of 8 followers (shapes, head
// collision, output). sim/followers/followers.h explains the model,
// sim/followers/follower_kernels.h has the equations, sim/followers/follower_update.cpp the
// step around this.
//
// Performance (100k followers × 24 vertices: 2.3M segments per step; the
// measurements behind these choices are in the README's follower section):
// - What depends only on a follower's guides is computed once per guide or
//   guide pair and segment: A of (2) and the guide vertex with its collision
//   bound per guide (guide records, fillGuide), the slerp arc θ, B - A and D
//   of (2) and d_v per pair (pair records; ~4.5k pairs against 100k
//   followers). Per segment a follower then evaluates its weight t (hash,
//   Algorithm 1), sin and cos of tθ (polynomials), (2) and its root frame.
// - Lanes are followers: a packet of 8 consecutive followers runs down the
//   strand together, so positions are a running sum per lane, and the frame
//   setup is vector work too. Each lane reads its own records, 4 floats at
//   a time, turned into lanes by a transpose. Consecutive, because the
//   output (positions read for the velocities, positions and velocities
//   written: ~86 MB per step at 100k) must stream through memory in order;
//   packing followers by guide instead made every access a cache miss
//   (3x the memory time).
// - Collision: one vector test per vertex against guide 1's bound
//   (collisionBound); only followers with a vertex the bound cannot clear
//   take the sequential follow-the-leader loop, from that vertex on.
// - Built twice, for x86-64-v3 (AVX2 + FMA) and baseline x86-64, picked at
//   load time. Multiply-adds contract into FMA in the v3 build
//   (-ffp-contract=fast on this file), so the two builds differ in the last
//   bits; within one machine every follower runs the same code in whatever
//   lane, packet or thread, which is the determinism the project needs
//   (bits identical across CPU generations are not promised).
#include "sim/collision/mesh_parts.h"
#include "sim/followers/follower_pinch.h"
#include "sim/followers/follower_simd.h"
#include "sim/followers/follower_state.h"

#include <algorithm>
#include <cmath>

namespace hp::follower {

namespace {

using namespace simd;
using Impl = Followers::Impl;
constexpr int kLanes = FollowerPacket::kLanes;

template <bool Own>
[[gnu::always_inline]] inline void buildPairRecords(const Impl& im, FollowerClass& c, size_t begin, size_t end) {
    const size_t P = c.pad;
    alignas(32) float rows[8][kMaxFollowerVertices];
    const float maxVelocity = im.settings.maxVelocity;
    for (size_t p = begin; p < end; ++p) {
        const GuidePair& gp = c.pairs[p];
        // One pointer per row: the slot loop reads and writes contiguous
        // rows and vectorizes (ivdep: rows never overlap; restrict alone is
        // lost once this is inlined).
        const GuideRows<HotRow>& hot = c.hot;
        const uint32_t g1 = gp.guide1, g2 = gp.guide2;
        const float *aW = hot.row(g1, HotRow::RotationW), *aX = hot.row(g1, HotRow::RotationX),
                    *aY = hot.row(g1, HotRow::RotationY), *aZ = hot.row(g1, HotRow::RotationZ);
        const float* speed = hot.row(g1, HotRow::Speed);
        const float *fX = hot.row(g1, HotRow::RestX), *fY = hot.row(g1, HotRow::RestY), *fZ = hot.row(g1, HotRow::RestZ);
        const float *bW = hot.row(g2, HotRow::RotationW), *bX = hot.row(g2, HotRow::RotationX),
                    *bY = hot.row(g2, HotRow::RotationY), *bZ = hot.row(g2, HotRow::RotationZ);
        float *o0 = rows[0], *o1 = rows[1], *o2 = rows[2], *o3 = rows[3], *o4 = rows[4], *o5 = rows[5], *o6 = rows[6],
              *o7 = rows[7];
        const float kc = gp.twistC, ks = gp.twistS;
#pragma GCC ivdep
        for (size_t j = 0; j < P; ++j) {
            const Quat a{aW[j], aX[j], aY[j], aZ[j]};
            // Guide 2's rotation turned into guide 1's frame: K q2 K⁻¹, K about y.
            const Quat b{bW[j], kc * bX[j] + ks * bZ[j], bY[j], -ks * bX[j] + kc * bZ[j]};
            float theta;
            Quat e;
            slerpArc(a, b, theta, e);
            o0[j] = theta;
            o7[j] = variableOffset(speed[j], maxVelocity);
            if constexpr (Own) {
                o1[j] = e.w;
                o2[j] = e.x;
                o3[j] = e.y;
                o4[j] = e.z;
                o5[j] = 0.f;
                o6[j] = 0.f;
            } else {
                Eigen::Vector3f A, BminusA, D;
                slerpedDirection(a, e, Eigen::Vector3f(fX[j], fY[j], fZ[j]), A, BminusA, D);
                o1[j] = BminusA.x();
                o2[j] = BminusA.y();
                o3[j] = BminusA.z();
                o4[j] = D.x();
                o5[j] = D.y();
                o6[j] = D.z();
            }
        }
        // Rows to one PairRecord per slot: row i is the record's float i
        // (θ, terms 0-5, d_v), written 8 slots at a time by a transpose.
        PairRecord* out = c.pairRecords.data() + p * P;
        for (size_t j = 0; j < P; j += 8) {
            f8 r0 = load(rows[0] + j), r1 = load(rows[1] + j), r2 = load(rows[2] + j), r3 = load(rows[3] + j);
            f8 r4 = load(rows[4] + j), r5 = load(rows[5] + j), r6 = load(rows[6] + j), r7 = load(rows[7] + j);
            transpose8(r0, r1, r2, r3, r4, r5, r6, r7);
            const f8 r[8] = {r0, r1, r2, r3, r4, r5, r6, r7};
            for (int k = 0; k < 8; ++k) store(&out[j + k].theta, r[k]);
        }
    }
}

/// A guide's vertex velocity rows (x, y, z) in a class's cold table.
struct VelocityRows {
    const float* row[3];
    VelocityRows(const FollowerClass& c, uint32_t guide)
        : row{c.cold.row(guide, ColdRow::VelocityX), c.cold.row(guide, ColdRow::VelocityY),
              c.cold.row(guide, ColdRow::VelocityZ)} {}
};

/// Follow the leader for lane k of a packet (positions pos[3v + c], lanes =
/// followers): a vertex the bound cannot clear is queried; one inside is
/// projected out keeping its segment's length (slid along the surface, or
/// where that fails bent or pinned: follower_pinch.h), and every later vertex
/// moves by the same shift, so segment directions are kept elsewhere.
/// `collider`: the head as this follower sees it (without the parts its root
/// lies inside). `last`: the lane's vertices in the previous frame (null
/// when there is none).
/// `cleared[v]` is the vector pass's bound test of the unshifted vertex,
/// valid until the first projection (and `uncleared`, bit v, the same for
/// vertices 1..31); after it shifted vertices are tested again.
void collideLane(const StepContext& ctx, const Collider& collider, const FollowerClass& c, uint32_t guide1,
                 const i8* cleared, uint32_t uncleared, int k, const OwnRestSlot* ownRest, float segmentLength,
                 const Vec3f* last, f8* pos, Counters& counters) {
    const float *gX = c.cold.row(guide1, ColdRow::X), *gY = c.cold.row(guide1, ColdRow::Y),
                *gZ = c.cold.row(guide1, ColdRow::Z), *bound = c.cold.row(guide1, ColdRow::Bound);
    float sx = 0.f, sy = 0.f, sz = 0.f;
    bool shifted = false;
    // Vertex v at q: queried without the normal (most queried vertices are
    // outside), again with it when inside, then projected.
    auto query = [&](uint32_t v, float qx, float qy, float qz) {
        ++counters.queries;
        Vec3f p(qx, qy, qz), normal;
        float d = collider.signedDistance(p);
        if (!(d < c.radii[v])) return;
        d = collider.signedDistance(p, &normal);
        const Vec3f previous(pos[3 * v - 3][k], pos[3 * v - 2][k], pos[3 * v - 1][k]);
        float length = segmentLength;
        if (ownRest) {
            const OwnRestSlot& r = ownRest[v];
            length = std::sqrt(r.x[k] * r.x[k] + r.y[k] * r.y[k] + r.z[k] * r.z[k]);
        }
        const Vec3f wanted = p;
        float after = projectSegmentOut(collider, previous, length, c.radii[v], d, normal, p);
        if (after < 0.f) {
            // The slide could not bring it out: bend, else pin (follower_pinch.h).
            const PinchPlace place = placePinched(collider, previous, length, c.radii[v], wanted,
                                                  last ? last + v : nullptr);
            p = place.position;
            after = place.distance;
            ++(place.pinned ? counters.pinned : counters.bent);
            // The one state a frame carries to the next: where a pinned vertex
            // was held from (its place in the previous frame), so a frame can
            // be rebuilt from its guides alone (FollowerStats::pins).
            if (place.pinned && last) counters.pins.push_back({uint32_t(last + v - ctx.positions), last[v]});
        }
        if (after < 0.f) {
            ++counters.inside;
            counters.maxDepth = std::max(counters.maxDepth, -after);
        }
        sx += p.x() - qx;
        sy += p.y() - qy;
        sz += p.z() - qz;
        shifted = true;
        ++counters.projected;
    };
    uint32_t v = 1;
    if (c.segments < 32) {
        // Up to the first projection, only the vertices the bound failed.
        while (uncleared && !shifted) {
            v = uint32_t(__builtin_ctz(uncleared));
            uncleared &= uncleared - 1;
            query(v, pos[3 * v][k], pos[3 * v + 1][k], pos[3 * v + 2][k]);
        }
        if (!shifted) return;
        pos[3 * v][k] += sx;
        pos[3 * v + 1][k] += sy;
        pos[3 * v + 2][k] += sz;
        ++v;
    }
    for (; v <= c.segments; ++v) {
        if (!shifted && cleared[v][k]) continue;
        float &px = pos[3 * v][k], &py = pos[3 * v + 1][k], &pz = pos[3 * v + 2][k];
        const float qx = px + sx, qy = py + sy, qz = pz + sz;
        const float gx = qx - gX[v], gy = qy - gY[v], gz = qz - gZ[v];
        if (!shifted || !(gx * gx + gy * gy + gz * gz < bound[v])) query(v, qx, qy, qz);
        if (shifted) {
            px += sx;
            py += sy;
            pz += sz;
        }
    }
}

template <FollowerMode M, bool Own>
[[gnu::always_inline]] inline void processPacket(const StepContext& ctx, const FollowerPacket& pk, Counters& counters) {
    const Impl& im = *ctx.im;
    const FollowerClass& c = im.classes[pk.cls];
    const size_t P = c.pad;
    const uint32_t S = c.segments;
    const OwnRestSlot* ownRest = Own ? im.ownRest.data() + pk.own : nullptr;
    const GuideRecord* guideRec[kLanes];
    const PairRecord* pairRec[kLanes];
    for (int k = 0; k < kLanes; ++k) {
        guideRec[k] = c.guideRecord(pk.guide1[k]);
        pairRec[k] = c.pairRecord(pk.pair[k]);
    }
    // Barycentric: guides 2 and 3 of each lane, their weights and twists.
    constexpr bool kTri = M == FollowerMode::Barycentric;
    static_assert(!kTri || Own, "barycentric followers read their own rest shapes");
    const TrianglePacket* tp = kTri ? &im.triangles[size_t(&pk - im.packets.data())] : nullptr;
    const GuideRecord* guide2Rec[kLanes];
    const GuideRecord* guide3Rec[kLanes];
    f8 b1{}, b2{}, b3{}, k2c{}, k2s{}, k3c{}, k3s{};
    if constexpr (kTri) {
        for (int k = 0; k < kLanes; ++k) {
            guide2Rec[k] = c.guideRecord(tp->guide2[k]);
            guide3Rec[k] = c.guideRecord(tp->guide3[k]);
        }
        b1 = load(tp->b1), b2 = load(tp->b2), b3 = load(tp->b3);
        k2c = load(tp->k2c), k2s = load(tp->k2s), k3c = load(tp->k3c), k3s = load(tp->k3s);
    }

    // Root frames of the lanes: E = [t', n, z'] per lane, orthonormalised and
    // turned about n by the rest twist toward guide 1 (see followers.h);
    // times the segment length for followers with the guides' rest shape.
    // SurfaceFrame is 9 floats (position, normal, tangent): the first 8 of
    // each lane by a transpose, the tangent's z lane by lane.
    static_assert(sizeof(SurfaceFrame) == 9 * sizeof(float), "SurfaceFrame layout");
    const float* frames[kLanes];
    alignas(32) float tangentZ[kLanes];
    for (int k = 0; k < kLanes; ++k) {
        frames[k] = ctx.roots[pk.follower[k]].position.data();
        tangentZ[k] = frames[k][8];
    }
    f8 x = load(frames[0]), y = load(frames[1]), z = load(frames[2]), nx = load(frames[3]);
    f8 ny = load(frames[4]), nz = load(frames[5]), tx = load(frames[6]), ty = load(frames[7]);
    transpose8(x, y, z, nx, ny, nz, tx, ty);
    f8 tz = load(tangentZ);
    const f8 invN = splat(1.f) / sqrt8(nx * nx + ny * ny + nz * nz);
    nx *= invN;
    ny *= invN;
    nz *= invN;
    const f8 nt = nx * tx + ny * ty + nz * tz;
    tx -= nt * nx;
    ty -= nt * ny;
    tz -= nt * nz;
    const f8 invT = splat(1.f) / sqrt8(tx * tx + ty * ty + tz * tz);
    tx *= invT;
    ty *= invT;
    tz *= invT;
    const f8 zx = ty * nz - tz * ny, zy = tz * nx - tx * nz, zz = tx * ny - ty * nx;
    const f8 ac = load(pk.alignC), as = load(pk.alignS), scale = load(pk.scale);
    const f8 m00 = scale * (ac * tx - as * zx), m10 = scale * (ac * ty - as * zy), m20 = scale * (ac * tz - as * zz);
    const f8 m01 = scale * nx, m11 = scale * ny, m21 = scale * nz;
    const f8 m02 = scale * (as * tx + ac * zx), m12 = scale * (as * ty + ac * zy), m22 = scale * (as * tz + ac * zz);

    // Down the strand: positions pos[3v + c] (so 8 consecutive entries are 8
    // consecutive output floats of every lane), weights, bound tests.
    alignas(32) f8 pos[3 * kMaxFollowerVertices];
    alignas(32) f8 weights[kMaxFollowerVertices];
    alignas(32) i8 cleared[kMaxFollowerVertices];
    pos[0] = x;
    pos[1] = y;
    pos[2] = z;
    const u8 hash = *reinterpret_cast<const u8*>(pk.hash);
    const f8 weight = load(pk.weight);
    i8 outside = i8{} - 1;
    u8 uncleared{};  // bit v: vertex v (< 32) not cleared by the bound
    // Two passes down the strand, each with fewer live registers than one:
    // 1. local directions (guide 1's frame) from the records, into pos[3j..];
    // 2. world space, the running sum from the root, the bound tests.
    const float* lane[kLanes];
    for (uint32_t j = 1; j <= S; ++j) {
        f8 t{}, s{}, co = splat(1.f);
        f8 theta{}, e1{}, e2{}, e3{}, e4{}, e5{}, e6{}, dv{};
        if constexpr (M != FollowerMode::Cluster && !kTri) {
            // The lanes' pair records (θ, ..., d_v), the slerp weight t
            // (Algorithm 1: d_r = fixedOffset d_f + rand_xy d_v), sin and cos of φ = tθ.
            for (int k = 0; k < kLanes; ++k) lane[k] = pairRec[k][j].arcAndTerms();
            transpose8x4(lane, theta, e1, e2, e3);
            for (int k = 0; k < kLanes; ++k) lane[k] = pairRec[k][j].lastTermsAndSpeed();
            transpose8x4(lane, e4, e5, e6, dv);
            if constexpr (M == FollowerMode::Interpolate) {
                t = weight;
            } else {
                const f8 random = toSignedUnit(segmentHash(hash, splat(uint32_t(j - 1))));
                t = splat(c.weightedCurve[j]) + random * dv;
            }
            sinCos(reduceHalfTurns(t * theta), s, co);
        }
        weights[j] = t;
        f8 l0, l1, l2, l3;  // the guide record's lead: A or q
        for (int k = 0; k < kLanes; ++k) lane[k] = guideRec[k][j].lead;
        transpose8x4(lane, l0, l1, l2, l3);
        f8 vx = l0, vy = l1, vz = l2;
        if constexpr (!Own) {  // (2): A + s² (B - A) + cs D
            if constexpr (M != FollowerMode::Cluster) {
                const f8 ss = s * s, cs = co * s;
                vx += ss * e1 + cs * e4;
                vy += ss * e2 + cs * e5;
                vz += ss * e3 + cs * e6;
            }
        } else if constexpr (kTri) {
            // q = normalize(b1 q1 + b2 ±K2 q2 K2⁻¹ + b3 ±K3 q3 K3⁻¹): K turns the
            // vector part about y (x' = c x + s z, z' = -s x + c z); each sign
            // puts the quaternion on q1's side (q and -q are one rotation).
            auto corner = [&](const GuideRecord* const* rec, f8 kc, f8 ks, f8 b, f8& ow, f8& ox, f8& oy, f8& oz) {
                f8 m0, m1, m2, m3;
                for (int k = 0; k < kLanes; ++k) lane[k] = rec[k][j].lead;
                transpose8x4(lane, m0, m1, m2, m3);
                const f8 x2 = kc * m1 + ks * m3, z2 = kc * m3 - ks * m1;
                const f8 dot = l0 * m0 + l1 * x2 + l2 * m2 + l3 * z2;
                const f8 sb = select(dot < splat(0.f), -b, b);
                ow += sb * m0;
                ox += sb * x2;
                oy += sb * m2;
                oz += sb * z2;
            };
            f8 qw = b1 * l0, qx = b1 * l1, qy = b1 * l2, qz = b1 * l3;
            corner(guide2Rec, k2c, k2s, b2, qw, qx, qy, qz);
            corner(guide3Rec, k3c, k3s, b3, qw, qx, qy, qz);
            const f8 inv = splat(1.f) / sqrt8(qw * qw + qx * qx + qy * qy + qz * qz);
            const OwnRestSlot& f = ownRest[j];
            rotate(qw * inv, qx * inv, qy * inv, qz * inv, load(f.x), load(f.y), load(f.z), vx, vy, vz);
        } else {  // (1): q = cos φ a + sin φ e, then q f q* of the lane's own rest segment
            const f8 qw = co * l0 + s * e1, qx = co * l1 + s * e2, qy = co * l2 + s * e3, qz = co * l3 + s * e4;
            const OwnRestSlot& f = ownRest[j];
            rotate(qw, qx, qy, qz, load(f.x), load(f.y), load(f.z), vx, vy, vz);
        }
        pos[3 * j] = vx;
        pos[3 * j + 1] = vy;
        pos[3 * j + 2] = vz;
    }
    for (uint32_t j = 1; j <= S; ++j) {
        const f8 vx = pos[3 * j], vy = pos[3 * j + 1], vz = pos[3 * j + 2];
        x += m00 * vx + m01 * vy + m02 * vz;
        y += m10 * vx + m11 * vy + m12 * vz;
        z += m20 * vx + m21 * vy + m22 * vz;
        pos[3 * j] = x;
        pos[3 * j + 1] = y;
        pos[3 * j + 2] = z;
        if (ctx.collider) {
            f8 gx, gy, gz, bound;  // the guide record's vertex and bound
            for (int k = 0; k < kLanes; ++k) lane[k] = guideRec[k][j].vertexAndBound();
            transpose8x4(lane, gx, gy, gz, bound);
            const f8 dx = x - gx, dy = y - gy, dz = z - gz;
            cleared[j] = dx * dx + dy * dy + dz * dz < bound;
            outside &= cleared[j];
            if (j < 32) uncleared |= u8(~cleared[j]) & splat(1u << j);
        }
    }
    for (size_t v = S + 1; v < P; ++v) pos[3 * v] = pos[3 * v + 1] = pos[3 * v + 2] = f8{};  // never written out

    if (ctx.collider && anyLane(~outside)) {
        alignas(32) int32_t clear[kLanes];
        std::memcpy(clear, &outside, sizeof clear);
        for (uint32_t k = 0; k < pk.count; ++k)
            if (!clear[k]) {
                // The lane's previous output, where a pinned vertex is held (still in `positions` until written below).
                const Vec3f* last = ctx.difference ? ctx.positions + pk.vertexOffset[k] : nullptr;
                // The head as this follower sees it: without the parts its
                // root lies inside (sim/collision/mesh_parts.h), as a guide.
                const uint32_t ignore = ctx.ignoreParts ? ctx.ignoreParts[pk.follower[k]] : 0u;
                const IgnoringParts own(*ctx.collider, ignore);
                collideLane(ctx, ignore ? static_cast<const Collider&>(own) : *ctx.collider, c, pk.guide1[k], cleared,
                            uncleared[k], int(k), ownRest, pk.scale[k], last, pos, counters);
            }
    }

    // Output: per 8 floats, a transpose turns lanes back into followers.
    const size_t n3 = 3 * size_t(S + 1);
    const uint32_t count = pk.count;
    const bool difference = ctx.difference;
    const f8 invDt = splat(ctx.invDt);
    float* outPos[kLanes];
    float* outVel[kLanes];
    for (int k = 0; k < kLanes; ++k) {
        outPos[k] = ctx.positions[0].data() + 3 * size_t(pk.vertexOffset[k]);
        outVel[k] = ctx.velocities[0].data() + 3 * size_t(pk.vertexOffset[k]);
    }
    // Transposed into one row per lane first, then written lane by lane: the
    // output is one sequential stream (8 consecutive followers), which the
    // hardware prefetcher follows, where writing chunk by chunk across lanes
    // interleaves 8 streams.
    alignas(32) float rows[kLanes][3 * kMaxFollowerVertices];
    for (size_t i = 0; i < n3; i += 8) {
        f8 o0 = pos[i], o1 = pos[i + 1], o2 = pos[i + 2], o3 = pos[i + 3];
        f8 o4 = pos[i + 4], o5 = pos[i + 5], o6 = pos[i + 6], o7 = pos[i + 7];
        transpose8(o0, o1, o2, o3, o4, o5, o6, o7);
        store(rows[0] + i, o0);
        store(rows[1] + i, o1);
        store(rows[2] + i, o2);
        store(rows[3] + i, o3);
        store(rows[4] + i, o4);
        store(rows[5] + i, o5);
        store(rows[6] + i, o6);
        store(rows[7] + i, o7);
    }
    const size_t whole = n3 & ~size_t(7);
    for (uint32_t k = 0; k < count; ++k) {
        float* __restrict p = outPos[k];
        float* __restrict u = outVel[k];
        const float* __restrict row = rows[k];
        if (difference) {
            for (size_t i = 0; i < whole; i += 8) {
                store(u + i, (load(row + i) - load(p + i)) * invDt);
                store(p + i, load(row + i));
            }
            for (size_t i = whole; i < n3; ++i) {
                u[i] = (row[i] - p[i]) * ctx.invDt;
                p[i] = row[i];
            }
        } else {
            for (size_t i = 0; i < n3; ++i) p[i] = row[i];
        }
    }
    if (!ctx.difference && kTri) {
        // No previous positions: the barycentric blend of the three guides' vertex velocities.
        for (uint32_t k = 0; k < pk.count; ++k) {
            const VelocityRows g[3] = {{c, pk.guide1[k]}, {c, tp->guide2[k]}, {c, tp->guide3[k]}};
            const float b[3] = {tp->b1[k], tp->b2[k], tp->b3[k]};
            float* vel = outVel[k];
            for (uint32_t v = 0; v <= S; ++v)
                for (int i = 0; i < 3; ++i)
                    vel[3 * v + i] = b[0] * g[0].row[i][v] + b[1] * g[1].row[i][v] + b[2] * g[2].row[i][v];
        }
    } else if (!ctx.difference) {
        // No previous positions: the slerp-weighted blend of the guides' vertex velocities.
        for (uint32_t k = 0; k < pk.count; ++k) {
            const VelocityRows g1{c, pk.guide1[k]}, g2{c, c.pairs[pk.pair[k]].guide2};
            float* vel = outVel[k];
            for (uint32_t v = 0; v <= S; ++v) {
                const float b = weights[v > 0 ? v : 1][k];
                for (int i = 0; i < 3; ++i) vel[3 * v + i] = (1.f - b) * g1.row[i][v] + b * g2.row[i][v];
            }
        }
    }
}

template <FollowerMode M, bool Own>
[[gnu::always_inline]] inline void processRangeT(const StepContext& ctx, size_t begin, size_t end, Counters& counters) {
    const FollowerPacket* packets = ctx.im->packets.data();
    for (size_t i = begin; i < end; ++i) processPacket<M, Own>(ctx, packets[i], counters);
}

[[gnu::target_clones("arch=x86-64-v3", "default")]] void processRange(const StepContext& ctx, size_t begin,
                                                                      size_t end, Counters& counters) {
    const bool own = !ctx.im->ownRest.empty();
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
        case FollowerMode::Barycentric:  // always own rest shapes (Followers' constructor)
            return processRangeT<FollowerMode::Barycentric, true>(ctx, begin, end, counters);
    }
}

[[gnu::target_clones("arch=x86-64-v3", "default")]] void pairRange(const Impl& im, FollowerClass& c, size_t begin,
                                                                   size_t end) {
    if (im.ownRest.empty()) buildPairRecords<false>(im, c, begin, end);
    else buildPairRecords<true>(im, c, begin, end);
}

}  // namespace

void buildPairs(const Impl& im, FollowerClass& c, size_t begin, size_t end) { pairRange(im, c, begin, end); }

void processPackets(const StepContext& ctx, size_t begin, size_t end, Counters& counters) {
    processRange(ctx, begin, end, counters);
}

}  // namespace hp::follower
