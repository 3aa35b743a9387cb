// Shades the simulated strands' vertices once a frame, before the camera
// pass: the radiance at the curve's point at each vertex (strand_curve.glsl)
// into a buffer that strand.tese interpolates along each segment
// (SHADED_POINTS). llvmpipe runs the tessellation stages on its calling
// thread alone and fills their SIMD lanes with one patch's few points; a
// compute dispatch runs on all its threads with full lanes, and shades each
// vertex once instead of at every tessellated point (render/preview/preview_gpu.h
// ShadedPoints). Same patch list as the draw: invocation (patch, k) shades
// slot k + 1's vertex, the start of the patch's segment k, and the tip at
// k = segments when the patch ends the strand, so each vertex is written by
// exactly one invocation (a chunk's last vertex is the next chunk's first).
#include "common.glsl"
#include "strand_curve.glsl"
#include "hair_shading.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Points { vec4 point[]; };    // xyz position, w radius
layout(std430, binding = 1) readonly buffer Patches { uint patchIndex[]; };  // PATCH_SIZE vertex indices a patch
layout(std430, binding = 2) writeonly buffer Colors { vec4 color[]; };    // rgb radiance per vertex
uniform uint uPatches;

const uint kSlots = uint(PATCH_SIZE - 2);  // vertex slots 1 .. PATCH_SIZE - 2 can start a segment or end the strand

void main() {
    uint id = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x;
    uint patch_ = id / kSlots;
    int k = int(id % kSlots);
    if (patch_ >= uPatches) return;
    uint base = patch_ * uint(PATCH_SIZE);
    // Segments in the patch as strand.tesc's patchSegments counts them.
    int segments = 0;
    for (int j = 2; j < PATCH_SIZE && patchIndex[base + j] == patchIndex[base + j - 1] + 1u; ++j) ++segments;
    segments = min(segments, PATCH_SIZE - 3);
    if (segments < 1 || k > segments) return;
    // The strand's tip belongs to its last patch; a chunk's end vertex to the next chunk.
    if (k == segments && patchIndex[base + segments + 2] != patchIndex[base + segments + 1]) return;
    int i = min(k, segments - 1);
    float u = float(k - i);
    vec4 c0 = point[patchIndex[base + i]], c1 = point[patchIndex[base + i + 1]];
    vec4 c2 = point[patchIndex[base + i + 2]], c3 = point[patchIndex[base + i + 3]];
    vec3 position, derivative;
    strandCurve(c0.xyz, c1.xyz, c2.xyz, c3.xyz, u, position, derivative);
    color[patchIndex[base + k + 1]] = vec4(shadeHair(position, derivative, uHairColor.rgb), 1.0);
}
