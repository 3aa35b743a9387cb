// Simulated strands, camera pass: each tessellated piece becomes a ribbon quad.
#include "common.glsl"

layout(lines) in;
layout(triangle_strip, max_vertices = 4) out;
layout(location = 0) in vec3 tWorld[];
layout(location = 1) in vec3 tTangent[];
layout(location = 2) in float tRadius[];
#ifdef SHADED_POINTS
layout(location = 3) in vec3 tColor[];  // radiance shaded by strand_shade.comp
#endif

#include "ribbon.glsl"

void main() {
    if (gl_in[0].gl_Position.w <= 1e-6 || gl_in[1].gl_Position.w <= 1e-6) return;  // behind the eye
#ifdef SHADED_POINTS
    emitRibbonEdges(tWorld[0], tTangent[0], tRadius[0], tColor[0]);
    emitRibbonEdges(tWorld[1], tTangent[1], tRadius[1], tColor[1]);
#else
    emitRibbonEdges(tWorld[0], tTangent[0], tRadius[0], uHairColor.rgb);
    emitRibbonEdges(tWorld[1], tTangent[1], tRadius[1], uHairColor.rgb);
#endif
    EndPrimitive();
}
