// Resolves the multisampled (and possibly supersampled) target into one
// pixel: per sample, hair = weighted-blended colour with alpha 1 - revealage
// over the opaque head; averaged; the environment fills the rest. Z is the
// nearest sample's camera depth. MULTISAMPLE selects sampler2DMS. SORTED:
// sorted hair was blended over black in place, and the skin behind it lies
// in the accumulation target: the pixel is the hair plus the skin seen
// through it (skinThrough), its alpha the hair's over the skin's coverage
// (revealage is neither cleared nor read).
#ifdef MULTISAMPLE
#define SAMPLER sampler2DMS
#else
#define SAMPLER sampler2D
#endif
layout(binding = 0) uniform SAMPLER uOpaque;
layout(binding = 1) uniform SAMPLER uAccum;
layout(binding = 2) uniform SAMPLER uReveal;
layout(binding = 3) uniform SAMPLER uDepth;
uniform int uSamples;
uniform int uSupersample;
uniform vec3 uEnvironment;
uniform vec3 uForward;  // sorted: the hair's forward albedo a_f (0 for Kajiya-Kay)

// What hair of coverage A (the over operator's alpha) lets through of the
// skin behind it. A fibre lets through its gaps, and of the light that meets
// it from behind it scatters some forward, toward the viewer: by reciprocity
// the radiance a fibre sends the viewer under radiance L_s from the half
// space behind it is L_s int_behind S(w_i, w_o) cos(theta_i) dw_i =
// L_s a_f(w_o), the share of light arriving from the viewer that it scatters
// forward (Zinke, Yuksel, Weber and Keyser 2008, "Dual scattering
// approximation for fast multiple scattering in hair", their forward
// scattering albedo a_f; render/reference/hair_fit.cpp integrates it from
// the physical fibre). For skin of slowly varying radiance that half space is
// the skin, so a fragment of coverage a passes 1 - a + a a_f = 1 - a (1 - a_f)
// per channel, and fragments a_1..a_k, each thinner than a sample:
//   prod (1 - a_j (1 - a_f)) = exp(sum ln(1 - a_j (1 - a_f)))
//                           ~ exp(-(1 - a_f) sum a_j) ~ (prod (1 - a_j))^(1 - a_f) = (1 - A)^(1 - a_f)
// (to first order in each a_j; the over operator's 1 - A for a_f = 0). The
// light the fibres turn and spread away from the straight path is taken from
// skin a few fibre widths away, of about the same radiance.
// NO_FORWARD_SCATTERING: a_f = 0 (Kajiya-Kay hair), the over operator's 1 - A
// without the pow (llvmpipe's is exp2(log2 x y), its cost per sample and channel).
#ifdef NO_FORWARD_SCATTERING
vec3 skinThrough(float coverage) { return vec3(max(1.0 - coverage, 1e-30)); }
#else
vec3 skinThrough(float coverage) { return pow(vec3(max(1.0 - coverage, 1e-30)), vec3(1.0) - uForward); }
#endif

layout(location = 0) out vec4 oColor;
layout(location = 1) out vec4 oDepth;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 sum = vec4(0.0);
    float depth = uintBitsToFloat(0x7F800000u);  // +inf
    for (int sy = 0; sy < uSupersample; ++sy)
        for (int sx = 0; sx < uSupersample; ++sx) {
            ivec2 p = pixel * uSupersample + ivec2(sx, sy);
            for (int s = 0; s < uSamples; ++s) {
#ifdef MULTISAMPLE
                const int q = s;
#else
                const int q = 0;
#endif
                vec4 opaque = texelFetch(uOpaque, p, q);
                depth = min(depth, texelFetch(uDepth, p, q).r);
                vec4 accum = texelFetch(uAccum, p, q);
#ifdef SORTED
                sum += vec4(opaque.rgb + accum.rgb * skinThrough(opaque.a), opaque.a + (1.0 - opaque.a) * accum.a);
#else
                float reveal = texelFetch(uReveal, p, q).r;
                float hairAlpha = 1.0 - reveal;
                vec3 hair = accum.a > 0.0 ? accum.rgb / accum.a * hairAlpha : vec3(0.0);
                sum += vec4(hair, hairAlpha) + opaque * reveal;
#endif
            }
        }
    sum /= float(uSamples * uSupersample * uSupersample);
    sum.rgb += uEnvironment * (1.0 - sum.a);
    oColor = sum;
    oDepth = vec4(depth);
}
