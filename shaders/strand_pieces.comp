// The thin strands' line pieces computed in two compute passes instead of
// the tessellation stages (render/preview/line_pieces.h): llvmpipe runs
// those on its calling thread alone, a patch at a time, ~2 s a frame at
// 100k strands (docs/benchmarks.md); compute shaders run on all its
// threads. COUNT: per patch, strand.tesc's choice (THIN_PASS), the pieces
// a line and the lines (0 culled). EMIT: per patch, strand.tese's points at
// the same tessellation coordinates (equal spacing: x = k / n on line l) as
// one strip of lines * n pieces (the end of line l is the start of line
// l + 1), shaded per point, and the pieces' index pairs, in patch order so
// the sorted patches stay back to front. Invocation = patch. (An
// invocation a point, its patch from a CPU-written list, cost more:
// docs/benchmarks.md.)
#include "common.glsl"
#include "strand_curve.glsl"
#ifdef EMIT
#include "hair_shading.glsl"
#endif

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Points { vec4 point[]; };  // xyz position, w radius
layout(std430, binding = 1) readonly buffer Patches { uint patchIndex[]; };  // PATCH_SIZE a patch
// Per patch: segments << 16 | lines << 8 | pieces a line; 0 culled.
layout(std430, binding = 2) buffer Shape { uint shape[]; };
#ifdef EMIT
layout(std430, binding = 3) readonly buffer Firsts { uvec2 first[]; };  // per patch: first vertex, first index
layout(std430, binding = 4) writeonly buffer Vertices { vec4 vertex[]; };  // two a point: clip position; rgb, alpha
layout(std430, binding = 5) writeonly buffer Indices { uint lineIndex[]; };
#endif
uniform uint uPatches;

vec4 P(uint p, int k) { return point[patchIndex[p * uint(PATCH_SIZE) + uint(k)]]; }

// strand.tesc's patchSegments, on the index list.
int patchSegments(uint p) {
    int n = 0;
    for (int k = 2; k < PATCH_SIZE && patchIndex[p * uint(PATCH_SIZE) + uint(k)] ==
                                          patchIndex[p * uint(PATCH_SIZE) + uint(k - 1)] + 1u; ++k)
        ++n;
    return min(n, PATCH_SIZE - 3);
}

void main() {
    uint id = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x;
#ifdef COUNT
    uint p = id;
    if (p >= uPatches) return;
    int segments = patchSegments(p);
    // strand.tesc, THIN_PASS, word for word.
    float pixels = 0.0;
    bvec4 outside = bvec4(true);
    bool behind = true;
    float widest = 0.0;
    vec2 previous = vec2(0.0);
    for (int i = 1; i <= segments + 1; ++i) {
        vec4 v = P(p, i);
        vec4 c = uViewProj * vec4(v.xyz, 1.0);
        float m = 1.1 * abs(c.w);
        outside = bvec4(outside.x && c.x > m, outside.y && c.x < -m, outside.z && c.y > m, outside.w && c.y < -m);
        behind = behind && c.w <= 0.0;
        widest = max(widest, 2.0 * v.w * uEye.w / max(c.w, 1e-6));
        vec2 q = c.xy / max(c.w, 1e-6) * 0.5 * uViewport.xy;
        if (i > 1) pixels += length(q - previous);
        previous = q;
    }
    float most = float(segments) * uTess.x;
    float pieces = uTess.y > 0.0 ? clamp(ceil(pixels / uTess.y), 1.0, most) : most;
    float lines = ceil(pieces / 64.0);
    bool cull = any(outside) || behind || segments < 1 || widest > uTess.w;
    // The segments too, so the emit pass need not count them again.
    shape[p] = cull ? 0u : (uint(segments) << 16) | (uint(lines) << 8) | uint(ceil(pieces / lines));
#else
    uint p = id;
    if (p >= uPatches) return;
    uint s_ = shape[p];
    int segments = int(s_ >> 16);
    uint lines = (s_ >> 8) & 255u, n = s_ & 255u;
    if (lines == 0u) return;
    uint count = lines * n;
    uvec2 f = first[p];
    for (uint j = 0u; j <= count; ++j) {
        uint l = min(j / n, lines - 1u);
        float x = float(j - l * n) / float(n);
        // strand.tese
        float s = (float(l) + x) / float(lines) * float(segments);
        int i = min(int(s), segments - 1);
        float u = s - float(i);
        vec4 c0 = P(p, i), c1 = P(p, i + 1), c2 = P(p, i + 2), c3 = P(p, i + 3);
        vec3 position, derivative;
        strandCurve(c0.xyz, c1.xyz, c2.xyz, c3.xyz, u, position, derivative);
        float radius = mix(c1.w, c2.w, u);
        vec4 clip = uViewProj * vec4(position, 1.0);
        float alpha = 2.0 * radius * uEye.w / clip.w / uTess.w;
        vertex[2u * (f.x + j)] = clip;
        vertex[2u * (f.x + j) + 1u] = vec4(shadeHair(position, derivative, uHairColor.rgb), alpha);
        if (j < count) {
            lineIndex[f.y + 2u * j] = f.x + j;
            lineIndex[f.y + 2u * j + 1u] = f.x + j + 1u;
        }
    }
#endif
}
