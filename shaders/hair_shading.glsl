// Radiance leaving a hair point toward the camera, under every light.
// Kajiya-Kay: the model times the light's visibility (voxel grid, shadow map).
// Fitted (render/reference/hair_fit.h): the dual-scattering approximation of
// Zinke, Yuksel, Weber and Keyser 2008. Behind C expected fibre crossings
// toward the light (the voxel grid) the light arriving is the forward-
// scattered T_f = exp(-(1 - a_f) C) (coloured: each fibre keeps what it
// scatters forward, a_f per channel), spread along the fibre by
// sigma_f^2 = C beta_f^2, which widens every lobe; the fibres around the point
// add the local back-scatter d_b f_back (lobe 3):
//   L = sum over lights of E T_f shadowMap (f_fitted(sigma_f^2) + d_b f_back(sigma_f^2)).
// Evaluated per ribbon vertex (default; Gouraud along the strand, which
// software rasterizers need for speed) or per fragment (SHADE_PER_FRAGMENT).
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
        if (uCounts.w != kHairFitted) {
            color += kajiyaKay(albedo, t, n, l, v) * radiance * lightVisibility(i, world);
            continue;
        }
        float crossings = hairCrossings(i, world);
        float spread = uShadowColor.w * crossings;
        vec3 f = fittedHair(albedo, t, l, v, spread) + hairLobe(3, t, l, v, spread);
        color += f * radiance * exp(-uShadowColor.rgb * crossings) * headVisibility(i, world);
    }
    return color;
}
