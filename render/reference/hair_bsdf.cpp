#include "render/reference/hair_bsdf.h"

#include <algorithm>
#include <cmath>

namespace hp {

namespace {

constexpr float kPi = float(M_PI);

float safeSqrt(float x) { return std::sqrt(std::max(0.f, x)); }
float safeAsin(float x) { return std::asin(std::clamp(x, -1.f, 1.f)); }

/// log I0(x) for x ≥ 0, I0 the modified Bessel function of the first kind of
/// order 0, from the polynomial fits of Abramowitz & Stegun 9.8.1 (x ≤ 3.75,
/// in (x/3.75)²) and 9.8.2 (x > 3.75: √x e^−x I0(x) in 3.75/x), both with
/// relative error below 1e-6: one logarithm instead of a series that needs
/// dozens of terms near x = 12. Working in logs keeps Mp finite for tiny
/// variances (x in the thousands).
float logI0(float x) {
    if (x <= 3.75f) {
        const float t = (x / 3.75f) * (x / 3.75f);
        return std::log(1.f + t * (3.5156229f + t * (3.0899424f + t * (1.2067492f +
                                   t * (0.2659732f + t * (0.0360768f + t * 0.0045813f))))));
    }
    const float r = 3.75f / x;
    const float p =
        0.39894228f + r * (0.01328592f + r * (0.00225319f + r * (-0.00157565f + r * (0.00916281f +
        r * (-0.02057706f + r * (0.02635537f + r * (-0.01647633f + r * 0.00392377f)))))));
    return x + std::log(p / std::sqrt(x));
}

/// d'Eon et al. 2011 longitudinal scattering, normalised so that
/// ∫ Mp cos θi dθi = 1:
///   Mp = csch(1/v) / (2v) · exp(−sin θi sin θo / v) · I0(cos θi cos θo / v),
/// evaluated in logs: csch(1/v)/(2v) = e^(−1/v) / (v (1 − e^(−2/v))), whose
/// log (`logNorm`, mpLogNormalization) depends on v only. The sum of logs is
/// taken in float (float exp/log cost half the double ones): its terms are of
/// the order 1/v and cancel, so Mp's relative error is about 1e-7/v, 1e-6 at
/// the default roughness and below 0.2% at the smallest (β_m = 0.01).
double mpLogNormalization(double v) { return -1.0 / v - std::log(v) - std::log1p(-std::exp(-2.0 / v)); }

float Mp(float cosThetaI, float cosThetaO, float sinThetaI, float sinThetaO, float v, double logNorm) {
    const float a = cosThetaI * cosThetaO / v;
    const float b = sinThetaI * sinThetaO / v;
    return std::exp(logI0(a) - b + float(logNorm));
}

/// Unpolarised Fresnel reflectance of a dielectric of relative index `eta`
/// for incidence cosine `cosI` from outside.
float fresnelDielectric(float cosI, float eta) {
    cosI = std::clamp(cosI, 0.f, 1.f);
    const float sin2T = (1.f - cosI * cosI) / (eta * eta);
    if (sin2T >= 1.f) return 1.f;
    const float cosT = std::sqrt(1.f - sin2T);
    const float rPar = (eta * cosI - cosT) / (eta * cosI + cosT);
    const float rPerp = (cosI - eta * cosT) / (cosI + eta * cosT);
    return 0.5f * (rPar * rPar + rPerp * rPerp);
}

/// Attenuation of the lobes (Chiang eq. 3-5): A0 = f, A1 = (1 − f)² T,
/// A2 = A1 T f, residual A3 = A2 f T / (1 − f T) (the geometric sum of all
/// longer paths). `cosTheta` is the longitudinal cosine used for Fresnel.
void attenuation(float cosTheta, float eta, float h, const Vec3f& T, Vec3f ap[HairModel::kLobes]) {
    const float cosGammaO = safeSqrt(1.f - h * h);
    const float f = fresnelDielectric(cosTheta * cosGammaO, eta);
    ap[0] = Vec3f::Constant(f);
    ap[1] = (1.f - f) * (1.f - f) * T;
    ap[2] = ap[1].cwiseProduct(T) * f;
    const Eigen::Array3f fT = f * T.array();
    ap[3] = (ap[2].array() * fT / (1.f - fT).max(1e-6f)).matrix();
}

float logistic(float x, float s) {
    x = std::abs(x);
    const float e = std::exp(-x / s);
    return e / (s * (1.f + e) * (1.f + e));
}
float logisticCdf(float x, float s) { return 1.f / (1.f + std::exp(-x / s)); }
float sampleTrimmedLogistic(float u, float s, float a, float b) {
    const float k = logisticCdf(b, s) - logisticCdf(a, s);
    const float x = -s * std::log(1.f / (u * k + logisticCdf(a, s)) - 1.f);
    return std::clamp(x, a, b);
}

/// Azimuthal deflection of lobe p for an entry offset γo and refracted γt:
/// Φ = 2pγt − 2γo + pπ (exact for a smooth cylinder).
float Phi(int p, float gammaO, float gammaT) { return 2.f * p * gammaT - 2.f * gammaO + p * kPi; }

/// Near-field azimuthal lobe: a logistic of scale s around Φ, trimmed to
/// [−π, π] so that it integrates to one over the circle (`trim` =
/// HairModel::logisticTrimScale()).
float Np(float phi, int p, float s, float trim, float gammaO, float gammaT) {
    // Φ and φ stay within a few turns: wrap to [−π, π] by whole turns.
    float dphi = phi - Phi(p, gammaO, gammaT);
    dphi -= 2.f * kPi * std::nearbyint(dphi * (0.5f / kPi));
    return logistic(dphi, s) * trim;
}

/// Absorption along one internal chord: T = exp(−σa · 2 cos γt / cos θt).
Vec3f transmittance(const Vec3f& sigmaA, float cosGammaT, float cosThetaT) {
    return (-sigmaA.array() * (2.f * cosGammaT / std::max(cosThetaT, 1e-4f))).exp().matrix();
}

}  // namespace

Vec3f hairAbsorptionFromMelanin(float eumelanin, float pheomelanin) {
    const Vec3f eu(0.419f, 0.697f, 1.37f);
    const Vec3f pheo(0.187f, 0.4f, 1.05f);
    return eumelanin * eu + pheomelanin * pheo;
}

namespace {
/// Chiang 2016 eq. 9's denominator: σa = (ln c / D(β_n))².
float colorFitScale(float b) {
    return 5.969f - 0.215f * b + 2.532f * b * b - 10.73f * b * b * b + 5.574f * b * b * b * b +
           0.245f * b * b * b * b * b;
}
}  // namespace

Vec3f hairAbsorptionFromColor(const Vec3f& color, float betaN) {
    const float d = colorFitScale(betaN);
    Vec3f sigma;
    for (int c = 0; c < 3; ++c) {
        const float l = std::log(std::clamp(color[c], 1e-4f, 1.f)) / d;
        sigma[c] = l * l;
    }
    return sigma;
}

Vec3f hairColorFromAbsorption(const Vec3f& sigmaA, float betaN) {
    const float d = colorFitScale(betaN);
    Vec3f color;
    for (int c = 0; c < 3; ++c) color[c] = std::exp(-std::sqrt(std::max(sigmaA[c], 0.f)) * d);
    return color;
}

HairModel::HairModel(const HairFiberParams& params) : params_(params) {
    const float bm = std::clamp(params.longitudinalRoughness, 0.01f, 1.f);
    const float bn = std::clamp(params.azimuthalRoughness, 0.01f, 1.f);
    // Chiang eq. 7 and 8: perceptually linear roughness to lobe variance and
    // logistic scale.
    const float sm = 0.726f * bm + 0.812f * bm * bm + 3.7f * std::pow(bm, 20.f);
    v_[0] = sm * sm;
    v_[1] = 0.25f * v_[0];
    v_[2] = 4.f * v_[0];
    v_[3] = v_[2];
    s_ = std::sqrt(kPi / 8.f) * (0.265f * bn + 1.194f * bn * bn + 5.372f * std::pow(bn, 22.f));
    for (int p = 0; p < kLobes; ++p) logMpNorm_[p] = mpLogNormalization(double(v_[p]));
    trim_ = 1.f / (logisticCdf(kPi, s_) - logisticCdf(-kPi, s_));
    sin2kAlpha_[0] = std::sin(params.cuticleTiltDegrees * kPi / 180.f);
    cos2kAlpha_[0] = safeSqrt(1.f - sin2kAlpha_[0] * sin2kAlpha_[0]);
    for (int k = 1; k < 3; ++k) {
        sin2kAlpha_[k] = 2.f * cos2kAlpha_[k - 1] * sin2kAlpha_[k - 1];
        cos2kAlpha_[k] = cos2kAlpha_[k - 1] * cos2kAlpha_[k - 1] - sin2kAlpha_[k - 1] * sin2kAlpha_[k - 1];
    }
}

struct HairBsdf::Angles {
    float sinThetaO, cosThetaO, phiO;
    float sinThetaI, cosThetaI, phiI;
    float gammaT;  ///< refracted azimuthal offset
    Vec3f T;       ///< transmittance of one internal chord
};

HairBsdf::HairBsdf(const HairModel& model, float h)
    : model_(model), h_(std::clamp(h, -1.f, 1.f)), gammaO_(safeAsin(h_)) {}

HairBsdf::Angles HairBsdf::angles(const Vec3f& wo, const Vec3f& wi) const {
    Angles a;
    a.sinThetaO = std::clamp(wo.x(), -1.f, 1.f);
    a.cosThetaO = safeSqrt(1.f - a.sinThetaO * a.sinThetaO);
    a.phiO = std::atan2(wo.z(), wo.y());
    a.sinThetaI = std::clamp(wi.x(), -1.f, 1.f);
    a.cosThetaI = safeSqrt(1.f - a.sinThetaI * a.sinThetaI);
    a.phiI = std::atan2(wi.z(), wi.y());
    a.gammaT = refractedOffset(a.sinThetaO, a.cosThetaO, &a.T);
    return a;
}

float HairBsdf::refractedOffset(float sinThetaO, float cosThetaO, Vec3f* T) const {
    const float eta = model_.params().ior;
    // Bravais index: refraction projected into the normal plane.
    const float etap = std::sqrt(eta * eta - sinThetaO * sinThetaO) / std::max(cosThetaO, 1e-4f);
    const float sinThetaT = sinThetaO / eta;
    const float sinGammaT = h_ / etap;
    *T = transmittance(model_.params().sigmaA, safeSqrt(1.f - sinGammaT * sinGammaT),
                       safeSqrt(1.f - sinThetaT * sinThetaT));
    return safeAsin(sinGammaT);
}

void HairBsdf::tilt(int p, float sinThetaO, float cosThetaO, float* sinOp, float* cosOp) const {
    // The cuticle scales' free edges point to the tip (x > 0), so a scale's
    // surface normal leans toward the root by α. Mirror reflection about it
    // gives θo = −θi − 2α: the primary (R) highlight moves toward the root
    // (Marschner et al. 2003, §4.1 and Table 1). Mp peaks where θi = −θo', so
    // R is evaluated at θo' = θo + 2α, and the refracted lobes, which the
    // scales bend the other way, at θo' = θo − α (TT) and θo − 4α (TRT)
    // (Chiang 2016 §4.1 magnitudes). pbrt-v3 uses the opposite signs, which
    // moves R toward the tip (Tungsten issue #50).
    const HairModel& m = model_;
    const int k = p == 0 ? 1 : p == 1 ? 0 : 2;
    const float s = p == 0 ? m.sin2kAlpha(k) : -m.sin2kAlpha(k);  // sin of the signed shift
    *sinOp = sinThetaO * m.cos2kAlpha(k) + cosThetaO * s;
    *cosOp = std::abs(cosThetaO * m.cos2kAlpha(k) - sinThetaO * s);
}

Vec3f HairBsdf::evaluate(const Vec3f& wo, const Vec3f& wi, Vec3f* lobes, float* pdf) const {
    const Angles a = angles(wo, wi);
    const HairFiberParams& prm = model_.params();
    Vec3f ap[HairModel::kLobes];
    attenuation(a.cosThetaO, prm.ior, h_, a.T, ap);
    float apPdf[HairModel::kLobes];
    if (pdf) lobePdf(ap, apPdf), *pdf = 0.f;
    const float phi = a.phiI - a.phiO;
    Vec3f sum = Vec3f::Zero();
    for (int p = 0; p < 3; ++p) {
        float sinOp, cosOp;
        tilt(p, a.sinThetaO, a.cosThetaO, &sinOp, &cosOp);
        const float mn = Mp(a.cosThetaI, cosOp, a.sinThetaI, sinOp, model_.variance(p), model_.logMpNormalization(p)) *
                         Np(phi, p, model_.logisticScale(), model_.logisticTrimScale(), gammaO_, a.gammaT);
        const Vec3f lobe = mn * ap[p];
        if (lobes) lobes[p] = lobe;
        if (pdf) *pdf += apPdf[p] * mn;
        sum += lobe;
    }
    // Residual: all longer paths, azimuthally uniform, untilted.
    const float m3 =
        Mp(a.cosThetaI, a.cosThetaO, a.sinThetaI, a.sinThetaO, model_.variance(3), model_.logMpNormalization(3)) /
        (2.f * kPi);
    const Vec3f residual = m3 * ap[3];
    if (lobes) lobes[3] = residual;
    if (pdf) *pdf += apPdf[3] * m3;
    return sum + residual;
}

Vec3f HairBsdf::eval(const Vec3f& wo, const Vec3f& wi, Vec3f* lobes) const { return evaluate(wo, wi, lobes, nullptr); }

void HairBsdf::lobePdf(const Vec3f ap[HairModel::kLobes], float out[HairModel::kLobes]) {
    // The lobes' attenuations averaged over the colour channels.
    float total = 0.f;
    for (int p = 0; p < HairModel::kLobes; ++p) total += (out[p] = ap[p].mean());
    for (int p = 0; p < HairModel::kLobes; ++p) out[p] = total > 0.f ? out[p] / total : 0.25f;
}

float HairBsdf::pdf(const Vec3f& wo, const Vec3f& wi) const {
    float density = 0.f;
    evaluate(wo, wi, nullptr, &density);
    return density;
}

HairSample HairBsdf::sample(const Vec3f& wo, const Vec2f& u0, const Vec2f& u1) const {
    HairSample out;
    const float sinThetaO = std::clamp(wo.x(), -1.f, 1.f);
    const float cosThetaO = safeSqrt(1.f - sinThetaO * sinThetaO);
    const float phiO = std::atan2(wo.z(), wo.y());

    Vec3f T;
    const float gammaT = refractedOffset(sinThetaO, cosThetaO, &T);
    Vec3f ap[HairModel::kLobes];
    attenuation(cosThetaO, model_.params().ior, h_, T, ap);
    float apPdf[HairModel::kLobes];
    lobePdf(ap, apPdf);
    int p = 0;
    float u = u0.x();
    for (; p < 3; ++p) {
        if (u < apPdf[p]) break;
        u -= apPdf[p];
    }

    // Longitudinal: sample the von Mises-Fisher lobe around the (tilted)
    // mirror direction on the sphere; its θ has density Mp cos θ (d'Eon 2013).
    float sinOp = sinThetaO, cosOp = cosThetaO;
    if (p < 3) tilt(p, sinThetaO, cosThetaO, &sinOp, &cosOp);
    const float v = model_.variance(p);
    const float um = std::max(u1.x(), 1e-5f);
    const float cosTheta = 1.f + v * std::log(um + (1.f - um) * std::exp(-2.f / v));
    const float sinTheta = safeSqrt(1.f - cosTheta * cosTheta);
    const float cosPhi = std::cos(2.f * kPi * u1.y());
    const float sinThetaI = std::clamp(-cosTheta * sinOp + sinTheta * cosPhi * cosOp, -1.f, 1.f);
    const float cosThetaI = safeSqrt(1.f - sinThetaI * sinThetaI);

    // Azimuthal: the logistic around the lobe's deflection Φ.
    const float dphi = p < 3 ? Phi(p, gammaO_, gammaT) + sampleTrimmedLogistic(u0.y(), model_.logisticScale(), -kPi, kPi)
                             : 2.f * kPi * u0.y();
    const float phiI = phiO + dphi;
    out.wi = Vec3f(sinThetaI, cosThetaI * std::cos(phiI), cosThetaI * std::sin(phiI));
    out.lobe = p;
    const Vec3f f = evaluate(wo, out.wi, nullptr, &out.pdf);
    if (!(out.pdf > 0.f) || !std::isfinite(out.pdf)) return out;
    out.weight = f / out.pdf;
    out.valid = out.weight.allFinite();
    return out;
}

}  // namespace hp
