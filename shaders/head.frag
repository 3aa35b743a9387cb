// The opaque head: albedo * ambient + sum of skinShade * radiance * hair's
// shadow (the head does not shadow itself; shaders/shadow.glsl says why).
// With DEPTH_ONLY it is the shadow map's (empty) fragment stage.
#include "common.glsl"
#include "shadow.glsl"

layout(location = 0) in vec3 vWorld;
layout(location = 1) in vec3 vNormal;

#ifdef DEPTH_ONLY
void main() {}
#else
layout(location = 0) out vec4 oColor;
layout(location = 3) out vec4 oDepth;

void main() {
    vec3 n = normalize(vNormal);
    vec3 v = normalize(uEye.xyz - vWorld);
    // Shading normals face the viewer, as the reference's do.
    if (dot(n, v) < 0.0) n = -n;
    vec3 color = uHeadColor.rgb * uHeadColor.w;
    float w = max(uHeadSkin.x, 0.0);
    for (int i = 0; i < uCounts.x; ++i) {
        vec3 radiance;
        vec3 l = toLight(i, vWorld, radiance);
        float c = dot(n, l);
        // skinShade (render/view/view.cpp): wrapped diffuse plus a Blinn-Phong sheen.
        vec3 f = uHeadColor.rgb * max(0.0, (c + w) / (1.0 + w));
        if (c > 0.0 && uHeadSkin.y > 0.0) f += vec3(uHeadSkin.y * pow(max(0.0, dot(n, normalize(l + v))), uHeadSkin.z));
        if (max(f.r, max(f.g, f.b)) > 0.0) color += f * radiance * hairOnlyVisibility(i, vWorld);
    }
    oColor = vec4(color, 1.0);
    oDepth = vec4(1.0 / gl_FragCoord.w);
}
#endif
