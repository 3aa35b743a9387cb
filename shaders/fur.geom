// Generated hair (Dehlin and Styngberg 2017, 2.1.3): one strand per tessellated triangle, from
// its centre along its mean normal; after each segment the direction turns
// toward the force: d <- normalize(d + weight * force). The hair type (colour,
// segment count and length, force weight, root and tip radius) is read from
// the hair-type texture. The force is gravity plus gusting wind, travelling
// along the wind (render/preview/generated_hair.h, hairForce).
// Camera pass: one ribbon strip per strand. VOXEL_PASS: a line strip.
#include "common.glsl"

layout(triangles) in;
#ifdef VOXEL_PASS
layout(line_strip, max_vertices = 17) out;
layout(location = 0) out vec3 gWorld;
layout(location = 1) out vec3 gTangent;
layout(location = 2) out float gRadius;
#else
layout(triangle_strip, max_vertices = 34) out;
#include "ribbon.glsl"
#endif
layout(location = 0) in vec3 ePosition[];
layout(location = 1) in vec3 eNormal[];
layout(location = 2) in float eType[];

// Row 0: rgb colour, segment count; row 1: segment length, force weight, root radius, tip radius.
layout(binding = 2) uniform sampler2D uHairTypes;

void main() {
    int type = int(eType[0] + 0.5) - 1;
    if (type < 0) return;
    vec4 look = texelFetch(uHairTypes, ivec2(type, 0), 0);
    vec4 shape = texelFetch(uHairTypes, ivec2(type, 1), 0);
    int segments = clamp(int(look.w + 0.5), 1, 16);
    vec3 position = (ePosition[0] + ePosition[1] + ePosition[2]) / 3.0;
    vec3 dir = normalize(normalize(eNormal[0]) + normalize(eNormal[1]) + normalize(eNormal[2]));
    float windLength = length(uWind.xyz);
    float along = windLength > 0.0 ? dot(position, uWind.xyz) / windLength : 0.0;
    float phase = 6.28318530718 * (uFurTime.y * uFurTime.x - along / uFurTime.z);
    vec3 force = uGravity.xyz + uWind.xyz * (1.0 + uWind.w * sin(phase));
    vec3 prevDir = dir;
    for (int k = 0; k <= segments; ++k) {
        vec3 tangent = k == 0 ? dir : (k == segments ? prevDir : normalize(prevDir + dir));
        float radius = mix(shape.z, shape.w, float(k) / float(segments));
#ifdef VOXEL_PASS
        gWorld = position;
        gTangent = tangent;
        gRadius = radius;
        gl_Position = uViewProj * vec4(position, 1.0);
        EmitVertex();
#else
        emitRibbonEdges(position, tangent, radius, look.rgb);
#endif
        position += shape.x * dir;
        prevDir = dir;
        dir = normalize(dir + shape.y * force);
    }
    EndPrimitive();
}
