#include "render/reference/hair_fit.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <tuple>
#include <vector>

namespace hp {

namespace {

constexpr double kPi = M_PI;
constexpr int kTheta = 36;  ///< θ midpoints over (−π/2, π/2), 5° apart
constexpr int kPhi = 48;    ///< φ midpoints over (−π, π)
constexpr int kH = 8;       ///< h midpoints over (−1, 1)
constexpr int kLobes = HairModel::kLobes;

double thetaAt(int i) { return -0.5 * kPi + (i + 0.5) * kPi / kTheta; }
double phiAt(int j) { return -kPi + (j + 0.5) * 2.0 * kPi / kPhi; }

using Rgb = Eigen::Vector3d;
double luminance(const Rgb& c) { return 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z(); }

/// The physical fibre integrated over φ and averaged over h, lobe by lobe.
struct Tables {
    Rgb integrated[kLobes][kTheta][kTheta];  ///< A_p(θi, θo) = ∫ S_p dφ (1/sr)
    double phiCell[kLobes][kTheta][kTheta][kPhi];  ///< per θi, θo, φ: w Y(S_p)
    double phiSum[kLobes][kTheta][kPhi] = {};       ///< ... summed over θi
    Rgb forward[kLobes][kTheta], back[kLobes][kTheta];  ///< ∫ S_p dω_o over |φ| > π/2, < π/2, per θi
};

void tabulate(const HairFiberParams& fiber, Tables* t) {
    const HairModel model(fiber);
    const double dPhi = 2.0 * kPi / kPhi, dTheta = kPi / kTheta;
    tbb::parallel_for(0, kTheta, [&](int i) {
        const double ti = thetaAt(i);
        for (int p = 0; p < kLobes; ++p) {
            t->forward[p][i] = t->back[p][i] = Rgb::Zero();
        }
        for (int o = 0; o < kTheta; ++o) {
            const double to = thetaAt(o);
            const Vec3f wo(float(std::sin(to)), float(std::cos(to)), 0.f);
            Rgb sum[kLobes] = {Rgb::Zero(), Rgb::Zero(), Rgb::Zero(), Rgb::Zero()};
            for (int j = 0; j < kPhi; ++j) {
                const double phi = phiAt(j);
                const Vec3f wi(float(std::sin(ti)), float(std::cos(ti) * std::cos(phi)), float(std::cos(ti) * std::sin(phi)));
                Rgb atPhi[kLobes] = {Rgb::Zero(), Rgb::Zero(), Rgb::Zero(), Rgb::Zero()};
                for (int k = 0; k < kH; ++k) {
                    const HairBsdf bsdf(model, float(-1.0 + (k + 0.5) * 2.0 / kH));
                    Vec3f lobes[kLobes];
                    bsdf.eval(wo, wi, lobes);
                    for (int p = 0; p < kLobes; ++p) atPhi[p] += lobes[p].cast<double>() / kH;
                }
                for (int p = 0; p < kLobes; ++p) {
                    sum[p] += atPhi[p] * dPhi;
                    t->phiCell[p][i][o][j] = std::cos(ti) * std::cos(to) * luminance(atPhi[p]);
                    // By reciprocity's symmetry in the two directions, the
                    // share of incident light going forward (φ away from the
                    // light's side) is ∫ S dω over that half.
                    (std::abs(phi) > 0.5 * kPi ? t->forward : t->back)[p][i] += atPhi[p] * (std::cos(to) * dTheta * dPhi);
                }
            }
            for (int p = 0; p < kLobes; ++p) t->integrated[p][i][o] = sum[p];
        }
    });
    // Each lobe's azimuthal distribution, summed in a fixed order.
    for (int p = 0; p < kLobes; ++p)
        for (int i = 0; i < kTheta; ++i)
            for (int o = 0; o < kTheta; ++o)
                for (int j = 0; j < kPhi; ++j) t->phiSum[p][o][j] += t->phiCell[p][i][o][j];
}

/// Index of |θo|'s bin: the grid's θo midpoints pair up as ±θo.
int absBin(int o) { return o < kTheta / 2 ? kTheta / 2 - 1 - o : o - kTheta / 2; }
constexpr int kBins = kTheta / 2;

/// The lobe's shape without its strength: cos(θi + θo − shift)^n / √(cos θi cos θo).
double lobeShape(double ti, double to, double shift, double n) {
    const double c = std::cos(ti + to - shift);
    return c > 0.0 ? std::pow(c, n) / std::sqrt(std::max(std::cos(ti) * std::cos(to), 0.01)) : 0.0;
}

/// Least-squares fit of k(|θo|) cos(θi + θo − shift)^n / √(cos θi cos θo) to
/// one lobe's table: k per |θo| bin in closed form, (n, shift) by a coarse
/// then a fine grid search on the luminance.
HairLobe fitLobe(const Rgb (&a)[kTheta][kTheta]) {
    double w[kTheta][kTheta], y[kTheta][kTheta];
    for (int i = 0; i < kTheta; ++i)
        for (int o = 0; o < kTheta; ++o) {
            w[i][o] = std::cos(thetaAt(i)) * std::cos(thetaAt(o));
            y[i][o] = luminance(a[i][o]);
        }
    double best = 1e300, bestN = 1.0, bestShift = 0.0;
    auto search = [&](double nLo, double nHi, int nSteps, double sLo, double sHi, int sSteps) {
        for (int a0 = 0; a0 <= nSteps; ++a0) {
            const double n = nLo * std::pow(nHi / nLo, double(a0) / nSteps);
            for (int b0 = 0; b0 <= sSteps; ++b0) {
                const double shift = sLo + (sHi - sLo) * b0 / sSteps;
                double by[kBins] = {}, bb[kBins] = {}, yy[kBins] = {};
                for (int i = 0; i < kTheta; ++i)
                    for (int o = 0; o < kTheta; ++o) {
                        const double b = lobeShape(thetaAt(i), thetaAt(o), shift, n);
                        const int k = absBin(o);
                        by[k] += w[i][o] * b * y[i][o];
                        bb[k] += w[i][o] * b * b;
                        yy[k] += w[i][o] * y[i][o] * y[i][o];
                    }
                double err = 0.0;
                for (int k = 0; k < kBins; ++k) err += bb[k] > 0.0 ? yy[k] - by[k] * by[k] / bb[k] : yy[k];
                if (err < best) best = err, bestN = n, bestShift = shift;
            }
        }
    };
    const double deg = kPi / 180.0;
    search(1.0, 1000.0, 40, -20.0 * deg, 20.0 * deg, 40);
    search(bestN / 1.2, bestN * 1.2, 12, bestShift - 1.0 * deg, bestShift + 1.0 * deg, 8);
    HairLobe lobe;
    lobe.exponent = float(bestN);
    lobe.shift = float(bestShift);
    Rgb by[kBins], bb[kBins];
    for (int k = 0; k < kBins; ++k) by[k] = bb[k] = Rgb::Zero();
    for (int i = 0; i < kTheta; ++i)
        for (int o = 0; o < kTheta; ++o) {
            const double b = lobeShape(thetaAt(i), thetaAt(o), bestShift, bestN);
            by[absBin(o)] += w[i][o] * b * a[i][o];
            bb[absBin(o)] += Rgb::Constant(w[i][o] * b * b);
        }
    // Bin k sits at |θo| = (k + ½) 5°; the nodes at 11.25° steps take the
    // linear interpolation between bins (the end bins beyond them).
    for (int node = 0; node < kHairLobeNodes; ++node) {
        const double x = std::clamp(node * 90.0 / (kHairLobeNodes - 1) / (180.0 / kTheta) - 0.5, 0.0, kBins - 1.0);
        const int k = std::min(int(x), kBins - 2);
        const double f = x - k;
        Rgb v;
        for (int c = 0; c < 3; ++c) {
            const double k0 = bb[k][c] > 0.0 ? by[k][c] / bb[k][c] : 0.0, k1 = bb[k + 1][c] > 0.0 ? by[k + 1][c] / bb[k + 1][c] : 0.0;
            v[c] = std::max(0.0, (1.0 - f) * k0 + f * k1);
        }
        lobe.strength[size_t(node)] = v.cast<float>();
    }
    return lobe;
}

/// The lobe's azimuthal distribution N(|φ|; |θo|) from the physical fibre's
/// (luminance, weights cos θi cos θo, summed over θi and h): at each node
/// (|θo|_a, |φ|_b) the table's rows take the physical response under hats of
/// the nodes' spacing (the least-squares weights of bilinear interpolation),
/// each row then scaled so that its piecewise-linear N integrates to 1 over
/// (−π, π]. One N for all θo, a power ((1 ± cos φ)/2)^m matched to the mean
/// cos φ as fitted before, spread the transmission over the sides: lit from
/// the side (the rig's key, 73° from the view) the fitted fibre sent the
/// viewer 22% more light than the physical one, TT alone 5.5 times its
/// share; with N per θo, 5% (docs/rendering.md).
void setAzimuth(HairLobe* lobe, const double (&phiSum)[kTheta][kPhi]) {
    const double thetaStep = 0.5 * kPi / (kHairLobeNodes - 1), phiStep = kPi / (kHairLobeNodes - 1);
    auto hat = [](double x, double step) { return std::max(0.0, 1.0 - std::abs(x) / step); };
    for (int a = 0; a < kHairLobeNodes; ++a) {
        std::array<float, kHairLobeNodes>& row = lobe->azimuth[size_t(a)];
        double integral = 0.0;
        for (int b = 0; b < kHairLobeNodes; ++b) {
            double sum = 0.0, weight = 0.0;
            for (int j = 0; j < kPhi; ++j) {
                const double hp = hat(std::abs(phiAt(j)) - b * phiStep, phiStep);
                if (hp <= 0.0) continue;
                weight += hp;
                for (int o = 0; o < kTheta; ++o) sum += hat(std::abs(thetaAt(o)) - a * thetaStep, thetaStep) * hp * phiSum[o][j];
            }
            row[size_t(b)] = float(weight > 0.0 ? sum / weight : 0.0);
            integral += (b == 0 || b == kHairLobeNodes - 1 ? 1.0 : 2.0) * row[size_t(b)] * phiStep;
        }
        if (integral > 0.0)
            for (float& n : row) n = float(n / integral);
        else
            row.fill(float(0.5 / kPi));
    }
}

HairMaterial fitted(const HairFiberParams& fiber) {
    auto t = std::make_unique<Tables>();
    tabulate(fiber, t.get());
    HairMaterial m;
    HairLobe* lobes[3] = {&m.r, &m.tt, &m.trt};
    for (int p = 0; p < 3; ++p) {
        *lobes[p] = fitLobe(t->integrated[p]);
        setAzimuth(lobes[p], t->phiSum[p]);
    }
    // R is Fresnel reflection off the cuticle: white by construction.
    for (Vec3f& k : m.r.strength) k = Vec3f::Constant(k.mean());
    // The residual (light that bounced inside the fibre more than twice) as
    // the diffuse term kd·color·cos θi: least squares over the grid.
    m.kd = 1.f;
    for (int c = 0; c < 3; ++c) {
        double by = 0.0, bb = 0.0;
        for (int i = 0; i < kTheta; ++i)
            for (int o = 0; o < kTheta; ++o) {
                const double w = std::cos(thetaAt(i)) * std::cos(thetaAt(o)), b = 2.0 * kPi * std::cos(thetaAt(i));
                by += w * b * t->integrated[3][i][o][c];
                bb += w * b * b;
            }
        m.color[c] = float(by / bb);
    }
    // Dual scattering (Zinke 2008 §4): the fibre's forward and backward
    // albedos a_f, a_b averaged over incidence (weights cos θi), the
    // variances of the lobes weighted by their share of each.
    const HairModel model(fiber);
    Rgb af = Rgb::Zero(), ab = Rgb::Zero();
    double wSum = 0.0, vf = 0.0, vfW = 0.0, vb = 0.0, vbW = 0.0;
    for (int i = 0; i < kTheta; ++i) {
        const double w = std::cos(thetaAt(i));
        wSum += w;
        for (int p = 0; p < kLobes; ++p) {
            af += w * t->forward[p][i];
            ab += w * t->back[p][i];
            vf += w * luminance(t->forward[p][i]) * model.variance(p), vfW += w * luminance(t->forward[p][i]);
            vb += w * luminance(t->back[p][i]) * model.variance(p), vbW += w * luminance(t->back[p][i]);
        }
    }
    af /= wSum;
    ab /= wSum;
    const double betaF2 = vfW > 0.0 ? vf / vfW : 0.0, betaB2 = vbW > 0.0 ? vb / vbW : 0.0;
    // Zinke eq. 13, 14: back-scattering of paths with one and three
    // backward events between any number of forward ones,
    // A_b = a_b a_f² / (1 − a_f²) + a_b³ a_f² / (1 − a_f²)³.
    Rgb Ab;
    for (int c = 0; c < 3; ++c) {
        const double f2 = std::min(af[c] * af[c], 0.99), b = ab[c];
        Ab[c] = b * f2 / (1.0 - f2) + b * b * b * f2 / std::pow(1.0 - f2, 3.0);
    }
    // Zinke eq. 17, leading term: the back lobe's variance σ_b² ≈ 2β_f² + β_b²;
    // a lobe of strength k cos^n integrates to ≈ k √(2π/n) over θo, so
    // k = d_b A_b √(n/2π) with n = 1/σ_b², and N = (1 + cos φ)/(2π) (m = 1):
    // the light returns to the light's side.
    HairLobe& back = m.dual.back;
    const double sigmaB2 = std::max(2.0 * betaF2 + betaB2, 1e-3);
    back.exponent = float(1.0 / sigmaB2);
    back.shift = 0.f;
    back.setStrength((kDualBackDensity * Ab * std::sqrt(1.0 / (sigmaB2 * 2.0 * kPi))).cast<float>());
    back.setAzimuthPower(1.f, 1.f);
    // The azimuthal turn of forward-scattered light, δ = π − |φ| (0: straight
    // on through the fibre), its variance over the forward half of every lobe
    // (luminance, weights cos θi cos θo): s_φ² = Σ w δ² / Σ w.
    double turn = 0.0, turnW = 0.0;
    for (int p = 0; p < kLobes; ++p)
        for (int i = 0; i < kTheta; ++i)
            for (int o = 0; o < kTheta; ++o)
                for (int j = 0; j < kPhi; ++j) {
                    const double delta = kPi - std::abs(phiAt(j));
                    if (delta >= 0.5 * kPi) continue;
                    turn += t->phiCell[p][i][o][j] * delta * delta;
                    turnW += t->phiCell[p][i][o][j];
                }
    m.dual.forwardAzimuthVariance = float(turnW > 0.0 ? turn / turnW : 0.0);
    m.dual.forward = af.cast<float>().cwiseMin(Vec3f::Ones());
    m.dual.forwardVariance = float(betaF2);
    m.shading = HairShading::Fitted;
    return m;
}

}  // namespace

void fitHairMaterial(const HairFiberParams& fiber, HairMaterial* m) {
    // Scenes build their view several times (stages, camera tracks): fit once per fibre.
    static std::mutex mutex;
    static std::map<std::array<float, 7>, HairMaterial> memo;
    const std::array<float, 7> key{fiber.sigmaA.x(), fiber.sigmaA.y(), fiber.sigmaA.z(), fiber.longitudinalRoughness,
                                   fiber.azimuthalRoughness, fiber.cuticleTiltDegrees, fiber.ior};
    HairMaterial f;
    {
        std::lock_guard<std::mutex> lock(mutex);
        auto it = memo.find(key);
        if (it != memo.end()) f = it->second;
        else f = memo.emplace(key, fitted(fiber)).first->second;
    }
    m->shading = HairShading::Fitted;
    m->color = f.color;
    m->kd = f.kd;
    m->r = f.r;
    m->trt = f.trt;
    m->tt = f.tt;
    m->dual = f.dual;
}

}  // namespace hp
