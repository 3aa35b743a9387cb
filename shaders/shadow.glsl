// Visibility of the shadowed light (seed 004, 2.3): hair transmittance
// alpha^C from the summed voxel grid, times the PCF shadow map of the head.

layout(binding = 0) uniform sampler3D uDensity;        // C (or V when the sum is off), trilinear
layout(binding = 1) uniform sampler2DShadow uShadowMap; // head depth from the light, compare mode on

float shadowMapVisibility(vec3 world) {
    vec4 c = uLightClip * vec4(world, 1.0);
    vec3 p = c.xyz / c.w * 0.5 + 0.5;
    if (any(lessThan(p.xy, vec2(0.0))) || any(greaterThan(p.xy, vec2(1.0)))) return 1.0;
    int r = int(uShadow.y);
    float lit = 0.0;
    // Seed eq. 8: the fraction of shadow-map texels around p that are not closer to the light.
    for (int y = -r; y <= r; ++y)
        for (int x = -r; x <= r; ++x)
            lit += texture(uShadowMap, vec3(p.xy + vec2(x, y) * uShadow.z, p.z - uShadow.w));
    float n = float(2 * r + 1);
    return lit / (n * n);
}

float voxelDensity(vec3 world) {
    return texture(uDensity, lightGrid(world)).r;
}

float lightVisibility(int light, vec3 world) {
    if (light != uCounts.y) return 1.0;
    float v = 1.0;
    if ((uCounts.z & kFlagVoxels) != 0) v *= pow(uShadow.x, voxelDensity(world));
    if ((uCounts.z & kFlagShadowMap) != 0) v *= shadowMapVisibility(world);
    return v;
}
