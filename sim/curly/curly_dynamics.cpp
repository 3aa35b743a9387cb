#include "sim/curly/curly_dynamics.h"

#include <algorithm>
#include <cmath>

namespace hp::curly {

void StrandScratch::resize(size_t n) {
    const size_t e = n > 0 ? n - 1 : 0;
    d.resize(e);
    b.resize(e);
    nu.resize(e);
    curl.resize(e);
    frames.resize(e);
    force.resize(n);
    rhs.resize(n);
    diag.resize(n);
    upper.resize(n);
}

MaterialSprings materialSprings(const rod::Material& m, float R, float P, float l, float mass, float h) {
    MaterialSprings out;
    out.massPerLength = float(m.massPerLength());
    const double mu = mass >= 0.f ? double(mass) : m.massPerLength();
    out.ks = float(1e4 * mu * l / (double(h) * h));
    const double EI = m.bendStiffness(), GJ = m.twistStiffness();
    double kb = EI / (double(l) * l * l);  // the straight rod's cap
    if (R > 0.f) {
        const double alpha = std::atan2(double(P), 2.0 * M_PI * R);
        const double c2 = std::cos(alpha) * std::cos(alpha), s2 = 1.0 - c2;
        const double compliance = double(R) * R * l * (c2 / GJ + s2 / EI);  // c_l, m/N
        kb = std::min(kb, c2 / compliance);
    }
    out.kb = float(kb);
    out.kc = 0.f;
    return out;
}

bool implicitStep(const Vec3f* x, const Vec3f* v, size_t n, const Mat3f& root, const Vec3f& rootVelocity,
                  const StrandRest& rest, const StrandCoefficients& k, const StrandLoads& loads, float h,
                  StrandScratch& s, Vec3f* dv) {
    if (n < 2) {
        if (n == 1) dv[0] = rootVelocity - v[0];
        return true;
    }
    s.resize(n);
    const size_t edges = n - 1;
    // Bending frames on the smoothed curve (eq. 2-3), core edges b_i and the
    // smoothed velocity differences ν_i (eq. 5).
    const Vec3f start = bendingCurveStart(x, root);
    smoothEdges(x, n, k.betaBend, s.d.data(), &start);
    transportFrames(s.d.data(), edges, root, s.frames.data());
    if (k.kc > 0.f || k.cc > 0.f) {
        smoothEdges(x, n, k.betaCore, s.b.data());
        smoothEdges(v, n, k.betaCore, s.nu.data());
    }
    bool wet = false;
    if (loads.sigma && k.curlWeight > 0.f)
        for (size_t i = 0; i < n && !wet; ++i) wet = loads.sigma[i] > 0.f;
    if (wet) curlForces(x, n, rest.helix, root, loads.sigma, k.curlWeight, s.curl.data());

    for (size_t i = 0; i < n; ++i) {
        s.force[i].setZero();
        s.rhs[i].setZero();
        s.diag[i].setZero();
        s.upper[i].setZero();
    }
    const float tap = k.betaCore * k.betaCore;
    for (size_t i = 0; i < edges; ++i) {
        const Vec3f e = x[i + 1] - x[i];
        const Vec3f dvp = v[i + 1] - v[i];
        PairForce p = stretchSpring(e, dvp, rest.edgeLength[i], k.ks, k.cs);
        const PairForce bend = bendingSpring(e, dvp, s.frames[i] * rest.bendTarget[i], k.kb, k.cb);
        p.force += bend.force;
        p.K += bend.K;
        p.C += bend.C;
        if (k.kc > 0.f || k.cc > 0.f) {
            const PairForce core = coreSpring(s.b[i], rest.coreLength[i], s.nu[i], k.kc, k.cc, tap);
            p.force += core.force;
            p.K += core.K;
            p.C += core.C;
        }
        if (wet) {
            // Only the part across the edge turns it; the part along it is
            // what the inextensible link absorbs, so it is left out rather
            // than loading the stretch spring. Its transverse (geometric)
            // stiffness (f·ê)/|e| (I - êêᵀ) is what keeps a strong curl
            // force stable at a large step.
            const float len = e.norm();
            if (len > 1e-12f) {
                const Vec3f u = e / len;
                const Mat3f P = Mat3f::Identity() - u * u.transpose();
                p.force -= P * s.curl[i];  // the child gets +f, the parent -f
                p.K += (std::max(0.f, s.curl[i].dot(u)) / len) * P;
            }
        }
        s.force[i] += p.force;
        s.force[i + 1] -= p.force;
        const Mat3f B = h * p.C + h * h * p.K;
        s.diag[i] += B;
        s.diag[i + 1] += B;
        s.upper[i] -= B;  // A(i, i+1)
        const Vec3f kv = h * h * (p.K * dvp);
        s.rhs[i] += kv;
        s.rhs[i + 1] -= kv;
    }
    for (size_t i = 1; i < n; ++i) {
        const float m = rest.mass[i];
        Vec3f a = k.gravity;
        if (loads.acceleration) a += loads.acceleration[i];
        float kCoh = 0.f;
        if (loads.cohesion && k.cohesionStiffness > 0.f) {
            a += k.cohesionStiffness * loads.cohesion[i].offset;
            kCoh = k.cohesionStiffness * loads.cohesion[i].weight;
        }
        s.rhs[i] += h * (s.force[i] + m * a);
        s.diag[i] += (m * (1.f + h * h * kCoh)) * Mat3f::Identity();
    }
    // The kinematic root: its known Δv_0 moves to the right-hand side,
    // r_1 -= A(1, 0) Δv_0 with A(1, 0) = U_0ᵀ.
    dv[0] = rootVelocity - v[0];
    s.rhs[1] -= s.upper[0].transpose() * dv[0];
    solveBlockTridiagonal(&s.diag[1], &s.upper[1], &s.rhs[1], edges);
    bool finite = true;
    for (size_t i = 1; i < n; ++i) {
        dv[i] = s.rhs[i];
        finite = finite && dv[i].allFinite();
    }
    return finite;
}

void restData(const Vec3f* p, size_t n, const Mat3f& root, const StrandCoefficients& k, const float* mass,
              bool preload, float* edgeLength, Vec3f* bendTarget, float* coreLength) {
    if (n < 2) return;
    const size_t edges = n - 1;
    std::vector<Vec3f> d(edges), b(edges);
    std::vector<Mat3f> frames(edges);
    const Vec3f start = bendingCurveStart(p, root);
    smoothEdges(p, n, k.betaBend, d.data(), &start);
    transportFrames(d.data(), edges, root, frames.data());
    smoothEdges(p, n, k.betaCore, b.data());
    Vec3f weight = Vec3f::Zero();  // W_i = g Σ_{k>i} m_k
    for (size_t i = edges; i-- > 0;) {
        weight += mass[i + 1] * k.gravity;
        const Vec3f e = p[i + 1] - p[i];
        edgeLength[i] = e.norm();
        Vec3f t = e;
        if (preload && k.kb > 0.f) t -= weight / k.kb;
        bendTarget[i] = frames[i].transpose() * t;
        coreLength[i] = b[i].norm();
    }
}

}  // namespace hp::curly
