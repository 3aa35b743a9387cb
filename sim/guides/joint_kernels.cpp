#include "sim/guides/joint_kernels.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <xmmintrin.h>

namespace hp::strand {

float springFraction(float stiffness, float inertia, float h) {
    const float k = stiffness * h * h;
    return k > 0.f ? k / (inertia + k) : 0.f;
}

namespace {

/// transport(), inlined into the joint passes' loops.
[[gnu::always_inline]] inline Quatf minimalRotation(const Vec3f& from, const Vec3f& to) {
    // For unit a, b the half-way quaternion (1 + a·b, a×b), normalised, is the
    // minimal rotation; only the antiparallel case needs Eigen's general path.
    const float w = 1.f + from.dot(to);
    if (w < 1e-6f) return Quatf::FromTwoVectors(from, to);
    const Vec3f v = from.cross(to);
    return Quatf(w, v.x(), v.y(), v.z()).normalized();
}

}  // namespace

Quatf transport(const Vec3f& from, const Vec3f& to) { return minimalRotation(from, to); }

float angleBetween(const Vec3f& a, const Vec3f& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

Vec3f rotateToAngle(const Vec3f& d, const Vec3f& axis, float angle) {
    Vec3f perp = d - axis * axis.dot(d);
    const float len = perp.norm();
    // d parallel to the axis: any perpendicular will do (only reached when
    // angle > 0 is asked of a direction at angle 0 or π).
    perp = len > 1e-12f ? Vec3f(perp / len) : Vec3f(axis.unitOrthogonal());
    return std::cos(angle) * axis + std::sin(angle) * perp;
}

namespace {

/// The Finish pass needs no frames: the projection limit bounds the angle
/// between consecutive segments to rest bend ± (limit + projection), the
/// same cone as the frames give for a straight rest and its ring otherwise.
void finish(Vec3f* x, int vertexCount, const Mat3f& rootFrame, const JointParams& p, const HeadQuery* head,
            float radius, Contact* contacts) {
    if (contacts) contacts[0] = Contact{};
    const float reach = p.limit + p.projection;
    Vec3f u = rootFrame * p.restDir[0];  // the virtual follicle segment's direction
    for (int j = 0; j + 1 < vertexCount; ++j) {
        const Vec3f& parent = x[j];
        Vec3f e = x[j + 1] - parent;
        const float len = e.norm();
        Vec3f w = len > 1e-12f ? Vec3f(e / len) : u;
        const float bend = p.restBend[j];
        const float c = u.dot(w);
        if (c < p.cosMostBend[j])
            w = rotateToAngle(w, u, bend + reach);
        else if (c > p.cosLeastBend[j])
            w = rotateToAngle(w, u, bend - reach);
        Vec3f child = parent + p.restLength[j] * w;
        const Contact k = placeSegment(parent, child, p.restLength[j], head, radius);
        if (contacts) contacts[j + 1] = k;
        x[j + 1] = child;
        u = (child - parent).normalized();
    }
}

}  // namespace

namespace {

/// Where the Drive pass stands along one strand: joint j's frame Q and the
/// carries of the joints above composed into one rigid map (C, c), so that
/// vertex i's current position is C·x_i + c. Carrying every subtree
/// explicitly would cost O(n²).
struct DriveState {
    Quatf Q;
    Quatf C = Quatf::Identity();
    Vec3f c = Vec3f::Zero();
    explicit DriveState(const Mat3f& rootFrame) : Q(rootFrame) {}
};

/// Joint j as the pass finds it: its parent vertex, its child as the turns
/// above carry it, the rest direction in the transported frame, and the
/// child's direction (the rest direction when the segment has collapsed).
struct JointView {
    Vec3f parent, oldChild, rest, d;
    float length;
};

[[gnu::always_inline]] inline JointView viewJoint(const DriveState& s, const Vec3f* x, int j, const JointParams& p) {
    JointView v;
    v.parent = x[j];
    v.oldChild = s.C * x[j + 1] + s.c;
    v.length = p.restLength[j];
    v.rest = s.Q * p.restDir[j];
    const Vec3f e = v.oldChild - v.parent;
    const float len = e.norm();
    v.d = len > 1e-12f ? Vec3f(e / len) : v.rest;
    return v;
}

/// Sets joint j's segment to direction `dir` at its rest length, carrying
/// the subtree with the turn and the length fix (a joint drive moves what
/// hangs from it), and turns the transported frame on.
[[gnu::always_inline]] inline void turnJoint(DriveState& s, Vec3f* x, int j, const JointView& v, const Vec3f& dir) {
    const Quatf q = minimalRotation(v.d, dir);
    s.C = q * s.C;
    s.c = v.parent + v.length * dir + q * (s.c - v.oldChild);
    x[j + 1] = v.parent + v.length * dir;
    s.Q = minimalRotation(v.rest, dir) * s.Q;
    s.Q.normalize();  // keep rounding from accumulating over the chain
}

/// Joint j of the Drive pass: the implicit spring on the segment's end,
/// x ← x + f·(x* - x), renormalised onto the segment's length.
/// driveLanes repeats these statements in SIMD lanes.
inline void driveJoint(DriveState& s, Vec3f* x, int j, const JointParams& p) {
    const JointView v = viewJoint(s, x, j, p);
    const float f = p.spring[j];
    const Vec3f dir = ((1.f - f) * v.d + f * (s.Q * p.springDir[j])).normalized();
    turnJoint(s, x, j, v, dir);
}

/// The Drive pass of one strand.
void driveStrand(Vec3f* x, int vertexCount, const Mat3f& rootFrame, const JointParams& p) {
    DriveState s(rootFrame);
    for (int j = 0; j + 1 < vertexCount; ++j) driveJoint(s, x, j, p);
}

}  // namespace

void relaxJoints(JointPass pass, Vec3f* x, int vertexCount, const Mat3f& rootFrame, const JointParams& p,
                 const HeadQuery* head, float radius, Contact* contacts) {
    if (pass == JointPass::Finish) return finish(x, vertexCount, rootFrame, p, head, radius, contacts);
    if (pass == JointPass::Drive) return driveStrand(x, vertexCount, rootFrame, p);
    // SolvePreload, with the Drive pass's frames and carries.
    DriveState s(rootFrame);
    for (int j = 0; j + 1 < vertexCount; ++j) {
        const JointView v = viewJoint(s, x, j, p);
        const Vec3f& rest = v.rest;
        const Vec3f& d = v.d;
        const float f = p.spring[j];
        // Aim past the rest direction r so that the spring step lands on it:
        // normalize((1-f)·d + f·t) = r with |t| = 1 gives
        // t = (λ·r - (1-f)·d)/f, λ the positive root of
        // λ² - 2λ(1-f)(r·d) + (1-f)² - f² = 0.
        Vec3f target = rest;
        if (f > 0.f) {
            const float g = 1.f - f, cd = rest.dot(d);
            const float lambda = g * cd + std::sqrt(std::max(0.f, g * g * cd * cd - g * g + f * f));
            target = ((lambda * rest - g * d) / f).normalized();
            // A pre-bend far beyond the joint's limit makes a soft joint
            // unstable; such a joint keeps some sag instead.
            if (angleBetween(target, rest) > 2.f * p.limit) target = rotateToAngle(target, rest, 2.f * p.limit);
        }
        p.springDir[j] = s.Q.conjugate() * target;
        // The vertex goes back onto the rest shape, what hangs below with it.
        turnJoint(s, x, j, v, rest);
    }
}

namespace {

// Four strands' Drive passes in SIMD lanes (GCC vector extensions, SSE).
// Each lane repeats exactly the operations, in the same order, that Eigen
// performs for driveJoint (Eigen 3.4: cross products scalar; 3-term sums
// split in halves, a + (b + c); quaternion products by its SSE kernel;
// 4-vector norms as (x² + z²) + (y² + w²)), and IEEE +, -, ×, ÷ and √ are
// exact per lane, so the lanes give the one-strand results bit for bit
// (tested).
typedef float f4 __attribute__((vector_size(16)));
typedef int32_t i4 __attribute__((vector_size(16)));

inline f4 splat4(float x) { return f4{x, x, x, x}; }
inline f4 sqrt4(f4 x) { return f4(_mm_sqrt_ps(__m128(x))); }
inline bool anyLane(i4 m) { return (m[0] | m[1] | m[2] | m[3]) != 0; }

struct V3 {
    f4 x, y, z;
};
struct Q4 {
    f4 x, y, z, w;
};

inline V3 cross(const V3& a, const V3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
/// Eigen's 3-term sums split in halves: a₀b₀ + (a₁b₁ + a₂b₂).
inline f4 dot(const V3& a, const V3& b) { return a.x * b.x + (a.y * b.y + a.z * b.z); }
/// Eigen's QuaternionBase::_transformVector.
inline V3 rotate(const Q4& q, const V3& v) {
    const V3 qv{q.x, q.y, q.z};
    V3 uv = cross(qv, v);
    uv = {uv.x + uv.x, uv.y + uv.y, uv.z + uv.z};
    const V3 c = cross(qv, uv);
    return {(v.x + q.w * uv.x) + c.x, (v.y + q.w * uv.y) + c.y, (v.z + q.w * uv.z) + c.z};
}
/// Eigen's SSE quaternion product (quat_product, Geometry_SIMD.h).
inline Q4 multiply(const Q4& a, const Q4& b) {
    return {(a.x * b.w - a.z * b.y) + (a.y * b.z + a.w * b.x), (a.y * b.w - a.x * b.z) + (a.z * b.x + a.w * b.y),
            (a.z * b.w - a.y * b.x) + (a.x * b.y + a.w * b.z), (a.w * b.w - a.x * b.x) + -(a.z * b.z + a.y * b.y)};
}
/// Quaternion normalize(): coefficients over √ of their SSE-reduced squared norm.
inline Q4 normalized(const Q4& q) {
    const f4 n = (q.x * q.x + q.z * q.z) + (q.y * q.y + q.w * q.w);
    const i4 ok = n > splat4(0.f);
    const f4 s = sqrt4(n);
    return {ok ? q.x / s : q.x, ok ? q.y / s : q.y, ok ? q.z / s : q.z, ok ? q.w / s : q.w};
}
/// minimalRotation in lanes; the rare antiparallel lanes take Eigen's general path.
[[gnu::always_inline]] inline Q4 minimalRotation4(const V3& from, const V3& to) {
    const f4 w = splat4(1.f) + dot(from, to);
    const V3 v = cross(from, to);
    Q4 q = normalized(Q4{v.x, v.y, v.z, w});
    const i4 general = w < splat4(1e-6f);
    if (anyLane(general))
        for (int k = 0; k < 4; ++k)
            if (general[k]) {
                const Quatf r = minimalRotation(Vec3f(from.x[k], from.y[k], from.z[k]), Vec3f(to.x[k], to.y[k], to.z[k]));
                q.x[k] = r.x();
                q.y[k] = r.y();
                q.z[k] = r.z();
                q.w[k] = r.w();
            }
    return q;
}

inline V3 gather(const Vec3f* const* a, int j) {
    return {f4{a[0][j].x(), a[1][j].x(), a[2][j].x(), a[3][j].x()},
            f4{a[0][j].y(), a[1][j].y(), a[2][j].y(), a[3][j].y()},
            f4{a[0][j].z(), a[1][j].z(), a[2][j].z(), a[3][j].z()}};
}

/// Four strands' Drive passes, one per lane: driveJoint's statements one for one.
void driveLanes(Vec3f* const* x, int vertexCount, const Mat3f* rootFrames, const JointParams* p) {
    Q4 Q, C{splat4(0.f), splat4(0.f), splat4(0.f), splat4(1.f)};
    V3 c{splat4(0.f), splat4(0.f), splat4(0.f)};
    for (int k = 0; k < 4; ++k) {
        const Quatf q(rootFrames[k]);
        Q.x[k] = q.x();
        Q.y[k] = q.y();
        Q.z[k] = q.z();
        Q.w[k] = q.w();
    }
    const Vec3f* restDir[4] = {p[0].restDir, p[1].restDir, p[2].restDir, p[3].restDir};
    const Vec3f* springDir[4] = {p[0].springDir, p[1].springDir, p[2].springDir, p[3].springDir};
    const Vec3f* xs[4] = {x[0], x[1], x[2], x[3]};
    V3 parent = gather(xs, 0);
    for (int j = 0; j + 1 < vertexCount; ++j) {
        const V3 child = gather(xs, j + 1);
        const V3 rc = rotate(C, child);
        const V3 oldChild{rc.x + c.x, rc.y + c.y, rc.z + c.z};
        const f4 length{p[0].restLength[j], p[1].restLength[j], p[2].restLength[j], p[3].restLength[j]};
        const V3 rest = rotate(Q, gather(restDir, j));
        const V3 e{oldChild.x - parent.x, oldChild.y - parent.y, oldChild.z - parent.z};
        const f4 len = sqrt4(dot(e, e));
        const i4 long_ = len > splat4(1e-12f);
        const V3 d{long_ ? e.x / len : rest.x, long_ ? e.y / len : rest.y, long_ ? e.z / len : rest.z};
        const f4 f{p[0].spring[j], p[1].spring[j], p[2].spring[j], p[3].spring[j]};
        const f4 g = splat4(1.f) - f;
        const V3 t = rotate(Q, gather(springDir, j));
        const V3 u{g * d.x + f * t.x, g * d.y + f * t.y, g * d.z + f * t.z};
        const f4 z = dot(u, u);
        const i4 nonzero = z > splat4(0.f);
        const f4 sz = sqrt4(z);
        const V3 dir{nonzero ? u.x / sz : u.x, nonzero ? u.y / sz : u.y, nonzero ? u.z / sz : u.z};
        const Q4 q = minimalRotation4(d, dir);
        C = multiply(q, C);
        const V3 placed{parent.x + length * dir.x, parent.y + length * dir.y, parent.z + length * dir.z};
        const V3 r = rotate(q, V3{c.x - oldChild.x, c.y - oldChild.y, c.z - oldChild.z});
        c = {placed.x + r.x, placed.y + r.y, placed.z + r.z};
        for (int k = 0; k < 4; ++k) x[k][j + 1] = Vec3f(placed.x[k], placed.y[k], placed.z[k]);
        Q = normalized(multiply(minimalRotation4(rest, dir), Q));
        parent = placed;
    }
}

}  // namespace

void driveJoints(int count, Vec3f* const* x, int vertexCount, const Mat3f* rootFrames, const JointParams* joints) {
    int b = 0;
    for (; b + 4 <= count; b += 4) driveLanes(x + b, vertexCount, rootFrames + b, joints + b);
    for (; b < count; ++b) driveStrand(x[b], vertexCount, rootFrames[b], joints[b]);
}

void bendBounds(const Vec3f* restDir, int segments, float reach, float* restBend, float* cosMostBend,
                float* cosLeastBend) {
    for (int j = 0; j < segments; ++j) {
        restBend[j] = j > 0 ? angleBetween(restDir[j - 1], restDir[j]) : 0.f;
        cosMostBend[j] = std::cos(std::min(restBend[j] + reach, float(M_PI)));
        cosLeastBend[j] = restBend[j] > reach ? std::cos(restBend[j] - reach) : 2.f;  // 2: never
    }
}

void bendLimitSpan(const float* restLength, const Vec3f* restDir, int segments, float limit, float* minSpan,
                   float* maxSpan) {
    for (int j = 0; j < segments; ++j) {
        const float l0 = restLength[j > 0 ? j - 1 : 0], l1 = restLength[j];
        const float rest = j > 0 ? angleBetween(restDir[j - 1], restDir[j]) : 0.f;
        auto span = [&](float angle) { return std::sqrt(l0 * l0 + l1 * l1 + 2.f * l0 * l1 * std::cos(angle)); };
        minSpan[j] = span(std::min(rest + limit, float(M_PI)));
        // A joint whose rest bend is within the limit may straighten fully:
        // no upper bound (D(0) would also catch mere stretch mid-solve).
        maxSpan[j] = rest > limit ? span(rest - limit) : std::numeric_limits<float>::infinity();
    }
}

void limitSpan(Vec3f& a, Vec3f& b, float wa, float wb, float minSpan, float maxSpan, float fraction) {
    const Vec3f e = b - a;
    const float d2 = e.squaredNorm();
    if (d2 >= minSpan * minSpan && d2 <= maxSpan * maxSpan) return;  // the common case, no sqrt
    const float w = wa + wb;
    if (w <= 0.f || d2 <= 0.f) return;
    const float d = std::sqrt(d2);
    const float excess = d < minSpan ? d - minSpan : d - maxSpan;
    const Vec3f corr = (fraction * excess / (d * w)) * e;
    a += wa * corr;
    b -= wb * corr;
}

}  // namespace hp::strand
