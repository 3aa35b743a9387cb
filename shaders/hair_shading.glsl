// Radiance leaving a hair point toward the camera, under every light.
// Kajiya-Kay: the model times the light's visibility (its slot's voxel grid
// and shadow map; 1 for a light without a slot).
// Fitted (render/reference/hair_fit.h): the dual-scattering approximation of
// Zinke, Yuksel, Weber and Keyser 2008. Behind n fibre crossings toward each
// shadowed light (Poisson with mean C, its slot's voxel grid) the light
// arrives straight with probability exp(-C) and forward-scattered as the rest
// of T_f = exp(-(1 - a_f) C) (coloured: each fibre keeps what it scatters
// forward, a_f per channel), the latter times d_f, spread along the fibre by
// n beta_f^2 and turned about it by n s_phi^2; the fibres around the point add
// the local back-scatter d_b f_back (lobe 3), scaled by how much hair lies
// behind the point (C_b, the rest of the voxel column):
//   L = sum over lights of E shadowMap [exp(-C) (f + B(0)) + (T_f - exp(-C)) d_f (f_turned(n) + B(n))],
//   B(n) = (1 - exp(-(1 - a_f^2) C_b)) d_b f_back(n beta_f^2), n = C / (1 - exp(-C)),
// plus the scalp's bounce under the hair (scalpBounce below): the skin lit through
// the hair's column lights the fibres above it. Sorted hair takes that path
// from the skin the camera sees behind the fibre instead (resolve.frag
// skinThrough), and keeps the bounce where the camera sees none (hair beside
// the head: skinBehindInView).
// Evaluated per ribbon vertex (default; Gouraud along the strand, which
// software rasterizers need for speed) or per fragment (SHADE_PER_FRAGMENT).
#include "kajiya_kay.glsl"
#include "shadow.glsl"

// Zinke 2008's forward density factor d_f (their 0.7 for human hair): the
// share of forward-scattered light that meets the next fibre of a chain.
const float kForwardDensity = 0.7;
// The scalp's bounce: light that crossed the hair to the skin, reflected
// diffusely by it and scattered by the fibre above it. The hair lies on the
// scalp as a layer over a Lambertian plane: along the light's ray through the
// point the whole column C_all = c.y of hair lies between the light and the
// skin (where the ray meets the head: the shadow map's head lies behind the
// point, headBehind), so the skin receives E cos(theta_s) T_f(C_all), with
// T_f(C) = exp(-(1 - a_f) C) the forward transmittance that lights the head's
// own skin (shadow.glsl hairOnlyVisibility), and leaves with the radiance
//   L_s = rho (1 - k_s) / pi * E cos(theta_s) T_f(C_all)
// (render/view/view.cpp skinShade's diffuse part, its wrap left out). The
// fibre meets it through the C_b = c.y - c.x crossings between it and the skin
// (the light's column taken back), T_f(C_b), and by reciprocity a fibre lit
// by radiance L over the half space it faces sends the viewer
// L int S cos(theta_i) d(omega_i) = L a_f: the share of light arriving from the
// viewer that it scatters forward, away from the viewer, into that half space
// (Zinke et al. 2008's forward albedo, one of the fitted dual-scattering
// terms). The skin's normal n_s is not known here; the hair lies on the scalp,
// so n_s is perpendicular to the fibre and faces the viewer: taken uniform over
// that half circle (angle psi from the ribbon normal n, gamma the light's angle
// from n in the plane across the fibre, |l_p| = sin(t, l)),
//   E[max(0, n_s . l)] = |l_p| / pi int_{-pi/2}^{pi/2} max(0, cos(psi - gamma)) dpsi
//                      = |l_p| (1 + cos gamma) / pi.
// Per unit light radiance:
//   B = headBehind a_f T_f(C_b) rho (1 - k_s) / pi * |l_p| (1 + cos gamma) / pi * T_f(C_all).
vec3 scalpBounce(int s, vec3 world, vec3 t, vec3 n, vec3 l, vec3 af, vec2 c) {
    vec3 lp = l - dot(l, t) * t;
    float lpLength = length(lp);
    float cosGamma = lpLength > 1e-6 ? dot(n, lp) / lpLength : 0.0;
    float skinCos = lpLength * (1.0 + cosGamma) * 0.31830989;
    vec3 skin = uHeadColor.rgb * ((1.0 - clamp(uHeadSkin.y, 0.0, 1.0)) * skinCos * 0.31830989) * exp(-uShadowColor.rgb * c.y);
    return headBehind(s, world) * af * exp(-uShadowColor.rgb * max(c.y - c.x, 0.0)) * skin;
}

// The head's depth from the camera (sorted hair; render/preview/preview.cpp cameraPass).
layout(binding = 9) uniform sampler2D uCameraHead;

// 1 where the camera sees the head behind a hair point: there resolve.frag
// composites the skin through the hair's forward scattering (skinThrough),
// which is the scalp's bounce taken from the skin the camera sees; 0 where
// the hair lies beside the head or past it (its silhouette), where only the
// bounce brings the skin's light.
float skinBehindInView(vec3 world) {
    vec4 c = uViewProj * vec4(world, 1.0);
    vec3 p = c.xyz / c.w * 0.5 + 0.5;
    if (any(lessThan(p.xy, vec2(0.0))) || any(greaterThan(p.xy, vec2(1.0)))) return 0.0;
    return texture(uCameraHead, p.xy).r < 1.0 ? 1.0 : 0.0;
}

// Light i's share, its shadow slot s (-1 none) and type given: constants
// when the program is compiled for its lights (HAIR_LIGHTS below).
vec3 shadeLight(int i, int s, bool point, vec3 world, vec3 t, vec3 n, vec3 v, vec3 albedo, float firstColumn,
                float bounce) {
    vec3 radiance;
    vec3 l = toLightOfType(i, point, world, radiance);
    if (SHADE_MODEL != kHairFitted) return kajiyaKay(albedo, t, n, l, v) * radiance * slotVisibility(s, world);
    vec3 af = vec3(1.0) - uShadowColor.rgb;
    if (!voxelsOn(s)) {
        // A light without a grid (unshadowed: it reaches every fibre, as
        // in the reference). The fibres toward it are lit too and pass on
        // what they scatter forward: n fibres deep a_f^n, spread n beta_f^2.
        // Summed over n = 1..N with N Poisson of mean C_h, half of slot
        // 0's column here (the hair's half thickness, the grid's one
        // measure of it; without a grid the infinite sum), times Zinke's d_f:
        //   d_f a_f (1 - exp(-(1 - a_f) C_h)) / (1 - a_f),
        // spread at the series' mean depth 1 / (1 - a_f), capped by C_h.
        float column = firstColumn;
        vec3 deep = af / max(vec3(1.0) - af, vec3(0.05));
        float meanDepth = 1.0 / max(1.0 - dot(af, vec3(0.2126, 0.7152, 0.0722)), 0.05);
        vec3 chain = kForwardDensity * deep;
        float reach = meanDepth;
        if (column >= 0.0) {
            float half_ = 0.5 * column;
            chain = kForwardDensity * deep * (vec3(1.0) - exp(-(vec3(1.0) - af) * half_));
            reach = min(meanDepth, max(half_, 1.0));
        }
        float spreadU = uShadowColor.w * reach;
        vec3 fScattered;
        vec3 f = fittedHairBoth(albedo, t, l, v, spreadU, uLobeShape[0].z * reach, fScattered) + chain * fScattered +
                 hairLobe(3, t, l, v, spreadU) * (column >= 0.0 ? vec3(1.0) - exp(-(vec3(1.0) - af * af) * 0.5 * column) : vec3(1.0));
        return f * radiance * headVisibility(s, world);
    }
    // A shadowed light (Zinke 2008 §4, their F(T_f, sigma_f^2, directFraction)):
    // n fibres lie toward the light, Poisson with mean C (the column in front).
    // With none (directFraction = P(n = 0) = exp(-C)) the light arrives straight:
    //   F_direct = exp(-C) (f_s + d_b f_back);
    // through n >= 1 it arrives forward-scattered, T_f = E[a_f^n] = exp(-(1 - a_f) C)
    // less that direct share, times their forward density factor d_f, spread along the
    // fibre by sigma_f^2 = n beta_f^2 and turned about it by n s_phi^2 (hairLobeTurned),
    // n's mean given n >= 1 being C / (1 - exp(-C)):
    //   F_scatter = (T_f - exp(-C)) d_f (f_s^G(sigma_f^2) + d_b f_back(sigma_f^2)).
    // d_b f_back is lobe 3 (A_b, Zinke eq. 13-14, render/reference/hair_fit.cpp). A_b
    // sums paths into a half-space of hair; through the C_b = column - C fibres behind
    // the point the round trips a_f^2k stop after about C_b, the factor
    // 1 - exp(-(1 - a_f^2) C_b) (Poisson mean of 1 - a_f^(2n)).
    vec2 c = hairColumn(s, world);
    float direct = exp(-c.x);
    vec3 scattered = max(exp(-uShadowColor.rgb * c.x) - vec3(direct), vec3(0.0)) * kForwardDensity;
    float crossed = c.x / max(1.0 - direct, 1e-4);
    float spread = uShadowColor.w * crossed;
    vec3 depthFactor = vec3(1.0) - exp(-(vec3(1.0) - af * af) * (c.y - c.x));
    vec3 fScattered, backScattered;
    vec3 fStraight = fittedHairBoth(albedo, t, l, v, spread, uLobeShape[0].z * crossed, fScattered);
    vec3 backStraight = hairLobeBoth(3, t, l, v, spread, 0.0, backScattered);
    vec3 f = direct * (fStraight + backStraight * depthFactor) + scattered * (fScattered + backScattered * depthFactor) +
             bounce * scalpBounce(s, world, t, n, l, af, c);
    return f * radiance * headVisibility(s, world);
}

vec3 shadeHair(vec3 world, vec3 tangent, vec3 albedo) {
    vec3 t = normalize(tangent);
    vec3 v = normalize(uEye.xyz - world);
    // The ribbon's normal: the view direction made perpendicular to the strand
    // (what a ray-facing curve in the reference has); only shifts tangents.
    vec3 n = v - dot(v, t) * t;
    n = dot(n, n) > 1e-12 ? normalize(n) : vec3(0.0);
    vec3 color = vec3(0.0);
    // Lights without a shadow slot take the hair's thickness from slot 0's
    // column through the point (once for all of them).
    float firstColumn = -1.0;
    // The scalp's bounce, except where sorted hair composites the skin the
    // camera sees behind it (resolve.frag): the same path, counted once.
    float bounce = 1.0;
    if (SHADE_MODEL == kHairFitted && (SHADE_FLAGS & kFlagSortedHair) != 0) bounce = 1.0 - skinBehindInView(world);
    if (SHADE_MODEL == kHairFitted && (SHADE_FLAGS & kFlagUnshadowedLights) != 0 && voxelsOn(uCounts.y > 0 ? 0 : -1))
        firstColumn = hairColumn(0, world).y;
#ifdef HAIR_LIGHTS
    // HAIR_LIGHTS(F) is F(i, slot, point) for each light, in order
    // (hairShadingDefines): one inlined call per light, with constants.
#define HAIR_SHADE_ONE(i, s, point) color += shadeLight(i, s, point, world, t, n, v, albedo, firstColumn, bounce);
    HAIR_LIGHTS(HAIR_SHADE_ONE)
#else
    for (int i = 0; i < uCounts.x; ++i)
        color += shadeLight(i, shadowSlot(i), uLightVec[i].w >= 0.5, world, t, n, v, albedo, firstColumn, bounce);
#endif
    return color;
}
