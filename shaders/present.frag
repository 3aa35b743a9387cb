// The viewer's display: the resolved linear image, sRGB-encoded.
layout(binding = 0) uniform sampler2D uImage;
uniform ivec4 uRect;  // x, y, width, height of the window viewport
layout(location = 0) out vec4 oColor;

vec3 toSrgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

void main() {
    vec2 uv = (gl_FragCoord.xy - vec2(uRect.xy)) / vec2(uRect.zw);
    oColor = vec4(toSrgb(texture(uImage, uv).rgb), 1.0);
}
