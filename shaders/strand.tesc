// Simulated strands: a patch is a whole strand (or a chunk of a long one):
// the vertex before its first segment, its segments' vertices, the vertex
// after (render/preview/preview_buffers.cpp). Chooses how many pieces the strand's
// curve is cut into: enough for about uTess.y pixels each on screen, at most
// uTess.x per segment. The count is per strand, not per segment, so a strand
// far away costs few triangles (software rasterizers pay per triangle) and a
// close-up one is smooth. Pieces go on isolines of at most 64 (GL's limit).
// Culls strands wholly outside the view. PATCH_SIZE is set by the renderer.
// Hair thinner than the minimum width along its whole length is drawn as
// multisampled lines (THIN_PASS), the rest as geometry-shader ribbons
// (THICK_PASS): each pass culls the other's strands here, per patch.
#include "common.glsl"

layout(vertices = PATCH_SIZE) out;
in vec4 vPoint[];
in float vIndex[];
out vec4 cPoint[];
patch out float pSegments;
patch out float pFirst;  // vertex index of control point 1 (strand.tese reads the shaded vertices by it)

// Segments in this patch, read off its vertex indices: slots 1, 2, ... are
// consecutive vertices of the strand up to its last segment's end; after it
// comes the next vertex (a chunk that does not end at the tip) or the tip
// again, repeated. (Not a per-patch buffer indexed by gl_PrimitiveID: Mesa
// 22.3's llvmpipe numbers patches per batch there, which gave chunks of long
// strands the wrong counts.)
int patchSegments() {
    int n = 0;
    for (int k = 2; k < PATCH_SIZE && vIndex[k] == vIndex[k - 1] + 1.0; ++k) ++n;
    return min(n, PATCH_SIZE - 3);
}

void main() {
    cPoint[gl_InvocationID] = vPoint[gl_InvocationID];
    if (gl_InvocationID != 0) return;
    int segments = patchSegments();
    // Screen length of the polyline and whether it lies beyond one clip plane.
    float pixels = 0.0;
    bvec4 outside = bvec4(true);
    bool behind = true;
    float widest = 0.0;  // pixels
    vec2 previous = vec2(0.0);
    for (int i = 1; i <= segments + 1; ++i) {
        vec4 c = uViewProj * vec4(vPoint[i].xyz, 1.0);
        float m = 1.1 * abs(c.w);  // margin for the curve's bulge and the ribbon's width
        outside = bvec4(outside.x && c.x > m, outside.y && c.x < -m, outside.z && c.y > m, outside.w && c.y < -m);
        behind = behind && c.w <= 0.0;
        widest = max(widest, 2.0 * vPoint[i].w * uEye.w / max(c.w, 1e-6));
        vec2 p = c.xy / max(c.w, 1e-6) * 0.5 * uViewport.xy;
        if (i > 1) pixels += length(p - previous);
        previous = p;
    }
    float most = float(segments) * uTess.x;
    float pieces = uTess.y > 0.0 ? clamp(ceil(pixels / uTess.y), 1.0, most) : most;
#ifdef MIN_SEGMENTS_PER_PIECE
    // Light passes draw whole strands (render/preview/preview.cpp
    // lightStrands): at least one piece per this many segments, as the
    // camera's sorted patches of that many segments each get.
    pieces = max(pieces, min(ceil(float(segments) / float(MIN_SEGMENTS_PER_PIECE)), most));
#endif
    float lines = ceil(pieces / 64.0);
    bool cull = any(outside) || behind || segments < 1;
#if defined(THIN_PASS)
    cull = cull || widest > uTess.w;
#elif defined(THICK_PASS)
    cull = cull || (uBlend.z > 0.5 && widest <= uTess.w);  // uBlend.z: the thin pass runs
#endif
    pSegments = float(segments);
    pFirst = vIndex[1];
    gl_TessLevelOuter[0] = cull ? 0.0 : lines;
    gl_TessLevelOuter[1] = ceil(pieces / lines);
}
