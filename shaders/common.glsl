// Shared by every preview program: the per-pass uniform block (mirrors
// FrameUniforms in render/preview/preview_gpu.h, std140) and small helpers.

layout(std140, binding = 0) uniform Frame {
    mat4 uViewProj;     // world -> clip of this pass (camera, or the light for shadow passes)
    mat4 uView;         // world -> camera view
    mat4 uLightView;    // light passes: world -> light view of the grid this pass voxelizes
    vec4 uEye;          // xyz camera position; w: focal length in target pixels (ribbon widths)
    vec4 uViewport;     // target width, height, 1/width, 1/height
    vec4 uGridMap;      // light passes: that grid's scale.xy, offset.xy
    vec4 uGridDepth;    // light passes: near depth, far depth, perspective (0/1), voxel resolution
    vec4 uLightVec[16]; // xyz: unit direction to a directional light, or a point light's position; w: 0 / 1
    vec4 uLightRad[16]; // rgb radiance (directional) or intensity (point, / distance^2); w: shadow slot, -1 none
    vec4 uHairColor;    // rgb albedo, kd
    vec4 uSpecColor;    // rgb, ks
    vec4 uSecondColor;  // rgb, secondary ks
    vec4 uHairShape;    // shininess, secondary shininess, primary shift, secondary shift
    vec4 uHeadColor;    // rgb albedo, ambient
    vec4 uHeadSkin;     // wrap, specular weight, shininess (render/view/view.h skinShade)
    vec4 uShadow;       // optical depth per unit of C, pcf radius, 1 / shadow map size, shadow-map depth bias
    vec4 uTess;         // max level, target pixels per piece, curve (0 Catmull-Rom, 1 B-spline), min width (px)
    vec4 uBlend;        // reference depth (m), depth scale (m), thin strands drawn as lines (0/1)
    vec4 uGravity;      // generated hair: xyz gravity
    vec4 uWind;         // xyz wind, w gust strength
    vec4 uFurTime;      // time (s), gust frequency (Hz), gust wavelength (m), inner level
    vec4 uFurLevels;    // outer level
    vec4 uLobeShape[4]; // fitted lobes R, TRT, TT, back (render/view/view.h HairLobe): exponent, shift (rad), -, -
    vec4 uLobeStrength[36]; // lobe k's strength table: [9k + node], rgb, at |thetaO| = node * 11.25 deg
    vec4 uShadowColor;  // rgb optical depth per unit of C (1 - T, or 1 - a_f fitted), w: beta_f^2 per unit of C
    mat4 uSlotClip[4];  // per shadow slot (a shadowed light, render/preview/light_grid.h): world -> light clip
    mat4 uSlotView[4];  // world -> light view
    vec4 uSlotMap[4];   // scale.xy, offset.xy
    vec4 uSlotDepth[4]; // near depth, far depth, perspective (0/1), voxel resolution
    ivec4 uCounts;      // light count, shadow slots, flags (kFlag*), hair model (kHair*)
    vec4 uLobeAzimuth[81]; // lobe k's N (1/rad) at |thetaO| = a * 11.25 deg, |phi| = b * 22.5 deg:
                           // float 81k + 9a + b, four to a vec4
};

const int kFlagVoxels = 1;
const int kFlagShadowMap = 2;
const int kFlagVoxelFilter = 4;
const int kFlagUnshadowedLights = 8;  // some light has no shadow slot
const int kFlagSortedHair = 16;       // sorted hair: the skin seen through it (resolve.frag), bounce only beside it

// uCounts.w: Kajiya-Kay with one or two lobes, or the fitted model with dual scattering.
const int kHairKajiyaKay = 0;
const int kHairKajiyaKayTwoLobes = 1;
const int kHairFitted = 2;

// Fixed point of the r32ui voxel grid: this many units make 1 (one strand
// crossing, or one fragment in Dehlin and Styngberg's count). Mirrors kVoxelUnit in
// render/preview/preview_gpu.h.
const float kVoxelUnit = 4096.0;

// Grid coordinates of a world point in a light's box (render/preview/light_grid.h).
vec3 gridCoordinates(mat4 view, vec4 map, vec4 range, vec3 world) {
    vec4 v = view * vec4(world, 1.0);
    float depth = -v.z;
    vec2 q = range.z > 0.5 ? v.xy / depth : v.xy;
    return vec3(q * map.xy + map.zw, (depth - range.x) / (range.y - range.x));
}

// ... in the grid this light pass voxelizes.
vec3 lightGrid(vec3 world) { return gridCoordinates(uLightView, uGridMap, uGridDepth, world); }

// ... in shadow slot s's grid.
vec3 slotGrid(int s, vec3 world) { return gridCoordinates(uSlotView[s], uSlotMap[s], uSlotDepth[s], world); }

// Light i's shadow slot, -1 for an unshadowed light.
int shadowSlot(int i) { return int(uLightRad[i].w); }

// The hair programs are compiled for their frame's lights and flags
// (render/preview/preview_uniforms.cpp hairShadingDefines): llvmpipe's
// vertex stages run both sides of every branch under a mask, even where the
// condition is uniform, so a branch on a uniform costs both of its sides on
// every vertex. HAIR_FLAGS and HAIR_MODEL make those conditions constants;
// without them (the head's programs) the uniforms decide.
#ifdef HAIR_FLAGS
#define SHADE_FLAGS HAIR_FLAGS
#else
#define SHADE_FLAGS uCounts.z
#endif
#ifdef HAIR_MODEL
#define SHADE_MODEL HAIR_MODEL
#else
#define SHADE_MODEL uCounts.w
#endif

// Unit direction from p toward light i, and its radiance there (render/view/view.cpp Light::toLight);
// `point`: light i is a point light (uLightVec[i].w = 1).
vec3 toLightOfType(int i, bool point, vec3 p, out vec3 radiance) {
    if (!point) {
        radiance = uLightRad[i].rgb;
        return uLightVec[i].xyz;
    }
    vec3 d = uLightVec[i].xyz - p;
    float r2 = max(dot(d, d), 1e-8);
    radiance = uLightRad[i].rgb / r2;
    return d / sqrt(r2);
}

vec3 toLight(int i, vec3 p, out vec3 radiance) { return toLightOfType(i, uLightVec[i].w >= 0.5, p, radiance); }
