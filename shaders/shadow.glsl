// Visibility of the shadowed lights (Dehlin and Styngberg 2017, 2.3), each
// through its own shadow slot: hair transmittance exp(-k C) = alpha^C from
// the slot's summed voxel grid, times the PCF shadow map of the head from
// that light. C counts strand crossings in front of the point (or fragments,
// Dehlin and Styngberg's count) and k = uShadowColor.rgb is the optical depth
// of one: 1 - T for a per-crossing transmittance T (render/preview/preview.h
// says why), -ln(alpha) for Dehlin and Styngberg's alpha, 1 - a_f per channel
// for the fitted hair. A light without a slot is unshadowed.

layout(binding = 4) uniform sampler3D uDensity[4];       // slot k's C (or V when the sum is off), trilinear
layout(binding = 1) uniform sampler2DArrayShadow uShadowMap; // head depth from each slot's light (layer k)

// The first slot (the key) takes the PCF kernel; the others one bilinear
// comparison (2 x 2 texels): each tap costs per shaded vertex and light,
// and the fill's and rim's head shadows are soft and faint on the hair.
float shadowMapVisibility(int s, vec3 world) {
    vec4 c = uSlotClip[s] * vec4(world, 1.0);
    vec3 p = c.xyz / c.w * 0.5 + 0.5;
    if (any(lessThan(p.xy, vec2(0.0))) || any(greaterThan(p.xy, vec2(1.0)))) return 1.0;
    int r = s == 0 ? int(uShadow.y) : 0;
    float lit = 0.0;
    // Seed eq. 8: the fraction of shadow-map texels around p that are not closer to the light.
    for (int y = -r; y <= r; ++y)
        for (int x = -r; x <= r; ++x)
            lit += texture(uShadowMap, vec4(p.xy + vec2(x, y) * uShadow.z, float(s), p.z - uShadow.w));
    float n = float(2 * r + 1);
    return lit / (n * n);
}

// C in front of a point. The grid stores at each voxel centre what lies
// strictly in front of that voxel; looking up half a voxel toward the light
// keeps a strand's own fragments (and its voxel neighbours behind it) out of
// its shadow, the voxel method's "acne". With kFlagVoxelFilter four lookups
// average C over 2 x 2 voxels across the beam (a tent over ~3 x 3): regularly
// spaced hair otherwise casts moire rings, since one-voxel-wide lines fill
// neighbouring columns unevenly. Only the first slot (the key, on the
// finest grid) is filtered: the other grids are coarser, their voxels span
// more hair, and four lookups per light cost the camera pass most of the
// other lights' shadows on llvmpipe (docs/rendering.md). (The slot index is
// dynamically uniform, as GLSL 4 requires for indexing sampler arrays: it
// comes from a uniform.)
float voxelDensityAt(int s, vec3 g) {
    if ((SHADE_FLAGS & kFlagVoxelFilter) == 0 || s > 0) return texture(uDensity[s], g).r;
    float h = 0.75 / uSlotDepth[s].w;
    return 0.25 * (texture(uDensity[s], g + vec3(-h, -h, 0.0)).r + texture(uDensity[s], g + vec3(h, -h, 0.0)).r +
                   texture(uDensity[s], g + vec3(-h, h, 0.0)).r + texture(uDensity[s], g + vec3(h, h, 0.0)).r);
}

bool voxelsOn(int s) { return s >= 0 && (SHADE_FLAGS & kFlagVoxels) != 0; }

// Expected hair crossings C in front of a point toward the light of shadow
// slot s (0 for an unshadowed light, s = -1, or without the voxel grid).
float slotCrossings(int s, vec3 world) {
    if (!voxelsOn(s)) return 0.0;
    return voxelDensityAt(s, slotGrid(s, world) - vec3(0.0, 0.0, 0.5 / uSlotDepth[s].w));
}

// Slot s's voxel column through a point: x the crossings C in front of it,
// y the whole column's C (the hair behind it, seen from the light, is y - x).
vec2 hairColumn(int s, vec3 world) {
    vec3 g = slotGrid(s, world);
    float half_ = 0.5 / uSlotDepth[s].w;
    float front = voxelDensityAt(s, g - vec3(0.0, 0.0, half_));
    return vec2(front, max(voxelDensityAt(s, vec3(g.xy, 1.0 - half_)), front));
}

// The head's shadow map toward the light of slot s (1 unshadowed).
float headVisibility(int s, vec3 world) {
    if (s < 0 || (SHADE_FLAGS & kFlagShadowMap) == 0) return 1.0;
    return shadowMapVisibility(s, world);
}

// 1 where the light's ray through a point goes on to meet the head (the skin
// lies behind the point, seen from the light of slot s), 0 where it leaves
// past the head: one comparison with the shadow map at the grid's far end.
float headBehind(int s, vec3 world) {
    if (s < 0 || (SHADE_FLAGS & kFlagShadowMap) == 0) return 0.0;
    vec4 c = uSlotClip[s] * vec4(world, 1.0);
    vec3 p = c.xyz / c.w * 0.5 + 0.5;
    if (any(lessThan(p.xy, vec2(0.0))) || any(greaterThan(p.xy, vec2(1.0)))) return 0.0;
    return 1.0 - texture(uShadowMap, vec4(p.xy, float(s), 0.9999));
}

// The head's own visibility: hair shadows only, as in the reference
// (render/reference/embree_scene.h RayStart::throughHead: a low-poly head shadowing
// itself cuts its smooth shading into a staircase along the terminator).
// Coloured: exp(-k C) per channel, k = uShadowColor.rgb (1 - T for
// Kajiya-Kay, 1 - a_f for the fitted hair: the light fibres scatter forward
// reaches the skin, Zinke 2008's forward transmittance).
vec3 hairOnlyVisibility(int light, vec3 world) { return exp(-uShadowColor.rgb * slotCrossings(shadowSlot(light), world)); }

// Hair and head toward the light of slot s (the hair's Kajiya-Kay visibility).
vec3 slotVisibility(int s, vec3 world) { return exp(-uShadowColor.rgb * slotCrossings(s, world)) * headVisibility(s, world); }
