// The thin strands' line pieces from strand_pieces.comp: its clip position
// and its shaded colour and alpha, handed to hair.frag as strand.tese does.
layout(location = 0) in vec4 aClip;
layout(location = 1) in vec4 aColor;  // rgb radiance, alpha: true width / drawn width
layout(location = 2) out float gAlpha;
layout(location = 3) out vec3 gColor;

void main() {
    gl_Position = aClip;
    gAlpha = aColor.a;
    gColor = aColor.rgb;
}
