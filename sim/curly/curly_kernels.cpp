#include "sim/curly/curly_kernels.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace hp::curly {

float smoothingBeta(float edgeLength, float alpha) {
    if (!(alpha > 0.f)) return 1.f;
    return std::min(1.f, 1.f - std::exp(-edgeLength / alpha));
}

void smoothEdges(const Vec3f* lambda, size_t n, float beta, Vec3f* d, const Vec3f* start) {
    if (n < 2) return;
    const float a = 1.f - beta;
    const float c1 = 2.f * a, c2 = a * a, c3 = beta * beta;
    Vec3f d1 = start ? *start : Vec3f(lambda[1] - lambda[0]);  // d_{i-1}
    Vec3f d2 = d1;                     // d_{i-2}
    for (size_t i = 0; i + 1 < n; ++i) {
        const Vec3f di = c1 * d1 - c2 * d2 + c3 * (lambda[i + 1] - lambda[i]);
        d[i] = di;
        d2 = d1;
        d1 = di;
    }
}

Vec3f bendingCurveStart(const Vec3f* x, const Mat3f& root) { return root.col(1) * (x[1] - x[0]).norm(); }

void smoothedCurve(const Vec3f* lambda, size_t n, float beta, Vec3f* out) {
    if (n == 0) return;
    std::vector<Vec3f> d(n > 1 ? n - 1 : 0);
    smoothEdges(lambda, n, beta, d.data());
    out[0] = lambda[0];
    for (size_t i = 1; i < n; ++i) out[i] = out[i - 1] + d[i - 1];
}

namespace {
/// Unit vector, or `fallback` for a (near) zero vector.
inline Vec3f unitOr(const Vec3f& v, const Vec3f& fallback) {
    const float len = v.norm();
    return len > 1e-12f ? Vec3f(v / len) : fallback;
}
}  // namespace

void transportFrames(const Vec3f* d, size_t edges, const Mat3f& root, Mat3f* frames) {
    Vec3f prev = root.col(1);
    Mat3f F = root;
    for (size_t i = 0; i < edges; ++i) {
        const Vec3f t = unitOr(d[i], prev);
        F = Quatf::FromTwoVectors(prev, t).toRotationMatrix() * F;
        frames[i] = F;
        prev = t;
    }
}

namespace {
/// The axial spring-damper that the stretch spring (eq. 1) and the core
/// spring (eq. 5) both are, on an edge e with velocity difference Δv:
///   f = k(|e| - L)ê + c(Δv·ê)ê,
/// with |e| and êêᵀ kept for the callers' Jacobians. A (near) zero edge has
/// no direction: `valid` is false and the spring exerts nothing.
struct AxialSpring {
    bool valid = false;
    float length = 0.f;  ///< |e|
    Mat3f uu;            ///< êêᵀ
    Vec3f force;
};

AxialSpring axialSpring(const Vec3f& e, const Vec3f& dv, float restLength, float k, float c) {
    AxialSpring a;
    a.length = e.norm();
    if (!(a.length > 1e-12f)) return a;
    const Vec3f u = e / a.length;
    a.valid = true;
    a.uu = u * u.transpose();
    a.force = k * (a.length - restLength) * u + c * dv.dot(u) * u;
    return a;
}
}  // namespace

PairForce stretchSpring(const Vec3f& e, const Vec3f& dv, float restLength, float ks, float cs) {
    PairForce p;
    const AxialSpring a = axialSpring(e, dv, restLength, ks, cs);
    if (!a.valid) return p;
    p.force = a.force;
    p.K = ks * (a.uu + std::max(0.f, 1.f - restLength / a.length) * (Mat3f::Identity() - a.uu));
    p.C = cs * a.uu;
    return p;
}

PairForce bendingSpring(const Vec3f& e, const Vec3f& dv, const Vec3f& target, float kb, float cb) {
    PairForce p;
    const Vec3f u = unitOr(e, Vec3f::Zero());
    const Vec3f dvPerp = dv - dv.dot(u) * u;
    p.force = kb * (e - target) + cb * dvPerp;
    p.K = kb * Mat3f::Identity();
    p.C = cb * (Mat3f::Identity() - u * u.transpose());
    return p;
}

PairForce coreSpring(const Vec3f& b, float restLength, const Vec3f& nu, float kc, float cc, float tap) {
    PairForce p;
    const AxialSpring a = axialSpring(b, nu, restLength, kc, cc);
    if (!a.valid) return p;
    p.force = a.force;
    p.K = kc * tap * a.uu;
    p.C = cc * tap * a.uu;
    return p;
}

void solveBlockTridiagonal(Mat3f* diag, const Mat3f* upper, Vec3f* rhs, size_t n) {
    if (n == 0) return;
    // Forward elimination: D_i ← D_i - U_{i-1}ᵀ D_{i-1}⁻¹ U_{i-1}, r_i likewise.
    // diag[i] ends up holding the inverse of the eliminated block.
    diag[0] = diag[0].inverse().eval();
    for (size_t i = 1; i < n; ++i) {
        const Mat3f L = upper[i - 1].transpose() * diag[i - 1];
        diag[i] -= L * upper[i - 1];
        rhs[i] -= L * rhs[i - 1];
        diag[i] = diag[i].inverse().eval();
    }
    // Back substitution: x_i = D_i⁻¹ (r_i - U_i x_{i+1}).
    rhs[n - 1] = diag[n - 1] * rhs[n - 1];
    for (size_t i = n - 1; i-- > 0;) rhs[i] = diag[i] * (rhs[i] - upper[i] * rhs[i + 1]);
}

size_t limitRelativeVelocity(Vec3f* v, size_t n, float maxRelative) {
    size_t limited = 0;
    for (size_t i = 0; i + 1 < n; ++i) {
        const Vec3f dv = v[i + 1] - v[i];
        const float len = dv.norm();
        if (len <= maxRelative) continue;
        v[i + 1] = v[i] + dv * (maxRelative / len);
        ++limited;
    }
    return limited;
}

float perStepFactor(float factor, float h, float hRef) { return std::pow(factor, h / hRef); }

float strainLimited(float length, float restLength, float maxStrain) {
    return std::clamp(length, (1.f - maxStrain) * restLength, (1.f + maxStrain) * restLength);
}

void helixPoints(float radius, float pitch, float segment, size_t n, Vec3f* out) {
    const float c = pitch / float(2.0 * M_PI);
    const float speed = std::sqrt(radius * radius + c * c);  // arc length per unit t
    for (size_t k = 0; k < n; ++k) {
        const float s = float(k) * segment;
        if (!(speed > 0.f)) {
            out[k] = Vec3f(0.f, 0.f, s);
            continue;
        }
        const float t = s / speed;
        out[k] = Vec3f(radius * (std::cos(t) - 1.f), radius * std::sin(t), c * t);
    }
}

namespace {
float median(std::vector<float>& v) {
    if (v.empty()) return 0.f;
    const size_t mid = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + mid, v.end());
    float m = v[mid];
    if (v.size() % 2 == 0) m = 0.5f * (m + *std::max_element(v.begin(), v.begin() + mid));
    return m;
}
}  // namespace

HelixFit fitHelix(const Vec3f* p, size_t n, size_t skip) {
    HelixFit fit;
    if (n < 4) return fit;
    std::vector<float> radii, pitches;
    for (size_t i = std::max<size_t>(1, skip); i + 2 < n; ++i) {
        const Vec3f e0 = p[i] - p[i - 1], e1 = p[i + 1] - p[i], e2 = p[i + 2] - p[i + 1];
        Vec3f axis = (e1 - e0).cross(e2 - e1);
        const float an = axis.norm();
        // Straight or planar-zigzag stretches have no screw axis.
        const float scale = (e1 - e0).norm() * (e2 - e1).norm();
        if (!(an > 1e-3f * scale) || !(scale > 1e-20f)) continue;
        axis /= an;
        if (axis.dot(e1) < 0.f) axis = -axis;
        const Vec3f u = e0 - axis.dot(e0) * axis, w = e1 - axis.dot(e1) * axis;
        const float theta = std::atan2(u.cross(w).norm(), u.dot(w));
        if (!(theta > 1e-4f)) continue;
        pitches.push_back(float(2.0 * M_PI) * axis.dot(e1) / theta);
        radii.push_back(w.norm() / (2.f * std::sin(0.5f * theta)));
    }
    fit.samples = radii.size();
    fit.radius = median(radii);
    fit.pitch = median(pitches);
    return fit;
}

}  // namespace hp::curly
