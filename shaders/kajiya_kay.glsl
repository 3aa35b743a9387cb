// Kajiya-Kay hair shading, a line-for-line mirror of kajiyaKay() in
// render/view/view.cpp (the Embree reference calls that function), so preview and
// reference shade the same model: kd*color*sin(t,l) + ks*spec*sin(t',h)^alpha
// with h = normalize(l + v) (Dehlin and Styngberg 2017 eq. 4, 5) and the optional second,
// shifted-tangent lobe; hairLobe() mirrors the fitted lobes of the same
// family (render/view/view.cpp hairLobe, render/reference/hair_fit.h).

float sinBetween(vec3 a, vec3 b) {
    float c = clamp(dot(a, b), -1.0, 1.0);
    return sqrt(max(0.0, 1.0 - c * c));
}

// Eigen's normalized() leaves a zero vector unchanged; so does this.
vec3 safeNormalize(vec3 a) {
    float len2 = dot(a, a);
    return len2 > 0.0 ? a * inversesqrt(len2) : a;
}

vec3 shiftedTangent(vec3 t, vec3 n, float shift) {
    return shift == 0.0 ? t : safeNormalize(t + shift * n);
}

vec3 kajiyaKay(vec3 albedo, vec3 t, vec3 n, vec3 l, vec3 v) {
    vec3 h = safeNormalize(l + v);  // light straight behind the hair: h = 0, sin = 1, as on the CPU
    vec3 diffuse = uHairColor.w * sinBetween(t, l) * albedo;
    vec3 specular = uSpecColor.w * pow(sinBetween(shiftedTangent(t, n, uHairShape.z), h), uHairShape.x) *
                    uSpecColor.rgb;
    if (SHADE_MODEL == kHairKajiyaKayTwoLobes)
        specular += uSecondColor.w * pow(sinBetween(shiftedTangent(t, n, uHairShape.w), h), uHairShape.y) *
                    uSecondColor.rgb;
    return diffuse + specular;
}

// Fitted lobe k's N at |thetaO| node a, |phi| node b (render/view/view.h HairLobe::azimuth).
float lobeAzimuth(int k, int a, int b) {
    int index = (9 * k + a) * 9 + b;
    return uLobeAzimuth[index >> 2][index & 3];
}

// What lobe k's straight and scattered responses share, most of a lobe's cost: the
// cone term c = cos(thetaI + thetaO - shift), 1 / sqrt(cos thetaI cos thetaO), the
// strength at |thetaO| and the tabulated N(|phi|; |thetaO|). False where c <= 0 (no light).
bool lobeTerms(int k, vec3 t, vec3 l, vec3 v, out float c, out float projected, out vec3 strength, out float azimuthal) {
    vec4 shape = uLobeShape[k];
    float si = clamp(dot(t, l), -1.0, 1.0), so = clamp(dot(t, v), -1.0, 1.0);
    float ci = sqrt(1.0 - si * si), co = sqrt(1.0 - so * so);
    c = (ci * co - si * so) * cos(shape.y) + (si * co + ci * so) * sin(shape.y);
    projected = 0.0;
    strength = vec3(0.0);
    azimuthal = 0.15915494;  // along the fibre phi is undefined: N's mean, 1 / (2 pi)
    if (c <= 0.0) return false;
    projected = inversesqrt(max(ci * co, 0.01));
    vec3 lp = l - si * t, vp = v - so * t;
    float norms = sqrt(dot(lp, lp) * dot(vp, vp));
    float x = clamp(asin(abs(so)) * (16.0 / 3.14159265), 0.0, 8.0);  // |thetaO| in node units (11.25 deg)
    int i = min(int(x), 7);
    strength = mix(uLobeStrength[9 * k + i].rgb, uLobeStrength[9 * k + i + 1].rgb, x - float(i));
    if (norms > 1e-12) {
        float y = acos(clamp(dot(lp, vp) / norms, -1.0, 1.0)) * (8.0 / 3.14159265);  // |phi| in node units (22.5 deg)
        int j = min(int(y), 7);
        float g = y - float(j);
        azimuthal = mix(mix(lobeAzimuth(k, i, j), lobeAzimuth(k, i, j + 1), g),
                        mix(lobeAzimuth(k, i + 1, j), lobeAzimuth(k, i + 1, j + 1), g), x - float(i));
    }
    return true;
}

// N turned by the azimuthal variance `turn` (hairLobeTurned's N_V).
float turnedAzimuth(float azimuthal, float turn) {
    return 0.15915494 + (azimuthal - 0.15915494) * exp(-0.5 * max(turn, 0.0));
}

// Fitted lobe k (render/view/view.cpp hairLobe): strength(|thetaO|) * cos(thetaI + thetaO - shift)^n'
// * sqrt(n'/n) / sqrt(cos thetaI cos thetaO) * N(|phi|; |thetaO|), strength and N tabulated
// (linear between nodes), with 1/n' = 1/n + spread (rad^2): light spread by the fibres it crossed.
// `turn` (rad^2) is the variance of the azimuth by which those fibres turned the light (n
// crossings: n s_phi^2, uLobeShape's z). N is then N convolved with that spread around the
// fibre; on the circle a convolution with a wrapped normal of variance V multiplies N's
// Fourier coefficient k by exp(-k^2 V / 2); keeping the first, k = 1, for all (the others
// fade faster, so this keeps a little too much of the peak):
//   N_V(phi) = 1/(2 pi) + (N(phi) - 1/(2 pi)) exp(-V / 2).
// Zinke 2008 takes the limit instead, N averaged over the forward half circle (their N^G),
// which on the default shot lit the key's shaded side 4 times as bright as the physical render.
vec3 hairLobeTurned(int k, vec3 t, vec3 l, vec3 v, float spread, float turn) {
    float c, projected, azimuthal;
    vec3 strength;
    if (!lobeTerms(k, t, l, v, c, projected, strength, azimuthal)) return vec3(0.0);
    float n = uLobeShape[k].x / (1.0 + uLobeShape[k].x * max(spread, 0.0));
    float longitudinal = sqrt(n / uLobeShape[k].x) * pow(c, n) * projected;
    return strength * (longitudinal * turnedAzimuth(azimuthal, turn));
}

vec3 hairLobe(int k, vec3 t, vec3 l, vec3 v, float spread) { return hairLobeTurned(k, t, l, v, spread, 0.0); }

// Lobe k for straight light (no spread, N as tabulated), and in `scattered` for
// light spread by `spread` and turned by `turn` (hairLobeTurned): the two share
// their angles and table lookups, which are most of a lobe's cost.
vec3 hairLobeBoth(int k, vec3 t, vec3 l, vec3 v, float spread, float turn, out vec3 scattered) {
    scattered = vec3(0.0);
    float c, projected, azimuthal;
    vec3 strength;
    if (!lobeTerms(k, t, l, v, c, projected, strength, azimuthal)) return vec3(0.0);
    float n = uLobeShape[k].x / (1.0 + uLobeShape[k].x * max(spread, 0.0));
    scattered = strength * (sqrt(n / uLobeShape[k].x) * pow(c, n) * projected * turnedAzimuth(azimuthal, turn));
    return strength * (pow(c, uLobeShape[k].x) * projected * azimuthal);
}

// The fitted single-fibre response (kajiyaKay() in HairShading::Fitted: diffuse
// kd * albedo * cos(thetaI) plus R, TRT and TT) to straight light, and in
// `scattered` to light that reached the fibre through n other fibres (Zinke 2008's
// f_s^scatter): every lobe spread along the fibre by `spread` = n beta_f^2 and
// turned about it by `turn` = n s_phi^2.
vec3 fittedHairBoth(vec3 albedo, vec3 t, vec3 l, vec3 v, float spread, float turn, out vec3 scattered) {
    vec3 diffuse = uHairColor.w * sinBetween(t, l) * albedo;
    vec3 r, trt, tt;
    vec3 straight = diffuse + hairLobeBoth(0, t, l, v, spread, turn, r) + hairLobeBoth(1, t, l, v, spread, turn, trt) +
                    hairLobeBoth(2, t, l, v, spread, turn, tt);
    scattered = diffuse + r + trt + tt;
    return straight;
}
