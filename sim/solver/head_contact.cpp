#include "sim/solver/head_contact.h"

#include "sim/solver/length_kernels.h"

#include <algorithm>
#include <cmath>

namespace hp::strand {

float HeadQuery::distance(const Vec3f& x, Vec3f* normal) const {
    Vec3f n;
    const float d = ignoreParts ? collider->signedDistanceIgnoring(toCollider * x, &n, ignoreParts)
                                : collider->signedDistance(toCollider * x, &n);
    if (normal) *normal = normalToWorld * n;
    return d;
}

Contact projectOut(const HeadQuery& head, float radius, Vec3f& x) {
    Contact c;
    if (!head.collider) return c;
    if (head.distance(x, nullptr) >= radius) return c;  // the common case: no normal needed
    Vec3f n;
    const float d = head.distance(x, &n);
    c.active = true;
    c.normal = n;
    c.push = radius - d;
    x += c.push * n;
    return c;
}

namespace {

/// The point at `length` from `parent` nearest to `onPlane` that is not
/// below the plane through `onPlane` with unit normal n: with e = onPlane -
/// parent, a = n·e (the plane's height relative to the parent), clamped to
/// [-length, length], and t the unit tangential part of e,
///   x = parent + a·n + sqrt(length² - a²)·t.
/// It slides the child along the contact plane in one step, where
/// alternating projections (plane, then sphere) creep toward the corner
/// and leave the segment short after a few rounds (a strand meeting a floor
/// nearly head-on: 3% in 4 rounds).
Vec3f slideOnPlane(const Vec3f& parent, const Vec3f& onPlane, float length, const Vec3f& n) {
    const Vec3f e = onPlane - parent;
    const float a = std::clamp(n.dot(e), -length, length);
    Vec3f t = e - n * n.dot(e);
    const float tl = t.norm();
    t = tl > 1e-9f ? Vec3f(t / tl) : Vec3f(n.unitOrthogonal());
    return parent + a * n + std::sqrt(std::max(0.f, length * length - a * a)) * t;
}

/// Reattach::Radial's placement: x ← p + l·(x - p)/|x - p| (a collapsed edge
/// keeps its length along an arbitrary, deterministic axis). The same
/// direction as followTheLeader, rounded as the curly model always has.
Vec3f radial(const Vec3f& parent, const Vec3f& child, float length) {
    const Vec3f e = child - parent;
    const float len = e.norm();
    return parent + (len > 1e-12f ? Vec3f(e / len) : Vec3f::UnitY()) * length;
}

}  // namespace

Contact placeOutside(const Vec3f& parent, Vec3f& child, float length, const HeadQuery* head, float radius,
                     Reattach how) {
    const bool slide = how == Reattach::Slide;
    child = slide ? followTheLeader(parent, child, length) : radial(parent, child, length);
    Contact total;
    if (!head || !head->collider) return total;
    const Vec3f start = child;
    const int rounds = slide ? 4 : 16;
    for (int iter = 0; iter < rounds; ++iter) {
        const Contact c = projectOut(*head, radius, child);
        if (!c.active) break;
        total.active = true;
        total.normal = c.normal;
        child = slide ? slideOnPlane(parent, child, length, c.normal) : radial(parent, child, length);
    }
    if (total.active) {
        // A last projection guarantees the clearance; it can only cost length
        // when the parent itself sits inside the clearance band.
        const Contact c = projectOut(*head, radius, child);
        if (c.active) total.normal = c.normal;
        total.push = std::max(0.f, (child - start).dot(total.normal));
    }
    return total;
}

Vec3f contactFriction(const Vec3f& v, const Vec3f& vs, const Contact& contact, float mu, float h) {
    if (!contact.active) return v;
    const Vec3f& n = contact.normal;
    const Vec3f rel = v - vs;
    const float vnRaw = rel.dot(n) - contact.push / h;  // what it would have been without the push
    const float vn = std::max(vnRaw, 0.f);
    const float removed = vn - vnRaw;                    // ≥ 0: approach speed the contact stopped
    Vec3f vt = rel - rel.dot(n) * n;
    const float vtLen = vt.norm();
    if (vtLen > 0.f) vt *= std::max(0.f, 1.f - mu * removed / vtLen);
    return vs + vn * n + vt;
}

}  // namespace hp::strand
