// Hair voxelization from the light's view (seed 004, 2.3.1): each fragment of
// a strand updates the r32ui grid with image atomics, in fixed point (256 = 1):
//   uMode 0  binary, nearest:     the fragment's voxel is set to 1
//   uMode 1  additive, nearest:   the fragment's voxel gets +1
//   uMode 2  additive, trilinear: +w for the 8 voxels around it, w the trilinear weights
#include "common.glsl"

layout(location = 0) in vec3 gWorld;
layout(r32ui, binding = 0) uniform coherent uimage3D uVoxels;
uniform int uMode;

const float kUnit = 256.0;

void main() {
    int res = int(uGridDepth.w);
    vec3 g = lightGrid(gWorld) * float(res);
    if (uMode != 2) {
        ivec3 v = ivec3(floor(g));
        if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, ivec3(res)))) return;
        if (uMode == 0)
            imageStore(uVoxels, v, uvec4(uint(kUnit)));
        else
            imageAtomicAdd(uVoxels, v, uint(kUnit));
        return;
    }
    vec3 c = g - 0.5;  // relative to voxel centres
    ivec3 base = ivec3(floor(c));
    vec3 f = c - vec3(base);
    for (int k = 0; k < 8; ++k) {
        ivec3 o = ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
        ivec3 v = base + o;
        if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, ivec3(res)))) continue;
        vec3 w3 = mix(1.0 - f, f, vec3(o));
        uint w = uint(round(w3.x * w3.y * w3.z * kUnit));
        if (w > 0u) imageAtomicAdd(uVoxels, v, w);
    }
}
