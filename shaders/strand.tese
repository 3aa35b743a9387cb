// Simulated strands: a point of the smooth curve through the polyline,
// uniform Catmull-Rom (passes through every vertex) or uniform cubic
// B-spline (smoother, approximates the vertices). Isoline i of the patch is
// segment i, between control points i+1 and i+2. At a strand's root and tip
// the patch repeats the end vertex; it is mirrored (2b - c) instead, which
// makes both curves start and end exactly at the polyline's ends.
#include "common.glsl"

layout(isolines, equal_spacing) in;
in vec4 cPoint[];
layout(location = 0) out vec3 tWorld;
layout(location = 1) out vec3 tTangent;
layout(location = 2) out float tRadius;

void main() {
    int i = int(round(gl_TessCoord.y * gl_TessLevelOuter[0]));
    vec3 p1 = cPoint[i + 1].xyz, p2 = cPoint[i + 2].xyz;
    vec3 p0 = cPoint[i].xyz == p1 ? 2.0 * p1 - p2 : cPoint[i].xyz;
    vec3 p3 = cPoint[i + 3].xyz == p2 ? 2.0 * p2 - p1 : cPoint[i + 3].xyz;
    float u = gl_TessCoord.x, u2 = u * u, u3 = u2 * u;
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
    tRadius = mix(cPoint[i + 1].w, cPoint[i + 2].w, u);
    gl_Position = uViewProj * vec4(position, 1.0);
}
