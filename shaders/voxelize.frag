// Hair voxelization from the light's view (Dehlin and Styngberg 2017, 2.3.1): each fragment of
// a strand updates the r32ui grid with image atomics, in fixed point
// (kVoxelUnit = 1):
//   uMode 0  binary, nearest:     the fragment's voxel is set to w (the largest w wins)
//   uMode 1  additive, nearest:   the fragment's voxel gets +w
//   uMode 2  additive, trilinear: +w times the trilinear weights of the 8 voxels around it
// w is 1 with uCrossings = 0 (the seed: C counts fragments), else the number
// of crossings of this strand that a light ray through the fragment's voxel
// column expects (crossingWeight): C is then in strand crossings, the unit of
// the reference renderer's per-crossing transmittance.
#include "common.glsl"

layout(location = 0) in vec3 gWorld;
layout(location = 1) in vec3 gTangent;
layout(location = 2) in float gRadius;
layout(r32ui, binding = 0) uniform coherent uimage3D uVoxels;
// The mode and the weight are compile-time constants (VOXEL_MODE,
// VOXEL_CROSSINGS, set by render/preview/preview.cpp for the frame's
// settings): llvmpipe runs both sides of a branch on a uniform under an
// execution mask, so as uniforms every fragment paid the trilinear splat's 8
// atomics and the crossing weight whatever the settings.
const int uMode = VOXEL_MODE;
const int uCrossings = VOXEL_CROSSINGS;

// A fragment stands for the piece of strand inside one raster pixel (GL's
// diamond-exit rule gives one fragment per pixel along the line's major
// axis). A light ray through a random point of the pixel's column crosses
// that piece with probability (its projected area) / (pixel area); the
// projected area of a fibre of radius r is 2 r sin(theta) per metre of
// strand (theta between strand and ray), and a metre of strand covers
// max(|g.x|, |g.y|) fragments (g: raster pixels per metre along the strand).
float crossingWeight(vec3 world, vec3 tangent, float radius) {
    float len = length(tangent);
    if (len <= 0.0) return 0.0;
    vec4 v = uLightView * vec4(world, 1.0);
    vec3 dv = mat3(uLightView) * (tangent / len);
    float res = uGridDepth.w;
    vec2 pixel, dq;  // world size of a raster pixel across the beam; beam coordinates per metre of strand
    float sinTheta;
    if (uGridDepth.z > 0.5) {
        float depth = max(-v.z, 1e-6);
        pixel = depth / (uGridMap.xy * res);
        dq = (dv.xy + v.xy / depth * dv.z) / depth;
        vec3 ray = normalize(v.xyz);
        sinTheta = length(dv - dot(dv, ray) * ray);
    } else {
        pixel = 1.0 / (uGridMap.xy * res);
        dq = dv.xy;
        sinTheta = length(dv.xy);
    }
    vec2 g = abs(dq) * uGridMap.xy * res;
    float perMetre = max(g.x, g.y);
    return perMetre > 0.0 ? 2.0 * radius * sinTheta / (pixel.x * pixel.y * perMetre) : 0.0;
}

void main() {
    int res = int(uGridDepth.w);
    vec3 g = lightGrid(gWorld) * float(res);
    float w = uCrossings != 0 ? crossingWeight(gWorld, gTangent, gRadius) : 1.0;
    if (uMode != 2) {
        ivec3 v = ivec3(floor(g));
        if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, ivec3(res)))) return;
        uint units = uint(round(w * kVoxelUnit));
        if (uMode == 0)
            imageAtomicMax(uVoxels, v, units);
        else if (units > 0u)
            imageAtomicAdd(uVoxels, v, units);
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
        uint units = uint(round(w * w3.x * w3.y * w3.z * kVoxelUnit));
        if (units > 0u) imageAtomicAdd(uVoxels, v, units);
    }
}
