// Simulated strands: a point of the smooth curve through the polyline,
// uniform Catmull-Rom (passes through every vertex) or uniform cubic
// B-spline (smoother, approximates the vertices). The isolines of a patch
// cover the strand's parameter range [0, segments] one after the other;
// segment i lies between control points i+1 and i+2. At a strand's root and tip
// the patch repeats the end vertex; it is mirrored (2b - c) instead, which
// makes both curves start and end exactly at the polyline's ends.
#include "common.glsl"

layout(isolines, equal_spacing) in;
in vec4 cPoint[];
patch in float pSegments;
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
#ifndef SHADE_PER_FRAGMENT
#include "hair_shading.glsl"
#endif
#elif !defined(CAPTURE)
layout(location = 2) out float tRadius;
#endif

void main() {
    float lines = gl_TessLevelOuter[0];
    float s = (round(gl_TessCoord.y * lines) + gl_TessCoord.x) / lines * pSegments;
    int i = min(int(s), int(pSegments) - 1);
    vec3 p1 = cPoint[i + 1].xyz, p2 = cPoint[i + 2].xyz;
    vec3 p0 = cPoint[i].xyz == p1 ? 2.0 * p1 - p2 : cPoint[i].xyz;
    vec3 p3 = cPoint[i + 3].xyz == p2 ? 2.0 * p2 - p1 : cPoint[i + 3].xyz;
    float u = s - float(i), u2 = u * u, u3 = u2 * u;
    vec3 position, derivative;
    if (uTess.z < 0.5) {
        position = 0.5 * (2.0 * p1 + (p2 - p0) * u + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u2 +
                          (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * u3);
        derivative = 0.5 * ((p2 - p0) + 2.0 * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u +
                            3.0 * (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * u2);
    } else {
        float v = 1.0 - u;
        position = (v * v * v * p0 + (3.0 * u3 - 6.0 * u2 + 4.0) * p1 + (-3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0) * p2 +
                    u3 * p3) / 6.0;
        derivative = (-3.0 * v * v * p0 + (9.0 * u2 - 12.0 * u) * p1 + (-9.0 * u2 + 6.0 * u + 3.0) * p2 +
                      3.0 * u2 * p3) / 6.0;
    }
    if (dot(derivative, derivative) < 1e-20) derivative = p2 - p1;
    tWorld = position;
    tTangent = derivative;
    float radius = mix(cPoint[i + 1].w, cPoint[i + 2].w, u);
    gl_Position = uViewProj * vec4(position, 1.0);
#ifdef LINE_OUTPUT
    gAlpha = 2.0 * radius * uEye.w / gl_Position.w / uTess.w;  // true width / drawn width
#ifdef SHADE_PER_FRAGMENT
    gColor = uHairColor.rgb;
#else
    gColor = shadeHair(position, derivative, uHairColor.rgb);
#endif
#else
    tRadius = radius;
#endif
}
