// Hair fragments (simulated and generated). Sorted hair: the premultiplied
// colour (c a, a), blended back to front with the over operator over black,
// and the skin behind (the head draws it into attachment 1) multiplied by
// what the fragment lets through of it, per channel (skinThrough). Weighted
// blended order-independent transparency (McGuire & Bavoil 2013):
// accumulation += (c a, a) * w, revealage *= 1 - a, with w falling with
// depth behind the scene's front (uBlend). Both: depth = min(depth, z).
#include "common.glsl"
#ifdef SHADE_PER_FRAGMENT
#include "hair_shading.glsl"
#endif

layout(location = 0) in vec3 gWorld;
layout(location = 1) in vec3 gTangent;
layout(location = 2) in float gAlpha;
layout(location = 3) in vec3 gColor;

layout(location = 0) out vec4 oColor;  // sorted: premultiplied, blended with the over operator
layout(location = 1) out vec4 oAccum;  // weighted: accumulation; sorted: the skin's transmittance
layout(location = 2) out vec4 oReveal;
layout(location = 3) out vec4 oDepth;

// What a hair fragment of coverage a lets through of the skin behind it. A
// fibre lets through its gaps, 1 - a, and of the light that meets it from
// behind it scatters some forward, toward the viewer. By reciprocity the
// radiance a fibre sends the viewer under radiance L_s from the half space
// behind it is L_s int_behind S(w_i, w_o) cos(theta_i) dw_i = L_s a_f(w_o),
// the share of the light arriving from the viewer that it scatters forward
// (Zinke, Yuksel, Weber and Keyser 2008, "Dual scattering approximation for
// fast multiple scattering in hair", the forward scattering albedo a_f of
// their eq. 6-7; render/reference/hair_fit.cpp integrates it from the
// physical fibre, Marschner et al. 2003 / Chiang et al. 2016). For skin of
// slowly varying radiance that half space is the skin, so a fragment passes
//   T = 1 - a + a a_f = 1 - a (1 - a_f)   per channel,
// and skin behind fragments a_1..a_k reaches the viewer as L_s prod T_j
// (the over operator's prod (1 - a_j) with a_f = 0, Kajiya-Kay). The light
// the fibre turns and spreads away from the straight path is taken from
// skin a few fibre widths away, of about the same radiance.
vec3 skinThrough(float a) { return vec3(1.0) - a * (vec3(1.0) - uForward.rgb); }

void main() {
#ifdef SHADE_PER_FRAGMENT
    vec3 color = shadeHair(gWorld, gTangent, gColor);
#else
    vec3 color = gColor;
#endif
    float a = clamp(gAlpha, 0.0, 1.0);
    float z = 1.0 / gl_FragCoord.w;  // camera-space depth
    float w = exp(-min(max(z - uBlend.x, 0.0) / uBlend.y, 80.0));
    oColor = vec4(color * a, a);
    if ((SHADE_FLAGS & kFlagSortedHair) != 0)
        oAccum = vec4(skinThrough(a), 1.0);  // multiplies the skin (rgb), keeps its coverage (alpha)
    else
        oAccum = vec4(color * a, a) * w;
    oReveal = vec4(a);
    oDepth = vec4(z);
}
