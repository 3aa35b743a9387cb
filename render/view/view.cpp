#include "render/view/view.h"

#include <algorithm>
#include <cmath>

namespace hp {

Mat4f lookAt(const Vec3f& eye, const Vec3f& target, const Vec3f& up) {
    const Vec3f f = (target - eye).normalized();
    const Vec3f s = f.cross(up).normalized();
    const Vec3f u = s.cross(f);
    Mat4f m = Mat4f::Identity();
    m.block<1, 3>(0, 0) = s.transpose();
    m.block<1, 3>(1, 0) = u.transpose();
    m.block<1, 3>(2, 0) = -f.transpose();
    m(0, 3) = -s.dot(eye);
    m(1, 3) = -u.dot(eye);
    m(2, 3) = f.dot(eye);
    return m;
}

Mat4f Camera::view() const { return lookAt(position, target, up); }

Mat4f Camera::projection() const {
    const float t = 1.f / std::tan(0.5f * fovY * float(M_PI) / 180.f);
    Mat4f m = Mat4f::Zero();
    m(0, 0) = t / aspect();
    m(1, 1) = t;
    m(2, 2) = (farClip + nearClip) / (nearClip - farClip);
    m(2, 3) = 2.f * farClip * nearClip / (nearClip - farClip);
    m(3, 2) = -1.f;
    return m;
}

CameraRays::CameraRays(const Camera& c)
    : forward_((c.target - c.position).normalized()),
      side_(forward_.cross(c.up).normalized()),
      up_(side_.cross(forward_)),
      tanHalf_(std::tan(0.5f * c.fovY * float(M_PI) / 180.f)),
      aspect_(c.aspect()),
      width_(float(c.width)),
      height_(float(c.height)) {}

Vec3f Camera::rayDirection(float x, float y) const { return CameraRays(*this).direction(x, y); }

Vec3f Light::toLight(const Vec3f& p, Vec3f* radiance, float* distance) const {
    if (type == LightType::Directional) {
        if (radiance) *radiance = color * intensity;
        if (distance) *distance = std::numeric_limits<float>::infinity();
        return -direction.normalized();
    }
    // Point, and quad/disk as a point of the same intensity at the centre.
    const Vec3f d = position - p;
    const float r2 = std::max(d.squaredNorm(), 1e-8f);
    if (radiance) *radiance = color * (intensity / r2);
    if (distance) *distance = std::sqrt(r2);
    return d / std::sqrt(r2);
}

std::vector<Light> View::worldLights() const {
    std::vector<Light> out = lights;
    const Vec3f back = (camera.position - camera.target).normalized();
    const Vec3f right = camera.up.cross(back).normalized();
    const Vec3f up = back.cross(right);
    for (Light& l : out) {
        if (!l.cameraRelative) continue;
        l.direction = l.direction.x() * right + l.direction.y() * up + l.direction.z() * back;
        l.up = l.up.x() * right + l.up.y() * up + l.up.z() * back;
        l.position = camera.target + l.position.x() * right + l.position.y() * up + l.position.z() * back;
        l.cameraRelative = false;
    }
    return out;
}

std::vector<Light> threePointRig() {
    auto light = [](Vec3f direction, Vec3f color, float intensity, bool shadows) {
        Light l;
        l.direction = direction;
        l.color = color;
        l.intensity = intensity;
        l.castsShadows = shadows;
        l.cameraRelative = true;
        return l;
    };
    return {light({0.85f, -0.5f, -0.3f}, {1.f, 0.95f, 0.88f}, 1.6f, true),
            light({-0.8f, -0.1f, -0.55f}, {0.85f, 0.9f, 1.f}, 0.25f, true),
            light({-0.25f, -0.6f, 0.8f}, {1.f, 1.f, 1.f}, 1.f, true)};
}

std::vector<int> limitShadowedLights(std::vector<Light>& lights, int maxLights) {
    std::vector<int> cleared;
    int kept = 0;
    for (size_t i = 0; i < lights.size(); ++i) {
        if (!lights[i].castsShadows) continue;
        if (kept < maxLights) {
            ++kept;
            continue;
        }
        lights[i].castsShadows = false;
        cleared.push_back(int(i));
    }
    return cleared;
}

Vec3f skinShade(const SurfaceMaterial& m, const Vec3f& n, const Vec3f& l, const Vec3f& v) {
    constexpr float kInvPi = float(1.0 / M_PI);
    const float c = n.dot(l);
    const float w = std::max(m.wrap, 0.f);
    const float ks = std::clamp(m.specular, 0.f, 1.f);
    Vec3f f = m.color * ((1.f - ks) * std::max(0.f, c + w) * kInvPi / ((1.f + w) * (1.f + w)));
    if (c > 0.f && ks > 0.f) {
        const float s = m.shininess;
        const float nh = std::max(0.f, n.dot((l + v).normalized()));
        // Exact normalisation of Blinn-Phong with the cosine (Giesen 2009),
        // (s + 2)(s + 4) / (8π (2^(−s/2) + s)): reflects exactly 1 seen head
        // on and less elsewhere; (s + 8)/(8π) overshoots it by up to 5%.
        const float norm = (s + 2.f) * (s + 4.f) * (0.125f * kInvPi) / (std::exp2(-0.5f * s) + s);
        f += Vec3f::Constant(ks * norm * std::pow(nh, s) * c);
    }
    return f;
}

namespace {
float sinBetween(const Vec3f& a, const Vec3f& b) {
    const float c = std::clamp(a.dot(b), -1.f, 1.f);
    return std::sqrt(std::max(0.f, 1.f - c * c));
}
Vec3f shifted(const Vec3f& t, const Vec3f& n, float shift) {
    if (shift == 0.f) return t;
    return (t + shift * n).normalized();
}
}  // namespace

bool HairLobe::empty() const {
    for (const Vec3f& k : strength)
        if (k.maxCoeff() > 0.f) return false;
    return true;
}

Vec3f HairLobe::strengthAt(float absThetaO) const {
    const float x = std::clamp(absThetaO / float(0.5 * M_PI), 0.f, 1.f) * float(kHairLobeNodes - 1);
    const int i = std::min(int(x), kHairLobeNodes - 2);
    const float f = x - float(i);
    return (1.f - f) * strength[size_t(i)] + f * strength[size_t(i) + 1];
}

float HairLobe::azimuthAt(float absThetaO, float absPhi) const {
    const float x = std::clamp(absThetaO / float(0.5 * M_PI), 0.f, 1.f) * float(kHairLobeNodes - 1);
    const float y = std::clamp(absPhi / float(M_PI), 0.f, 1.f) * float(kHairLobeNodes - 1);
    const int i = std::min(int(x), kHairLobeNodes - 2), j = std::min(int(y), kHairLobeNodes - 2);
    const float f = x - float(i), g = y - float(j);
    auto row = [&](int a) { return (1.f - g) * azimuth[size_t(a)][size_t(j)] + g * azimuth[size_t(a)][size_t(j) + 1]; };
    return (1.f - f) * row(i) + f * row(i + 1);
}

void HairLobe::setAzimuthPower(float m, float sign) {
    // ∫ over (−π, π] of the piecewise-linear table: 2 Σ (N_i + N_i+1)/2 Δφ.
    const double step = M_PI / (kHairLobeNodes - 1);
    std::array<float, kHairLobeNodes> row;
    double integral = 0.0;
    for (int i = 0; i < kHairLobeNodes; ++i) {
        const double c = std::cos(i * step);
        row[size_t(i)] = float(std::pow(std::max(0.0, 0.5 * (1.0 + sign * c)), double(m)));
        integral += (i == 0 || i == kHairLobeNodes - 1 ? 1.0 : 2.0) * row[size_t(i)] * step;
    }
    for (float& a : row) a = integral > 0.0 ? float(a / integral) : 0.f;
    azimuth.fill(row);
}

Vec3f hairLobe(const HairLobe& lobe, const Vec3f& t, const Vec3f& l, const Vec3f& v, float extraVariance) {
    const float si = std::clamp(t.dot(l), -1.f, 1.f), so = std::clamp(t.dot(v), -1.f, 1.f);
    const float ci = std::sqrt(1.f - si * si), co = std::sqrt(1.f - so * so);
    // cos(θi + θo − shift) from the sines and cosines the dot products give.
    const float cosSum = ci * co - si * so, sinSum = si * co + ci * so;
    const float c = cosSum * std::cos(lobe.shift) + sinSum * std::sin(lobe.shift);
    if (c <= 0.f) return Vec3f::Zero();
    const float n = lobe.exponent;
    const float nSpread = n / (1.f + n * std::max(extraVariance, 0.f));  // 1/n' = 1/n + σ²
    const float longitudinal = std::sqrt(nSpread / n) * std::pow(c, nSpread) / std::sqrt(std::max(ci * co, 0.01f));
    // Azimuth: the light's and the viewer's directions projected into the
    // normal plane; along the fibre the azimuth is undefined and N its mean.
    const Vec3f lp = l - si * t, vp = v - so * t;
    const float norms = std::sqrt(lp.squaredNorm() * vp.squaredNorm());
    const float absThetaO = std::asin(std::abs(so));
    const float azimuthal = norms > 1e-12f ? lobe.azimuthAt(absThetaO, std::acos(std::clamp(lp.dot(vp) / norms, -1.f, 1.f)))
                                           : 0.5f / float(M_PI);
    return lobe.strengthAt(absThetaO) * (longitudinal * azimuthal);
}

Vec3f kajiyaKay(const HairMaterial& m, const Vec3f& t, const Vec3f& n, const Vec3f& l, const Vec3f& v,
                Vec3f* diffuseOut, Vec3f* specularOut) {
    const Vec3f diffuse = m.kd * sinBetween(t, l) * m.color;
    if (m.shading == HairShading::Fitted) {
        const Vec3f lobes = hairLobe(m.r, t, l, v) + hairLobe(m.trt, t, l, v) + hairLobe(m.tt, t, l, v);
        if (diffuseOut) *diffuseOut = diffuse;
        if (specularOut) *specularOut = lobes;
        return diffuse + lobes;
    }
    const Vec3f h = (l + v).normalized();
    Vec3f specular = m.ks * std::pow(sinBetween(shifted(t, n, m.primaryShift), h), m.shininess) * m.specularColor;
    if (m.twoLobes) {
        specular += m.secondaryKs * std::pow(sinBetween(shifted(t, n, m.secondaryShift), h), m.secondaryShininess) *
                    m.secondaryColor;
    }
    if (diffuseOut) *diffuseOut = diffuse;
    if (specularOut) *specularOut = specular;
    return diffuse + specular;
}

}  // namespace hp
