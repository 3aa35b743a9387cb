// Kajiya-Kay hair shading, a line-for-line mirror of kajiyaKay() in
// render/view/view.cpp (the Embree reference calls that function), so preview and
// reference shade the same model: kd*color*sin(t,l) + ks*spec*sin(t',h)^alpha
// with h = normalize(l + v) (seed 004 eq. 4, 5) and the optional second,
// shifted-tangent lobe.

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
    if (uCounts.w != 0)
        specular += uSecondColor.w * pow(sinBetween(shiftedTangent(t, n, uHairShape.w), h), uHairShape.y) *
                    uSecondColor.rgb;
    return diffuse + specular;
}
