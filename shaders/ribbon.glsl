// Camera-facing ribbons for geometry shaders. At each strand point the two
// edge vertices sit half the drawn width either side of the centre line,
// perpendicular to the strand's direction on screen (computed from the
// tangent, so consecutive pieces share edges exactly). A strand narrower than
// the minimum width (uTess.w pixels) is drawn that wide with alpha = true
// width / drawn width: its expected coverage stays its projected area.
// gColor carries the shaded radiance (per-vertex shading) or the albedo;
// with SHADED_POINTS `color` comes shaded already (strand_shade.comp).
#if !defined(SHADE_PER_FRAGMENT) && !defined(SHADED_POINTS)
#include "hair_shading.glsl"
#endif

layout(location = 0) out vec3 gWorld;
layout(location = 1) out vec3 gTangent;
layout(location = 2) out float gAlpha;
layout(location = 3) out vec3 gColor;

void emitRibbonEdges(vec3 world, vec3 tangent, float radius, vec3 color) {
    vec4 clip = uViewProj * vec4(world, 1.0);
    vec4 clipT = uViewProj * vec4(tangent, 0.0);
    vec2 dir = (clipT.xy * clip.w - clip.xy * clipT.w) * uViewport.xy;  // screen direction, in pixel units
    float len = length(dir);
    vec2 side = len > 1e-20 ? vec2(-dir.y, dir.x) / len : vec2(1.0, 0.0);
    float widthPx = 2.0 * radius * uEye.w / clip.w;
    float drawnPx = max(widthPx, uTess.w);
    vec2 offset = side * drawnPx * uViewport.zw * clip.w;  // half width, pixels -> clip
#if !defined(SHADE_PER_FRAGMENT) && !defined(SHADED_POINTS)
    color = shadeHair(world, tangent, color);
#endif
    gWorld = world;
    gTangent = tangent;
    gAlpha = widthPx / drawnPx;
    gColor = color;
    gl_Position = vec4(clip.xy - offset, clip.zw);
    EmitVertex();
    gWorld = world;
    gTangent = tangent;
    gAlpha = widthPx / drawnPx;
    gColor = color;
    gl_Position = vec4(clip.xy + offset, clip.zw);
    EmitVertex();
}
