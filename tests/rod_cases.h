// The rod formulation's validation cases (tests/test_rod.cpp asserts them,
// tools/bench/bench_rod.cpp reports them): a strand is run through the
// GuideSolver and measured against a reference computed here, never from
// the solver: the heavy elastica by shooting (RK4 + bisection), the hanging
// chain's first mode in closed form (Bessel J0), the energy balance.
#pragma once

#include "sim/guides/guides.h"
#include "sim/guides/rod_kernels.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

namespace hp::rodcases {

constexpr float kLength = 0.25f;  ///< m
constexpr double kG = 9.81;       ///< m/s²

/// A rod strand's settings: no head, given Young's modulus and drag.
inline GuideSettings rodSettings(float youngs, float drag, bool preload) {
    GuideSettings s;
    s.formulation = GuideFormulation::Rod;
    s.length = kLength;
    s.youngsModulus = youngs;
    s.damping = drag;
    s.preload = preload;
    s.headCollision = false;
    s.maxSpeed = 0.f;
    s.tipRadius = s.rootRadius;  // a uniform fibre: the references below assume one
    return s;
}

/// The settings' section as a rod::Material.
inline rod::Material material(const GuideSettings& s) {
    rod::Material m;
    m.youngs = s.youngsModulus;
    m.radius = s.rootRadius;
    m.tipRadius = s.taperedFibre ? s.tipRadius : s.rootRadius;
    m.hairsPerGuide = s.hairsPerGuide;
    m.density = s.density;
    return m;
}

/// Young's modulus giving the strand β = wL³/EI (w = μg).
inline float youngsFor(const GuideSettings& s, double beta) {
    rod::Material m = material(s);
    m.youngs = 1.f;
    return float(m.massPerLength() * kG * std::pow(double(s.length), 3) / beta / m.bendStiffness());
}

/// Free strands rooted at the origin (root frame: normal +x, tangent +z).
struct Strand {
    GuideSolver solver;
    std::vector<SurfaceFrame> roots;
    StepStats worst;
    Strand(const GuideSettings& s, const std::vector<Vec3f>& shape, size_t copies = 1) : solver(s) {
        SurfaceFrame f;
        f.normal = Vec3f::UnitX();
        f.tangent = Vec3f::UnitZ();
        roots.assign(copies, f);
        const std::vector<std::vector<Vec3f>> groom(copies, shape);
        solver.initialize(roots, HeadPose{}, &groom);
    }
    /// Steps for `seconds`; `each(frame)` sees every step's state.
    void run(double seconds, const std::function<void(const StrandFrame&)>& each = {}) {
        StrandFrame frame;
        const int steps = int(std::lround(seconds / solver.settings().timeStep));
        for (int k = 0; k < steps; ++k) {
            HeadPose pose;
            pose.time = solver.nextTime();
            worst.accumulate(solver.step(roots, pose));
            if (each) {
                solver.write(frame);
                each(frame);
            }
        }
    }
    StrandFrame frame() const {
        StrandFrame f;
        solver.write(f);
        return f;
    }
};

/// A straight strand of `segments` from the origin along `dir`.
inline std::vector<Vec3f> straight(const Vec3f& dir, int segments) {
    std::vector<Vec3f> x(size_t(segments) + 1);
    for (int i = 0; i <= segments; ++i) x[size_t(i)] = dir * (kLength * float(i) / float(segments));
    return x;
}

/// Heavy elastica: θ'' = -(β/L³)(L-s) cos θ, θ(0) = 0, θ'(L) = 0 (θ below the
/// horizontal), by shooting on θ'(0) with RK4 and bisection. Returns the tip
/// (x along the clamp, y up).
inline Vec3f elasticaTip(double beta, double L) {
    const double k = beta / (L * L * L);
    auto rhs = [&](double s, double th) { return -k * (L - s) * std::cos(th); };
    // Returns θ'(L), or the first negative θ' on the way; the tip in *tip.
    auto shoot = [&](double p, Vec3f* tip) {
        const int n = 4000;
        const double ds = L / n;
        double th = 0, om = p, x = 0, y = 0;
        for (int i = 0; i < n; ++i) {
            const double s = i * ds;
            const double a1 = om, b1 = rhs(s, th);
            const double a2 = om + ds / 2 * b1, b2 = rhs(s + ds / 2, th + ds / 2 * a1);
            const double a3 = om + ds / 2 * b2, b3 = rhs(s + ds / 2, th + ds / 2 * a2);
            const double a4 = om + ds * b3, b4 = rhs(s + ds, th + ds * a3);
            // The position with the same stages' angles (Simpson).
            const double t2 = th + ds / 2 * a1, t3 = th + ds / 2 * a2, t4 = th + ds * a3;
            x += ds / 6 * (std::cos(th) + 2 * std::cos(t2) + 2 * std::cos(t3) + std::cos(t4));
            y -= ds / 6 * (std::sin(th) + 2 * std::sin(t2) + 2 * std::sin(t3) + std::sin(t4));
            th += ds / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
            om += ds / 6 * (b1 + 2 * b2 + 2 * b3 + b4);
            if (om < 0) return om;  // turned back up before the tip: θ'(0) too small
        }
        if (tip) *tip = Vec3f(float(x), float(y), 0.f);
        return om;
    };
    // On the hanging branch θ' ≥ 0 along the strand: a θ'(0) for which θ'
    // turns negative before the tip is too small, one that leaves θ'(L) > 0
    // too large (a monotone test, where θ'(L) alone is not: small θ'(0)
    // spirals). θ'(0) ≤ kL²/2 since cos θ ≤ 1.
    double lo = 0, hi = k * L * L / 2;
    for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        (shoot(mid, nullptr) < 0 ? lo : hi) = mid;
    }
    Vec3f tip;
    shoot(hi, &tip);  // hi: the side that reaches the tip
    return tip;
}

struct Cantilever {
    float error = 0;               ///< |tip - elastica tip| / L
    double maxStretch = 0;         ///< max |l/l0 - 1| over the run
    double kineticEnergy = 0;      ///< J, at the end (static: ~0)
    std::vector<Vec3f> positions;  ///< final state, for determinism checks
};

/// A strand of `segments` segments clamped horizontally (5 copies, groups
/// of 2 so threads share the work), settled with drag for 6 s; its tip
/// against the elastica.
inline Cantilever cantilever(double beta, int threads, int segments = 23) {
    GuideSettings s = rodSettings(0.f, 4.f, false);
    s.segments = segments;
    s.youngsModulus = youngsFor(s, beta);
    s.threads = threads;
    s.strandsPerWorld = 2;
    Strand strand(s, straight(Vec3f::UnitX(), s.segments), 5);
    strand.run(6.0);
    const StrandFrame f = strand.frame();
    Cantilever c;
    const Vec3f tip = f.positions[f.vertexCount(size_t(0)) - 1];
    c.error = (tip - elasticaTip(beta, kLength)).norm() / kLength;
    c.maxStretch = strand.worst.maxLengthError;
    c.kineticEnergy = strand.solver.lastStats().kineticEnergy;
    c.positions = f.positions;
    return c;
}

/// Small-load tip deflection of a horizontally clamped tapered strand
/// (linear beam theory): with w(s) = μ(s)·g its weight per length,
///   V(s) = ∫_s^L w,   M(s) = ∫_s^L V,   δ = ∫_0^L M(s)/EI(s)·(L - s) ds
/// (the moment-area theorem), by the trapezoid rule on `n` intervals.
inline double taperedTipDeflection(const rod::Material& m, double L, int n = 20000) {
    const double ds = L / n;
    std::vector<double> w(size_t(n) + 1), V(size_t(n) + 1, 0.0), M(size_t(n) + 1, 0.0);
    for (int i = 0; i <= n; ++i) {
        const double r = m.radiusAt(double(i) / n);
        w[size_t(i)] = double(m.hairsPerGuide) * m.density * M_PI * r * r * kG;
    }
    for (int i = n - 1; i >= 0; --i) {
        V[size_t(i)] = V[size_t(i) + 1] + 0.5 * ds * (w[size_t(i)] + w[size_t(i) + 1]);
        M[size_t(i)] = M[size_t(i) + 1] + 0.5 * ds * (V[size_t(i)] + V[size_t(i) + 1]);
    }
    double delta = 0;
    for (int i = 0; i < n; ++i) {
        auto f = [&](int k) { return M[size_t(k)] / m.bendStiffnessAt(double(k) / n) * (L - k * ds); };
        delta += 0.5 * ds * (f(i) + f(i + 1));
    }
    return delta;
}

struct Pendulum {
    double period = 0, reference = 0, error = 0, maxStretch = 0;
    size_t crossings = 0;
};

/// Hanging chain (E = 0), started in its first mode with 1% of L amplitude:
/// u(z) ∝ J0(2ω·sqrt(z/g)), z from the free end; J0(j01) = 0 at the root
/// gives ω = (j01/2)·sqrt(g/L), T1 = 4π/j01·sqrt(L/g). The period is taken
/// from the tip's zero crossings over 4 s.
inline Pendulum pendulum() {
    const double j01 = 2.404825557695773;
    const GuideSettings s = rodSettings(0.f, 0.f, false);
    std::vector<Vec3f> x(size_t(s.segments) + 1);
    const float amp = 0.01f * kLength;
    for (int i = 0; i <= s.segments; ++i) {
        const double arc = kLength * double(i) / s.segments, z = kLength - arc;
        x[size_t(i)] = Vec3f(amp * float(std::cyl_bessel_j(0.0, j01 * std::sqrt(z / kLength))), -float(arc), 0.f);
    }
    Strand strand(s, x);
    std::vector<double> crossings;
    double prev = x.back().x(), t = 0;
    strand.run(4.0, [&](const StrandFrame& f) {
        const double now = f.positions[f.vertexCount() - 1].x();
        t += s.timeStep;
        if ((prev < 0) != (now < 0)) crossings.push_back(t - s.timeStep * now / (now - prev));
        prev = now;
    });
    Pendulum p;
    p.crossings = crossings.size();
    p.reference = 4 * M_PI / j01 * std::sqrt(kLength / kG);
    if (crossings.size() >= 2)
        p.period = 2 * (crossings.back() - crossings.front()) / double(crossings.size() - 1);
    p.error = std::abs(p.period / p.reference - 1);
    p.maxStretch = strand.worst.maxLengthError;
    return p;
}

/// The undamped hanging chain's swing (E = 0, no drag): the first mode
/// of pendulum() at `amplitude`·L, run for 4 s.
///   energy in play  E(t) = Σ ½ m_i |v_i|² + Σ m_i g (y_i - y_i^rest),
///     y^rest the chain hanging straight down at its rest lengths (its lowest
///     energy), so E → 0 as the swing dies;
///   energyKept2s    E(2 s) / E(0) (1 for an integrator that keeps energy);
///   logDecrement    δ = ln(A_k / A_{k+1}) per period, from the tip's
///                   extremes A (its horizontal offset's turning points,
///                   alternating sign, two per period) over the run;
///   period          from the tip's zero crossings, against
///                   T1 = 4π/j01·sqrt(L/g) (pendulum()).
/// For a linear mode E ∝ A², so E(t)/E(0) = exp(-2δ t/T1).
struct Swing {
    double energyKept2s = 0, logDecrement = 0, period = 0, reference = 0, periodError = 0, maxStretch = 0;
    size_t extremes = 0;
};

inline Swing swing(GuideSettings s, double amplitude = 0.05) {
    const double j01 = 2.404825557695773;
    s.youngsModulus = 0.f;
    s.damping = 0.f;
    s.preload = false;
    s.headCollision = false;
    s.maxSpeed = 0.f;
    std::vector<Vec3f> x(size_t(s.segments) + 1);
    const float amp = float(amplitude) * s.length;
    for (int i = 0; i <= s.segments; ++i) {
        const double arc = double(s.length) * i / s.segments, z = s.length - arc;
        x[size_t(i)] = Vec3f(amp * float(std::cyl_bessel_j(0.0, j01 * std::sqrt(z / s.length))), -float(arc), 0.f);
    }
    const rod::Material m = material(s);
    std::vector<double> mass(x.size(), 0.0), restY(x.size(), 0.0);
    for (size_t i = 1; i < x.size(); ++i) {
        const double l = (x[i] - x[i - 1]).norm();  // the groom's rest lengths
        mass[i - 1] += i > 1 ? 0.5 * m.massPerLength() * l : 0.0;
        mass[i] += 0.5 * m.massPerLength() * l;
        restY[i] = restY[i - 1] - l;
    }
    auto energy = [&](const StrandFrame& f) {
        double e = 0;
        for (size_t i = 1; i < x.size(); ++i)
            e += 0.5 * mass[i] * double(f.velocities[i].squaredNorm()) +
                 mass[i] * kG * (double(f.positions[i].y()) - restY[i]);
        return e;
    };
    Strand strand(s, x);
    const double e0 = energy(strand.frame());
    Swing r;
    r.reference = 4 * M_PI / j01 * std::sqrt(double(s.length) / kG);
    std::vector<double> crossings, extremes;
    double prev = x.back().x(), prevSlope = 0, t = 0;
    strand.run(4.0, [&](const StrandFrame& f) {
        const double now = f.positions[f.vertexCount() - 1].x();
        t += s.timeStep;
        if (std::abs(t - 2.0) < 0.5 * s.timeStep) r.energyKept2s = energy(f) / e0;
        if ((prev < 0) != (now < 0)) crossings.push_back(t - s.timeStep * now / (now - prev));
        const double slope = now - prev;
        if (t > 1.5 * s.timeStep && (slope < 0) != (prevSlope < 0)) extremes.push_back(std::abs(prev));
        prev = now;
        prevSlope = slope;
    });
    // The start is the first extreme (released at rest at amplitude).
    extremes.insert(extremes.begin(), std::abs(double(x.back().x())));
    r.extremes = extremes.size();
    if (extremes.size() >= 3)
        r.logDecrement = 2.0 * std::log(extremes.front() / extremes.back()) / double(extremes.size() - 1);
    if (crossings.size() >= 2)
        r.period = 2 * (crossings.back() - crossings.front()) / double(crossings.size() - 1);
    r.periodError = std::abs(r.period / r.reference - 1);
    r.maxStretch = strand.worst.maxLengthError;
    return r;
}

/// Kinetic + gravitational (root at height 0) + bending energy of strand 0,
/// straight at rest, not pre-loaded, root frame as in Strand.
inline double totalEnergy(const GuideSettings& s, const StrandFrame& f) {
    const rod::Material m = material(s);
    const int n = int(f.vertexCount(size_t(0)));
    const float l = kLength / float(n - 1);
    std::vector<float> rest(size_t(n - 1), l), w(size_t(n), 0.f);
    std::vector<rod::Vec2f> c(size_t(n - 1), rod::Vec2f::Zero());
    rod::RodStrand rs;
    rs.vertices = n;
    rs.restLength = rest.data();
    rs.invMass = w.data();
    rs.restCurvature = c.data();
    rs.ghostDir = Vec3f::UnitY();  // the first segment along the root normal, root-local
    rs.bendStiffness = m.bendStiffness();
    const strand::Mat3f R = strand::rootRotation(SurfaceFrame{Vec3f::Zero(), Vec3f::UnitX(), Vec3f::UnitZ()});
    double e = rod::bendEnergy(rs, f.positions.data(), R);
    for (int i = 1; i < n; ++i) {
        const double mass = m.massPerLength() * l * (i == n - 1 ? 0.5 : 1.0);
        e += 0.5 * mass * f.velocities[size_t(i)].squaredNorm() + mass * kG * f.positions[size_t(i)].y();
    }
    return e;
}

struct Energy {
    double drift = 0;            ///< (max E - E0) / (μgL²/2), no drag, 10 s
    double dampedKinetic = 0;    ///< J after 5 s with drag 1/s
    double maxStretch = 0;
};

/// A strand of human-hair stiffness released from horizontal.
inline Energy energy() {
    Energy r;
    const GuideSettings s = rodSettings(3.8e9f, 0.f, false);
    Strand free(s, straight(Vec3f::UnitX(), s.segments));
    const double e0 = totalEnergy(s, free.frame());
    double peak = e0;
    free.run(10.0, [&](const StrandFrame& f) { peak = std::max(peak, totalEnergy(s, f)); });
    // Relative to the energy in play (E0 = 0 with the root as the potential's
    // origin): what a limp strand releases from horizontal to hanging, μgL²/2.
    r.drift = (peak - e0) / (material(s).massPerLength() * kG * kLength * kLength / 2);
    Strand settling(rodSettings(3.8e9f, 1.f, false), straight(Vec3f::UnitX(), s.segments));
    settling.run(5.0);
    r.dampedKinetic = settling.solver.lastStats().kineticEnergy;
    r.maxStretch = std::max(free.worst.maxLengthError, settling.worst.maxLengthError);
    return r;
}

}  // namespace hp::rodcases
