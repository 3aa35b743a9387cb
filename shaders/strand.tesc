// Simulated strands: a patch is a whole strand (or a chunk of a long one):
// the vertex before its first segment, its segments' vertices, the vertex
// after (render/preview_buffers.cpp). Sets one isoline per segment, cut into
// enough pieces for about uTess.y pixels each (at most uTess.x), and culls
// strands wholly outside the view. PATCH_SIZE is defined by the renderer.
#include "common.glsl"

layout(vertices = PATCH_SIZE) out;
in vec4 vPoint[];
out vec4 cPoint[];

layout(std430, binding = 4) readonly buffer PatchSegments { uint uPatchSegments[]; };

void main() {
    cPoint[gl_InvocationID] = vPoint[gl_InvocationID];
    if (gl_InvocationID != 0) return;
    int segments = int(uPatchSegments[gl_PrimitiveID]);
    // Screen length of the polyline and whether it lies beyond one clip plane.
    float pixels = 0.0;
    bvec4 outside = bvec4(true);
    bool behind = true;
    vec2 previous = vec2(0.0);
    for (int i = 1; i <= segments + 1; ++i) {
        vec4 c = uViewProj * vec4(vPoint[i].xyz, 1.0);
        float m = 1.1 * abs(c.w);  // margin for the curve's bulge and the ribbon's width
        outside = bvec4(outside.x && c.x > m, outside.y && c.x < -m, outside.z && c.y > m, outside.w && c.y < -m);
        behind = behind && c.w <= 0.0;
        vec2 p = c.xy / max(c.w, 1e-6) * 0.5 * uViewport.xy;
        if (i > 1) pixels += length(p - previous);
        previous = p;
    }
    float level = uTess.y > 0.0 ? clamp(ceil(pixels / (float(segments) * uTess.y)), 1.0, uTess.x) : uTess.x;
    bool cull = any(outside) || behind || segments < 1;
    gl_TessLevelOuter[0] = cull ? 0.0 : float(segments);  // isolines: one per segment
    gl_TessLevelOuter[1] = level;                         // pieces along each
}
