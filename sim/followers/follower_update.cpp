// One step of the followers: checks, the output layout, the guide tables
// (rotations, speeds, vertices), then the pair tables and every follower
// (sim/followers/follower_step.cpp), each a TBB loop. sim/followers/followers.h explains the
// model, sim/followers/follower_kernels.h has the equations. Nothing is allocated per
// step once `out` has its layout.
#include "sim/followers/followers.h"

#include "core/errors.h"
#include "sim/followers/follower_kernels.h"
#include "sim/followers/follower_state.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <vector>

namespace hp {

namespace {

using Impl = Followers::Impl;

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
    // The union of every part: a lower bound of what any follower sees
    // (ignoring parts never brings a surface nearer), so the bound below
    // stays safe for followers that ignore parts their guide does not.
    for (uint32_t k = 0; k <= gs; ++k)
        clearance[k] = collider ? collider->signedDistance(x[k]) : std::numeric_limits<float>::max();

    const float inf = std::numeric_limits<float>::infinity();
    for (FollowerClass& c : im.classes) {
        // Slot j = vertex j = segment j - 1 (FollowerClass); slot 0 and the
        // padding keep the build's identity rotations and zero speeds.
        const size_t P = c.pad;
        const uint32_t S = c.segments;
        const bool same = S == gs;  // the usual case: no resampling
        float* rotation[4] = {c.hot.row(g, HotRow::RotationW), c.hot.row(g, HotRow::RotationX),
                              c.hot.row(g, HotRow::RotationY), c.hot.row(g, HotRow::RotationZ)};
        float* rowSpeed = c.hot.row(g, HotRow::Speed);
        for (uint32_t j = 1; j <= S; ++j) {
            const uint32_t s = same ? j - 1 : FollowerClass::guideSegment(j - 1, S, gs);
            for (int k = 0; k < 4; ++k) rotation[k][j] = q[s][k];
            rowSpeed[j] = speed[s];
        }
        const float *restX = c.hot.row(g, HotRow::RestX), *restY = c.hot.row(g, HotRow::RestY),
                    *restZ = c.hot.row(g, HotRow::RestZ);
        float *vx = c.cold.row(g, ColdRow::X), *vy = c.cold.row(g, ColdRow::Y), *vz = c.cold.row(g, ColdRow::Z);
        float* bound = c.cold.row(g, ColdRow::Bound);
        float *ux = c.cold.row(g, ColdRow::VelocityX), *uy = c.cold.row(g, ColdRow::VelocityY),
              *uz = c.cold.row(g, ColdRow::VelocityZ);
        GuideRecord* records = c.guideRecords.data() + g * P;
        for (uint32_t j = 0; j < P; ++j) {
            const uint32_t gv = j == 0 || same ? std::min(j, gs) : FollowerClass::guideSegment(std::min(j, S) - 1, S, gs) + 1;
            const bool vertex = j >= 1 && j <= S;  // the root and the padding are never tested
            vx[j] = x[gv].x();
            vy[j] = x[gv].y();
            vz[j] = x[gv].z();
            bound[j] = vertex ? follower::collisionBound(clearance[gv], c.radii[0]) : inf;
            ux[j] = v ? v[gv].x() : 0.f;
            uy[j] = v ? v[gv].y() : 0.f;
            uz[j] = v ? v[gv].z() : 0.f;
            // The record followers led by this guide read per slot: A = q r q*
            // (the rest direction turned; followers with own rest shapes take
            // q itself), then the vertex and its bound.
            GuideRecord& rec = records[j];
            const follower::Quat qj{rotation[0][j], rotation[1][j], rotation[2][j], rotation[3][j]};
            if (im.ownRest.empty()) {
                const Vec3f a = follower::sandwich(qj, Vec3f(restX[j], restY[j], restZ[j]));
                rec.lead[0] = a.x();
                rec.lead[1] = a.y();
                rec.lead[2] = a.z();
                rec.lead[3] = 0.f;
            } else {
                rec.lead[0] = qj.w;
                rec.lead[1] = qj.x;
                rec.lead[2] = qj.y;
                rec.lead[3] = qj.z;
            }
            rec.vertex[0] = vx[j];
            rec.vertex[1] = vy[j];
            rec.vertex[2] = vz[j];
            rec.bound = bound[j];
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
    follower::StepContext ctx{&im, step.followerRoots.data(), collider, out.positions.data() + guideVertices,
                              out.velocities.data() + guideVertices, stats.differenceVelocities,
                              step.dt > 0.0 ? float(1.0 / step.dt) : 0.f, step.ignoreParts};
    std::atomic<size_t> projected{0}, queries{0}, inside{0}, bent{0}, pinned{0};
    std::atomic<uint32_t> depthBits{0};  // a non-negative float's bits order like the float
    std::mutex pinsMutex;
    auto packetsLoop = [&](const tbb::blocked_range<size_t>& r) {
        follower::Counters counters;
        follower::processPackets(ctx, r.begin(), r.end(), counters);
        if (!counters.pins.empty()) {
            const std::lock_guard<std::mutex> lock(pinsMutex);
            stats.pins.insert(stats.pins.end(), counters.pins.begin(), counters.pins.end());
        }
        projected += counters.projected;
        queries += counters.queries;
        inside += counters.inside;
        bent += counters.bent;
        pinned += counters.pinned;
        uint32_t bits;
        std::memcpy(&bits, &counters.maxDepth, sizeof bits);
        uint32_t seen = depthBits.load();
        while (bits > seen && !depthBits.compare_exchange_weak(seen, bits)) {}
    };
    // Each pair and each follower depends only on the tables before it, so
    // any partition gives the same bits; the counters are integer sums.
    const size_t packets = im.packets.size();
    if (im.settings.parallel) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, G, 16), guidesLoop);
        for (FollowerClass& c : im.classes)
            tbb::parallel_for(tbb::blocked_range<size_t>(0, c.pairs.size(), 64),
                              [&](const tbb::blocked_range<size_t>& r) { follower::buildPairs(im, c, r.begin(), r.end()); });
        tbb::parallel_for(tbb::blocked_range<size_t>(0, packets, 32), packetsLoop);
    } else {
        guidesLoop(tbb::blocked_range<size_t>(0, G));
        for (FollowerClass& c : im.classes) follower::buildPairs(im, c, 0, c.pairs.size());
        packetsLoop(tbb::blocked_range<size_t>(0, packets));
    }
    stats.projected = projected;
    stats.collisionQueries = queries;
    stats.penetrationCount = inside;
    stats.bent = bent;
    stats.pinned = pinned;
    // Ranges finish in any order; sorted, the list is the same for any thread count.
    std::sort(stats.pins.begin(), stats.pins.end(),
              [](const FollowerPin& a, const FollowerPin& b) { return a.vertex < b.vertex; });
    const uint32_t bits = depthBits.load();
    std::memcpy(&stats.maxPenetration, &bits, sizeof bits);
    im.lastPositions = out.positions.data();
    im.lastVertexCount = total;
    return stats;
}

}  // namespace hp

namespace hp {

void Followers::adoptPrevious(const StrandFrame& out) {
    Impl& im = *impl_;
    const size_t G = im.guides, F = im.followers;
    if (out.guideCount != G || out.strandCount() != G + F)
        throw Error(cat("followers: the frame to adopt has ", out.guideCount, " guides and ", out.strandCount(),
                        " strands; the groom has ", G, " guides and ", G + F, " strands"));
    const uint32_t guideVertices = out.offsets[G];
    const size_t total = size_t(guideVertices) + im.vertexOffset[F];
    if (out.positions.size() != total || out.velocities.size() != total ||
        !sameRange(out.offsets, G, im.vertexOffset, 0, F + 1, guideVertices) || !sameRange(out.ids, G, im.ids, 0, F))
        throw Error("followers: the frame to adopt does not have this groom's follower layout");
    im.lastPositions = out.positions.data();
    im.lastVertexCount = total;
}

void Followers::adoptPins(StrandFrame& out, const std::vector<FollowerPin>& pins) {
    adoptPrevious(out);
    const size_t guideVertices = out.offsets[impl_->guides];
    for (const FollowerPin& pin : pins) {
        if (pin.vertex >= impl_->vertexOffset[impl_->followers])
            throw Error(cat("followers: pinned vertex ", pin.vertex, " lies outside the follower block"));
        out.positions[guideVertices + pin.vertex] = pin.last;
    }
}

}  // namespace hp

namespace hp {

Followers::LengthError Followers::lengthError(const StrandFrame& out) const {
    const Impl& im = *impl_;
    const size_t G = im.guides, F = im.followers;
    if (out.guideCount != G || out.strandCount() != G + F ||
        !sameRange(out.offsets, G, im.vertexOffset, 0, F + 1, out.offsets[G]))
        throw Error("followers: the frame to measure does not have this groom's follower layout");
    const Vec3f* base = out.positions.data() + out.offsets[G];
    // Per packet, then summed in packet order: the same result on any thread count.
    std::vector<double> sums(im.packets.size()), maxima(im.packets.size());
    std::vector<size_t> counts(im.packets.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, im.packets.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const FollowerPacket& pk = im.packets[i];
            const FollowerClass& c = im.classes[pk.cls];
            double sum = 0, worst = 0;
            for (uint32_t k = 0; k < pk.count; ++k) {
                const Vec3f* p = base + pk.vertexOffset[k];
                for (uint32_t j = 1; j <= c.segments; ++j) {
                    double rest = pk.scale[k];
                    if (!im.ownRest.empty()) {
                        const OwnRestSlot& o = im.ownRest[pk.own + j];
                        rest = std::sqrt(double(o.x[k]) * o.x[k] + double(o.y[k]) * o.y[k] + double(o.z[k]) * o.z[k]);
                    }
                    const double e = std::abs((p[j] - p[j - 1]).cast<double>().norm() / rest - 1.0);
                    sum += e;
                    worst = std::max(worst, e);
                }
            }
            sums[i] = sum;
            maxima[i] = worst;
            counts[i] = size_t(pk.count) * c.segments;
        }
    });
    LengthError e;
    size_t segments = 0;
    for (size_t i = 0; i < sums.size(); ++i) {
        e.mean += sums[i];
        e.max = std::max(e.max, maxima[i]);
        segments += counts[i];
    }
    e.mean = segments ? e.mean / double(segments) : 0.0;
    return e;
}

}  // namespace hp
