// Resolves the multisampled (and possibly supersampled) target into one
// pixel: per sample, hair = weighted-blended colour with alpha 1 - revealage
// over the opaque head; averaged; the environment fills the rest. Z is the
// nearest sample's camera depth. MULTISAMPLE selects sampler2DMS. SORTED:
// sorted hair was blended over black in place, and the skin behind it,
// multiplied by what each hair fragment lets through (hair.frag), lies in
// the accumulation target: the pixel is hair plus that skin, its alpha the
// hair's over the skin's coverage (revealage is neither cleared nor read).
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
                sum += vec4(opaque.rgb + accum.rgb, opaque.a + (1.0 - opaque.a) * accum.a);
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
