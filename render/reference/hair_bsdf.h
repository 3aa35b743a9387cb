// @brief Physically based hair fibre scattering after Chiang, Bitterli, Tappan
// and Burley 2016, "A Practical and Controllable Hair and Fur Model for
// Production Path Tracing": lobes R, TT, TRT and a residual, d'Eon et al.'s
// longitudinal lobes Mp, a near-field logistic azimuthal distribution Np,
// attenuation Ap from Fresnel and melanin absorption, cuticle tilt, and
// importance sampling of all lobes.
//
// Conventions. Directions are in the fibre's local frame: x along the
// tangent (root to tip), y and z spanning the normal plane; both directions
// point away from the fibre. theta is the angle to the normal plane
// (sin theta = w.x), phi = atan2(w.z, w.y). h in [-1, 1] is the offset of the
// hit across the fibre, measured along y for a viewer at +z.
//
// eval() returns the scattering kernel S with L_o(wo) = ∫ S(wo, wi) L_i(wi)
// dω_i: the fibre's projected-cosine factor is already inside Mp (d'Eon's
// normalisation ∫ Mp cos θi dθi = 1), so a renderer multiplies by nothing but
// the incident radiance, and a white fibre (σa = 0) under uniform light
// returns ≈ 1 (the white-furnace test).
//
// Reciprocity: as in the paper, Ap and the refracted offset γt depend on θo
// only (the outgoing ray fixes the path through the fibre). That makes Σ Ap = 1
// hold under every lobe, so energy is conserved exactly (σa = 0), at the price
// of exact reciprocity: S(wo, wi, h) = S(wi, wo, −h) holds on the specular cone
// θi = −θo, where nearly all of a smooth fibre's energy goes, and only
// approximately off it. (Evaluating Ap at Marschner's θd = (θo − θi)/2 instead
// is exactly reciprocal but lost up to 14% energy at θo = 70° in the furnace
// test; the cuticle tilt, which rotates only the outgoing cone, is not
// reciprocal either.)
#pragma once

#include "sim/strands/strand.h"

namespace hp {

/// Absorption coefficient σa of a fibre per unit fibre radius, from its
/// eumelanin and pheomelanin concentrations (Chiang 2016 §4.3; ~0.3 blond,
/// ~1.3 brown, ~8 black; pheomelanin adds red).
Vec3f hairAbsorptionFromMelanin(float eumelanin, float pheomelanin);

/// σa that gives approximately `color` (linear RGB, 0..1) as the multiply
/// scattered colour of a full head of hair with azimuthal roughness `betaN`
/// (Chiang 2016 §4.2, their fit).
Vec3f hairAbsorptionFromColor(const Vec3f& color, float betaN);

/// The inverse of hairAbsorptionFromColor: c = exp(−√σa · D(β_n)), the
/// multiply scattered colour of a head of hair with absorption σa (Chiang
/// 2016 eq. 9 solved for c). The one fit between melanin and the Kajiya-Kay
/// colour: render.hair.melanin sets σa (hairAbsorptionFromMelanin) and this
/// colour. At β_n = 0.3 (D = 5.888): eumelanin 0.3 -> (0.124, 0.068, 0.023),
/// eumelanin 0.3 + pheomelanin 0.8 -> (0.046, 0.014, 0.001), 1.3 -> (0.013,
/// 0.004, 0.000), 8 -> black. Linear albedos: dark hair leaves its look to
/// the specular lobes, as in the physical reference.
Vec3f hairColorFromAbsorption(const Vec3f& sigmaA, float betaN);

/// Material parameters of one hair fibre.
struct HairFiberParams {
    Vec3f sigmaA = hairAbsorptionFromMelanin(1.3f, 0.f);  ///< absorption per unit radius
    float longitudinalRoughness = 0.3f;                    ///< β_m in (0, 1]
    float azimuthalRoughness = 0.3f;                       ///< β_n in (0, 1]
    float cuticleTiltDegrees = 2.f;                        ///< α: scale tilt, shifts the lobes along the fibre
    float ior = 1.55f;                                     ///< η of keratin
};

/// Per-material constants derived once from HairFiberParams (lobe variances,
/// logistic scale, tilt sines), shared by every hit.
class HairModel {
  public:
    static constexpr int kLobes = 4;  ///< R, TT, TRT, residual
    explicit HairModel(const HairFiberParams& params);

    const HairFiberParams& params() const { return params_; }
    float variance(int lobe) const { return v_[lobe]; }
    /// log of Mp's normalisation csch(1/v)/(2v) for the lobe's variance
    /// (per material, so each Mp costs one exponential less).
    double logMpNormalization(int lobe) const { return logMpNorm_[lobe]; }
    float logisticScale() const { return s_; }
    /// 1 / (logistic CDF(π) − CDF(−π)): normalisation of the trimmed Np.
    float logisticTrimScale() const { return trim_; }
    /// sin/cos of 2^k α, k = 0, 1, 2 (tilt of TT, R and TRT).
    float sin2kAlpha(int k) const { return sin2kAlpha_[k]; }
    float cos2kAlpha(int k) const { return cos2kAlpha_[k]; }

  private:
    HairFiberParams params_;
    float v_[kLobes];
    double logMpNorm_[kLobes];
    float s_;
    float trim_;
    float sin2kAlpha_[3], cos2kAlpha_[3];
};

/// One importance-sampled direction.
struct HairSample {
    Vec3f wi = Vec3f::Zero();
    Vec3f weight = Vec3f::Zero();  ///< S(wo, wi) / pdf
    float pdf = 0.f;               ///< solid-angle density
    int lobe = -1;                 ///< lobe that produced the sample
    bool valid = false;
};

/// The fibre's scattering at one hit (fixed h).
class HairBsdf {
  public:
    HairBsdf(const HairModel& model, float h);

    /// Scattering kernel S(wo, wi) (1/sr); `lobes`, if given, receives the
    /// four lobes' parts (R, TT, TRT, residual) that sum to the result.
    Vec3f eval(const Vec3f& wo, const Vec3f& wi, Vec3f* lobes = nullptr) const;
    /// eval() and pdf() in one pass (what multiple importance sampling needs).
    Vec3f eval(const Vec3f& wo, const Vec3f& wi, Vec3f* lobes, float* pdf) const { return evaluate(wo, wi, lobes, pdf); }
    /// Solid-angle density of sample() producing wi.
    float pdf(const Vec3f& wo, const Vec3f& wi) const;
    /// Picks a lobe by its attenuation (u0.x), samples Np (u0.y) and Mp (u1).
    HairSample sample(const Vec3f& wo, const Vec2f& u0, const Vec2f& u1) const;

    float h() const { return h_; }

  private:
    struct Angles;
    Angles angles(const Vec3f& wo, const Vec3f& wi) const;
    /// eval() and, when `pdf` is given, pdf() in one pass: both are sums of
    /// the same Mp·Np products, weighted by attenuation or by lobe probability.
    Vec3f evaluate(const Vec3f& wo, const Vec3f& wi, Vec3f* lobes, float* pdf) const;
    /// Lobe selection probabilities from the lobes' attenuations.
    static void lobePdf(const Vec3f ap[HairModel::kLobes], float out[HairModel::kLobes]);
    /// Lobe selection probabilities, from the attenuations seen along wo.
    void lobePdf(float sinThetaO, float cosThetaO, float out[HairModel::kLobes]) const;
    /// γt for this h and θo; *T receives one internal chord's transmittance.
    float refractedOffset(float sinThetaO, float cosThetaO, Vec3f* T) const;
    /// Tilted sin/cos of θo for lobe p < 3.
    void tilt(int p, float sinThetaO, float cosThetaO, float* sinOp, float* cosOp) const;

    const HairModel& model_;
    float h_;
    float gammaO_;
};

}  // namespace hp
