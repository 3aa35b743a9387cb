// The preview's fitted hair (render/reference/hair_fit.h): the Kajiya-Kay
// family with terms fitted to Chiang et al. 2016's fibre must reproduce the
// physical BSDF's azimuthally integrated response over the melanin range, in
// the BSDF's own units. The physical side is integrated here from
// HairBsdf::eval on a grid of its own (finer in h and φ, other θ) than the
// fit's, and the fitted side by integrating kajiyaKay() itself over φ, so a
// wrong azimuthal normalisation, shift sign or strength shows.
#include "render/reference/hair_bsdf.h"
#include "render/reference/hair_fit.h"
#include "render/view/view.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace hp;

namespace {

constexpr double kPi = M_PI;
constexpr int kThetas = 21;  // θ from −75° to 75° in 7.5° steps
constexpr int kPhis = 96;
constexpr int kHs = 16;

double thetaAt(int i) { return (-75.0 + 7.5 * i) * kPi / 180.0; }
double phiAt(int j) { return -kPi + (j + 0.5) * 2.0 * kPi / kPhis; }
Vec3f direction(double theta, double phi) {
    return Vec3f(float(std::sin(theta)), float(std::cos(theta) * std::cos(phi)), float(std::cos(theta) * std::sin(phi)));
}

HairFiberParams fibre(float eumelanin, float pheomelanin) {
    HairFiberParams f;
    f.sigmaA = hairAbsorptionFromMelanin(eumelanin, pheomelanin);
    return f;  // β_m = β_n = 0.3, α = 2°, η = 1.55: reference.physical's defaults
}

/// ∫ over φ of the physical kernel averaged over h, and of the fitted
/// kajiyaKay(), split into φ's back half (|φ| < π/2, toward the light) and
/// forward half; per colour channel.
struct Response {
    Eigen::Vector3d physical[2][kThetas][kThetas], fitted[2][kThetas][kThetas];
};

void integrate(const HairFiberParams& f, const HairMaterial& m, Response* r) {
    const HairModel model(f);
    const Vec3f t = Vec3f::UnitX(), n = Vec3f::UnitZ();
    const double dPhi = 2.0 * kPi / kPhis;
    for (int i = 0; i < kThetas; ++i)
        for (int o = 0; o < kThetas; ++o) {
            for (int half = 0; half < 2; ++half) r->physical[half][i][o] = r->fitted[half][i][o] = Eigen::Vector3d::Zero();
            const Vec3f wo = direction(thetaAt(o), 0.0);
            for (int j = 0; j < kPhis; ++j) {
                const Vec3f wi = direction(thetaAt(i), phiAt(j));
                const int half = std::abs(phiAt(j)) < 0.5 * kPi ? 0 : 1;
                Eigen::Vector3d s = Eigen::Vector3d::Zero();
                for (int k = 0; k < kHs; ++k) s += HairBsdf(model, float(-1.0 + (k + 0.5) * 2.0 / kHs)).eval(wo, wi).cast<double>();
                r->physical[half][i][o] += s / kHs * dPhi;
                r->fitted[half][i][o] += kajiyaKay(m, t, n, wi, wo).cast<double>() * dPhi;
            }
        }
}

struct Errors {
    Eigen::Vector3d relativeL1;  ///< Σ w |F − P| / Σ w P per channel, w = cos θi cos θo
    double forwardShare[2];      ///< physical, fitted: share of the luminance scattered forward
};

Errors measure(const Response& r) {
    Errors e;
    Eigen::Vector3d diff = Eigen::Vector3d::Zero(), total = Eigen::Vector3d::Zero();
    double fwd[2] = {0, 0}, all[2] = {0, 0};
    auto lum = [](const Eigen::Vector3d& c) { return 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z(); };
    for (int i = 0; i < kThetas; ++i)
        for (int o = 0; o < kThetas; ++o) {
            const double w = std::cos(thetaAt(i)) * std::cos(thetaAt(o));
            const Eigen::Vector3d p = r.physical[0][i][o] + r.physical[1][i][o];
            const Eigen::Vector3d q = r.fitted[0][i][o] + r.fitted[1][i][o];
            diff += w * (q - p).cwiseAbs();
            total += w * p;
            fwd[0] += w * lum(r.physical[1][i][o]), all[0] += w * lum(p);
            fwd[1] += w * lum(r.fitted[1][i][o]), all[1] += w * lum(q);
        }
    e.relativeL1 = diff.cwiseQuotient(total);
    e.forwardShare[0] = fwd[0] / all[0];
    e.forwardShare[1] = fwd[1] / all[1];
    return e;
}

struct Case {
    float eumelanin, pheomelanin;
};

class HairFit : public ::testing::TestWithParam<Case> {};

// Bounds from the measured errors (printed) with a margin: the worst
// channel's relative L1 error of the azimuthally integrated response stays
// under 15% from blond (0.1) to black (8) hair (measured 2% at 0.1 and 0.3,
// 3-10% at 1.3, 7-12% at 3, 12.5% at 8, 2-7% for red 0.3 + 0.8: dark hair's
// response is R, whose d'Eon lobe the cone fits least well at grazing
// angles), and the share of light the fitted lobes send forward (through the
// fibre: TT) within 0.1 of the physical share (measured within 0.004 to 0.077).
TEST_P(HairFit, ReproducesTheAzimuthallyIntegratedPhysicalResponse) {
    const Case c = GetParam();
    const HairFiberParams f = fibre(c.eumelanin, c.pheomelanin);
    HairMaterial m;
    fitHairMaterial(f, &m);
    ASSERT_EQ(m.shading, HairShading::Fitted);
    Response r;
    integrate(f, m, &r);
    const Errors e = measure(r);
    std::printf("melanin %.2f + %.2f: relative L1 (%.3f, %.3f, %.3f), forward share physical %.3f fitted %.3f\n",
                c.eumelanin, c.pheomelanin, e.relativeL1.x(), e.relativeL1.y(), e.relativeL1.z(), e.forwardShare[0],
                e.forwardShare[1]);
    std::printf("  R k %.3f n %.1f shift %.2f deg | TRT k (%.3f %.3f %.3f) n %.1f shift %.2f | "
                "TT k (%.3f %.3f %.3f) n %.1f shift %.2f | diffuse (%.4f %.4f %.4f)\n",
                m.r.strength[0].x(), m.r.exponent, m.r.shift * 180 / kPi, m.trt.strength[0].x(), m.trt.strength[0].y(),
                m.trt.strength[0].z(), m.trt.exponent, m.trt.shift * 180 / kPi, m.tt.strength[0].x(), m.tt.strength[0].y(),
                m.tt.strength[0].z(), m.tt.exponent, m.tt.shift * 180 / kPi, m.color.x(), m.color.y(), m.color.z());
    std::printf("  dual: a_f (%.3f %.3f %.3f) beta_f^2 %.4f back k (%.3f %.3f %.3f) n %.1f\n", m.dual.forward.x(),
                m.dual.forward.y(), m.dual.forward.z(), m.dual.forwardVariance, m.dual.back.strength[0].x(),
                m.dual.back.strength[0].y(), m.dual.back.strength[0].z(), m.dual.back.exponent);
    for (int ch = 0; ch < 3; ++ch) EXPECT_LT(e.relativeL1[ch], 0.15) << "channel " << ch;
    EXPECT_NEAR(e.forwardShare[1], e.forwardShare[0], 0.1);
}

/// A lit head of hair seen at `angle` from the light: the mean, over fibre
/// directions spread evenly on the sphere (a Fibonacci lattice) and hit
/// offsets h, of the light the fibre sends the viewer per unit irradiance,
/// physical (HairBsdf) and fitted (kajiyaKay()); per colour channel.
void viewedAtAngle(const HairFiberParams& f, const HairMaterial& m, double angle, Eigen::Vector3d* physical,
                   Eigen::Vector3d* fitted) {
    const HairModel model(f);
    const Vec3f v = Vec3f::UnitZ(), l(float(std::sin(angle)), 0.f, float(std::cos(angle)));
    *physical = *fitted = Eigen::Vector3d::Zero();
    constexpr int kFibres = 2000;
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (int s = 0; s < kFibres; ++s) {
        const double z = 1.0 - (s + 0.5) * 2.0 / kFibres, r = std::sqrt(1.0 - z * z);
        const Vec3f t(float(r * std::cos(golden * s)), float(r * std::sin(golden * s)), float(z));
        // The fibre's frame as the reference builds it (vertex_bsdf.h fiberFrame): x along t, z toward the viewer.
        Vec3f n = v - v.dot(t) * t;
        if (n.squaredNorm() < 1e-10f) continue;
        n.normalize();
        const Vec3f y = n.cross(t);
        auto local = [&](const Vec3f& w) { return Vec3f(w.dot(t), w.dot(y), w.dot(n)); };
        for (int k = 0; k < kHs; ++k)
            *physical += HairBsdf(model, float(-1.0 + (k + 0.5) * 2.0 / kHs)).eval(local(v), local(l)).cast<double>() / kHs;
        *fitted += kajiyaKay(m, t, n, l, v).cast<double>();
    }
}

// Where the light falls matters as much as how much is scattered: the rig's
// key lights the hair 73° from the view, the fill 56°, the rim 141°. Bounds
// from the measured ratios (printed) with a margin: fitted over physical
// within 16% at every angle from 30° to 150° and melanin 0.1 to 1.3
// (measured 0.85-1.13: 1.13 at 110°, the blue of dark hair 0.85 at 150°;
// 0.98-1.05 at the key's and fill's angles). One N(φ) for every θo (the
// 45° row) fails it, 1.11-1.16 at 73°, and so did the power
// ((1 ± cos φ)/2)^m matched to each lobe's mean cos φ fitted before (1.22).
TEST_P(HairFit, SendsTheViewerThePhysicalLightAtEveryAngleFromTheLight) {
    const Case c = GetParam();
    if (c.eumelanin > 2.f) GTEST_SKIP() << "black hair: R alone, covered by the integrated response";
    const HairFiberParams f = fibre(c.eumelanin, c.pheomelanin);
    HairMaterial m;
    fitHairMaterial(f, &m);
    for (double degrees : {30.0, 56.0, 73.0, 110.0, 141.0, 150.0}) {
        Eigen::Vector3d p, q;
        viewedAtAngle(f, m, degrees * kPi / 180.0, &p, &q);
        const Eigen::Vector3d ratio = q.cwiseQuotient(p);
        std::printf("melanin %.2f + %.2f, %3.0f deg from the light: fitted / physical (%.3f %.3f %.3f)\n", c.eumelanin,
                    c.pheomelanin, degrees, ratio.x(), ratio.y(), ratio.z());
        for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(ratio[ch], 1.0, 0.16) << degrees << " deg, channel " << ch;
    }
}

INSTANTIATE_TEST_SUITE_P(MelaninRange, HairFit,
                         ::testing::Values(Case{0.1f, 0.f}, Case{0.3f, 0.1f}, Case{1.3f, 0.f}, Case{3.f, 0.f},
                                           Case{8.f, 0.f}, Case{0.3f, 0.8f}));

// R is white (Fresnel reflection off the cuticle), TRT takes the fibre's
// colour and sits on the other side of the specular cone (Marschner et al.
// 2003: R shifted toward the root, TRT toward the tip), TT faces forward.
TEST(HairFitLobes, ShiftsAndColoursFollowTheFibre) {
    HairMaterial m;
    fitHairMaterial(fibre(0.3f, 0.1f), &m);
    for (const Vec3f& k : m.r.strength) EXPECT_FLOAT_EQ(k.x(), k.z());
    EXPECT_GT(m.trt.strength[0].x(), 1.5f * m.trt.strength[0].z());
    // Fresnel: the reflection grows toward grazing angles.
    EXPECT_GT(m.r.strength[kHairLobeNodes - 2].x(), 2.f * m.r.strength[0].x());
    EXPECT_LT(m.r.shift, 0.f);
    EXPECT_GT(m.trt.shift, 0.f);
    // TT goes on through the fibre (φ = π), R comes back (φ = 0), at every |θo|.
    for (const auto& row : m.tt.azimuth) EXPECT_GT(row[kHairLobeNodes - 1], 2.f * row[0]);
    for (const auto& row : m.r.azimuth) EXPECT_GT(row[0], row[kHairLobeNodes - 1]);
    // Darker hair forwards less light through each fibre (the coloured shadow).
    HairMaterial dark;
    fitHairMaterial(fibre(8.f, 0.f), &dark);
    EXPECT_LT(dark.dual.forward.x(), 0.5f * m.dual.forward.x());
    EXPECT_GT(m.dual.forward.x(), m.dual.forward.z());
}

// Light that one fibre scatters forward leaves it turned about the fibre by
// δ = π − |φ| (0: straight on); n crossings turn it by variance n s_φ², which
// blurs the lobes' azimuthal distribution for the preview's multiply
// scattered light (shaders/kajiya_kay.glsl hairLobeTurned). s_φ² is integrated
// here from HairBsdf::eval on this test's own grids (θi, θo 30 midpoints, φ 96,
// h 16; luminance of all lobes, weights cos θi cos θo, forward half |φ| > π/2),
// so a turn measured from the wrong side (|φ| instead of π − |φ|), or over
// the whole circle, fails (1.0-1.2 rad² against 0.46-0.59). Bound: 5% (measured,
// printed: 0.467 / 0.486 / 0.604 rad² against 0.457 / 0.476 / 0.587, within 3%).
TEST(HairFitLobes, ForwardAzimuthVarianceIsThePhysicalFibresTurn) {
    for (const Case c : {Case{0.1f, 0.f}, Case{0.3f, 0.1f}, Case{1.3f, 0.f}}) {
        const HairFiberParams f = fibre(c.eumelanin, c.pheomelanin);
        const HairModel model(f);
        HairMaterial m;
        fitHairMaterial(f, &m);
        constexpr int kGrid = 30;
        double turn = 0.0, weight = 0.0;
        for (int o = 0; o < kGrid; ++o) {
            const double thetaO = -0.5 * kPi + (o + 0.5) * kPi / kGrid;
            const Vec3f wo = direction(thetaO, 0.0);
            for (int i = 0; i < kGrid; ++i) {
                const double thetaI = -0.5 * kPi + (i + 0.5) * kPi / kGrid;
                for (int j = 0; j < kPhis; ++j) {
                    const double delta = kPi - std::abs(phiAt(j));
                    if (delta >= 0.5 * kPi) continue;
                    Eigen::Vector3d s = Eigen::Vector3d::Zero();
                    for (int k = 0; k < kHs; ++k)
                        s += HairBsdf(model, float(-1.0 + (k + 0.5) * 2.0 / kHs)).eval(wo, direction(thetaI, phiAt(j))).cast<double>();
                    const double w = std::cos(thetaI) * std::cos(thetaO) * (0.2126 * s.x() + 0.7152 * s.y() + 0.0722 * s.z());
                    turn += w * delta * delta;
                    weight += w;
                }
            }
        }
        const double physical = turn / weight;
        std::printf("melanin %.2f + %.2f: forward azimuthal variance s_phi^2 physical %.4f fitted %.4f rad^2\n",
                    c.eumelanin, c.pheomelanin, physical, m.dual.forwardAzimuthVariance);
        EXPECT_NEAR(m.dual.forwardAzimuthVariance, physical, 0.05 * physical);
    }
}

}  // namespace
