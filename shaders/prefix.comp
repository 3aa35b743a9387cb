// Sums the voxel grid along the light's depth (Dehlin and Styngberg 2017 eq. 7): for each
// column, C at voxel z = sum of V over voxels strictly in front of it (the
// light reaching its front face is alpha^C). With uSum = 0 it copies V
// instead, Dehlin and Styngberg's look at the bare voxelization.
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(r32ui, binding = 0) readonly uniform uimage3D uVoxels;
layout(r32f, binding = 1) writeonly uniform image3D uDensity;
uniform int uSum;
uniform int uResolution;  // this light's grid: a corner of the shared voxel image

void main() {
    ivec3 size = ivec3(uResolution);
    ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
    if (xy.x >= size.x || xy.y >= size.y) return;
    float sum = 0.0;
    for (int z = 0; z < size.z; ++z) {
        float v = float(imageLoad(uVoxels, ivec3(xy, z)).r) / kVoxelUnit;
        imageStore(uDensity, ivec3(xy, z), vec4(uSum != 0 ? sum : v));
        sum += v;
    }
}
