// Hair fragments (simulated and generated). Sorted hair: the premultiplied
// colour (c a, a), blended back to front with the over operator over black
// (the resolve adds the skin behind, kept apart: resolve.frag). Weighted
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
layout(location = 1) out vec4 oAccum;
layout(location = 2) out vec4 oReveal;
layout(location = 3) out vec4 oDepth;

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
    oAccum = vec4(color * a, a) * w;
    oReveal = vec4(a);
    oDepth = vec4(z);
}
