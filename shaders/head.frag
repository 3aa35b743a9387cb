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
layout(location = 1) out vec4 oSkin;  // sorted hair: the skin apart, seen through the hair (resolve.frag)
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
        // skinShade (render/view/view.cpp): energy-conserving wrapped Lambert
        // plus a normalised Blinn-Phong sheen, (1 - ks) + ks <= 1.
        float ks = clamp(uHeadSkin.y, 0.0, 1.0);
        vec3 f = uHeadColor.rgb * ((1.0 - ks) * max(0.0, c + w) / (3.14159265 * (1.0 + w) * (1.0 + w)));
        if (c > 0.0 && ks > 0.0) {
            float s = uHeadSkin.z;
            float norm = (s + 2.0) * (s + 4.0) / (8.0 * 3.14159265 * (exp2(-0.5 * s) + s));
            f += vec3(ks * norm * pow(max(0.0, dot(n, normalize(l + v))), s) * c);
        }
        if (max(f.r, max(f.g, f.b)) > 0.0) color += f * radiance * hairOnlyVisibility(i, vWorld);
    }
    oColor = vec4(color, 1.0);
    oSkin = oColor;
    oDepth = vec4(1.0 / gl_FragCoord.w);
}
#endif
