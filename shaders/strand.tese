// Simulated strands: a point of the smooth curve through the polyline
// (strand_curve.glsl). The isolines of a patch cover the strand's parameter
// range [0, segments] one after the other; segment i lies between control
// points i+1 and i+2.
#include "common.glsl"
#include "strand_curve.glsl"

layout(isolines, equal_spacing) in;
in vec4 cPoint[];
patch in float pSegments;
patch in float pFirst;  // vertex index of control point 1 (the patch's first segment's start)
#ifdef CAPTURE
// The first light's voxel pass keeps its pieces for the other lights'
// (transform feedback, render/preview/preview_gpu.h CapturedPieces): world
// position, tangent and radius, 28 bytes a vertex.
layout(xfb_buffer = 0, xfb_stride = 28) out;
layout(location = 0, xfb_offset = 0) out vec3 tWorld;
layout(location = 1, xfb_offset = 12) out vec3 tTangent;
layout(location = 2, xfb_offset = 24) out float tRadius;
#else
layout(location = 0) out vec3 tWorld;
layout(location = 1) out vec3 tTangent;
#endif
#ifdef LINE_OUTPUT
// Thin hair goes straight to the rasterizer as lines of the minimum width:
// the outputs are the hair fragment shader's inputs (as ribbon.glsl's).
layout(location = 2) out float gAlpha;
layout(location = 3) out vec3 gColor;
#if !defined(SHADED_POINTS) && !defined(SHADE_PER_FRAGMENT)
#include "hair_shading.glsl"
#endif
#elif !defined(CAPTURE)
layout(location = 2) out float tRadius;
#ifdef SHADED_POINTS
layout(location = 3) out vec3 tColor;  // ribbon.geom's per-vertex radiance
#endif
#endif
#ifdef SHADED_POINTS
// Radiance at each strand vertex, shaded once a frame by strand_shade.comp
// (render/preview/preview_gpu.h ShadedPoints), interpolated along the
// segment: Gouraud between the curve's points at u = 0 and 1, where the
// compute pass shaded them.
layout(binding = 8) uniform samplerBuffer uPointColor;

vec3 shadedPoint(int i, float u) {
    int first = int(pFirst) + i;
    return mix(texelFetch(uPointColor, first).rgb, texelFetch(uPointColor, first + 1).rgb, u);
}
#endif

void main() {
    float lines = gl_TessLevelOuter[0];
    float s = (round(gl_TessCoord.y * lines) + gl_TessCoord.x) / lines * pSegments;
    int i = min(int(s), int(pSegments) - 1);
    float u = s - float(i);
    vec3 position, derivative;
    strandCurve(cPoint[i].xyz, cPoint[i + 1].xyz, cPoint[i + 2].xyz, cPoint[i + 3].xyz, u, position, derivative);
    tWorld = position;
    tTangent = derivative;
    float radius = mix(cPoint[i + 1].w, cPoint[i + 2].w, u);
    gl_Position = uViewProj * vec4(position, 1.0);
#ifdef LINE_OUTPUT
    gAlpha = 2.0 * radius * uEye.w / gl_Position.w / uTess.w;  // true width / drawn width
#if defined(SHADE_PER_FRAGMENT)
    gColor = uHairColor.rgb;
#elif defined(SHADED_POINTS)
    gColor = shadedPoint(i, u);
#else
    gColor = shadeHair(position, derivative, uHairColor.rgb);
#endif
#else
    tRadius = radius;
#ifdef SHADED_POINTS
    tColor = shadedPoint(i, u);
#endif
#endif
}
