// Generated hair: the PN-triangle (Vlachos et al. 2001) control net of a head
// triangle (Dehlin and Styngberg 2017, 2.1.2): cubic Bezier position coefficients b_ijk from the
// corners and their normals, quadratic normal coefficients n_ijk, and the
// inner/outer tessellation levels. The triangle's hair type comes along.
#include "common.glsl"

layout(vertices = 3) out;
layout(location = 0) in vec3 vPosition[];
layout(location = 1) in vec3 vNormal[];
layout(location = 0) out vec3 cPosition[];
layout(location = 1) out vec3 cNormal[];
patch out vec3 b210, b120, b021, b012, b102, b201, b111;
patch out vec3 n110, n011, n101;
patch out float pType;

layout(std430, binding = 3) readonly buffer TriangleTypes { uint uTypes[]; };

// Edge control point near p_i toward p_j, projected onto p_i's tangent plane.
vec3 edgePoint(vec3 pi, vec3 pj, vec3 ni) { return (2.0 * pi + pj - dot(pj - pi, ni) * ni) / 3.0; }

// Mid-edge normal, reflected across the plane perpendicular to the edge.
vec3 edgeNormal(vec3 pi, vec3 pj, vec3 ni, vec3 nj) {
    vec3 d = pj - pi;
    float v = 2.0 * dot(d, ni + nj) / max(dot(d, d), 1e-20);
    return normalize(ni + nj - v * d);
}

void main() {
    cPosition[gl_InvocationID] = vPosition[gl_InvocationID];
    cNormal[gl_InvocationID] = normalize(vNormal[gl_InvocationID]);
    if (gl_InvocationID != 0) return;
    vec3 p1 = vPosition[0], p2 = vPosition[1], p3 = vPosition[2];
    vec3 n1 = normalize(vNormal[0]), n2 = normalize(vNormal[1]), n3 = normalize(vNormal[2]);
    b210 = edgePoint(p1, p2, n1);
    b120 = edgePoint(p2, p1, n2);
    b021 = edgePoint(p2, p3, n2);
    b012 = edgePoint(p3, p2, n3);
    b102 = edgePoint(p3, p1, n3);
    b201 = edgePoint(p1, p3, n1);
    vec3 e = (b210 + b120 + b021 + b012 + b102 + b201) / 6.0;
    vec3 c = (p1 + p2 + p3) / 3.0;
    b111 = e + (e - c) / 2.0;
    n110 = edgeNormal(p1, p2, n1, n2);
    n011 = edgeNormal(p2, p3, n2, n3);
    n101 = edgeNormal(p3, p1, n3, n1);
    pType = float(uTypes[gl_PrimitiveID]);
    gl_TessLevelInner[0] = uFurTime.w;
    gl_TessLevelOuter[0] = uFurLevels.x;
    gl_TessLevelOuter[1] = uFurLevels.x;
    gl_TessLevelOuter[2] = uFurLevels.x;
}
