// Generated hair: a point of the PN triangle (Dehlin and Styngberg 2017 eqs. for p(u,v) and
// n(u,v)); u, v, w weight corners 1, 2, 3.
#include "common.glsl"

layout(triangles, equal_spacing, ccw) in;
layout(location = 0) in vec3 cPosition[];
layout(location = 1) in vec3 cNormal[];
patch in vec3 b210, b120, b021, b012, b102, b201, b111;
patch in vec3 n110, n011, n101;
patch in float pType;
layout(location = 0) out vec3 ePosition;
layout(location = 1) out vec3 eNormal;
layout(location = 2) out float eType;

void main() {
    float u = gl_TessCoord.x, v = gl_TessCoord.y, w = gl_TessCoord.z;
    vec3 b300 = cPosition[0], b030 = cPosition[1], b003 = cPosition[2];
    ePosition = b300 * u * u * u + b030 * v * v * v + b003 * w * w * w + 3.0 * b210 * u * u * v +
                3.0 * b120 * u * v * v + 3.0 * b201 * u * u * w + 3.0 * b021 * v * v * w + 3.0 * b012 * v * w * w +
                3.0 * b102 * u * w * w + 6.0 * b111 * u * v * w;
    eNormal = cNormal[0] * u * u + cNormal[1] * v * v + cNormal[2] * w * w + n110 * u * v + n011 * v * w +
              n101 * u * w;
    eType = pType;
    gl_Position = uViewProj * vec4(ePosition, 1.0);
}
