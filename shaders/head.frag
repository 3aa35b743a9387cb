// The opaque head: albedo * (ambient + sum of Lambert * radiance * visibility).
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
    vec3 light = vec3(uHeadColor.w);
    for (int i = 0; i < uCounts.x; ++i) {
        vec3 radiance;
        vec3 l = toLight(i, vWorld, radiance);
        float lambert = max(dot(n, l), 0.0);
        if (lambert > 0.0) light += lambert * radiance * lightVisibility(i, vWorld);
    }
    oColor = vec4(uHeadColor.rgb * light, 1.0);
    oDepth = vec4(1.0 / gl_FragCoord.w);
}
#endif
