// Shades the simulated strands' vertices once a frame, before the camera
// pass: the radiance at the curve's point at each vertex (strand_curve.glsl)
// into a buffer that strand.tese interpolates along each segment
// (SHADED_POINTS). llvmpipe runs the tessellation stages on its calling
// thread alone and fills their SIMD lanes with one patch's few points; a
// compute dispatch runs on all its threads with full lanes, and shades each
// vertex once (render/preview/preview_gpu.h ShadedPoints). Invocation i
// shades vertex i with the neighbours the tessellation gives it: the start of
// segment (i, i + 1) at u = 0, or at a strand's tip the end of its last
// segment at u = 1; at a root or tip the missing neighbour repeats the end
// vertex, which strandCurve mirrors, as the patches do
// (render/preview/preview_buffers.cpp StrandBuffers::upload).
#include "common.glsl"
#include "strand_curve.glsl"
#include "hair_shading.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Points { vec4 point[]; };  // xyz position, w radius
// Four vertices a word, a byte each (render/preview/preview_gpu.h ShadedPoints::flags): bit 0 the
// vertex is a strand's root, bit 1 its tip.
layout(std430, binding = 1) readonly buffer Flags { uint vertexFlags[]; };
layout(std430, binding = 2) writeonly buffer Colors { vec4 color[]; };  // rgb radiance per vertex
uniform uint uVertices;

uint flagsOf(uint i) { return (vertexFlags[i >> 2] >> (8u * (i & 3u))) & 3u; }

void main() {
    uint i = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x;
    if (i >= uVertices) return;
    uint f = flagsOf(i);
    if (f == 3u) return;  // a strand of one vertex draws nothing
    bool tip = (f & 2u) != 0u;
    uint a = tip ? i - 1u : i;  // the segment (a, a + 1) the point lies on
    uint before = (flagsOf(a) & 1u) != 0u ? a : a - 1u;
    uint after = (flagsOf(a + 1u) & 2u) != 0u ? a + 1u : a + 2u;
    vec3 position, derivative;
    strandCurve(point[before].xyz, point[a].xyz, point[a + 1u].xyz, point[after].xyz, tip ? 1.0 : 0.0, position,
                derivative);
    color[i] = vec4(shadeHair(position, derivative, uHairColor.rgb), 1.0);
}
