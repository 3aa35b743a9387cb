// Radiance leaving a hair point toward the camera: Kajiya-Kay under every
// light times that light's visibility (voxel grid, shadow map). Evaluated per
// ribbon vertex (default; Gouraud along the strand, which software
// rasterizers need for speed) or per fragment (SHADE_PER_FRAGMENT).
#include "kajiya_kay.glsl"
#include "shadow.glsl"

vec3 shadeHair(vec3 world, vec3 tangent, vec3 albedo) {
    vec3 t = normalize(tangent);
    vec3 v = normalize(uEye.xyz - world);
    // The ribbon's normal: the view direction made perpendicular to the strand
    // (what a ray-facing curve in the reference has); only shifts tangents.
    vec3 n = v - dot(v, t) * t;
    n = dot(n, n) > 1e-12 ? normalize(n) : vec3(0.0);
    vec3 color = vec3(0.0);
    for (int i = 0; i < uCounts.x; ++i) {
        vec3 radiance;
        vec3 l = toLight(i, world, radiance);
        color += kajiyaKay(albedo, t, n, l, v) * radiance * lightVisibility(i, world);
    }
    return color;
}
