#include "render/reference/light_sampling.h"

#include "render/reference/sampling.h"

#include <algorithm>
#include <cmath>

namespace hp {

namespace {

constexpr float kPi = float(M_PI);

/// Shirley and Chiu's concentric map of [0, 1)² onto the unit disk
/// ("A Low Distortion Map Between Disk and Square", 1997): area-preserving,
/// so uniform in u gives uniform on the disk.
Vec2f concentricDisk(const Vec2f& u) {
    const float a = 2.f * u.x() - 1.f, b = 2.f * u.y() - 1.f;
    if (a == 0.f && b == 0.f) return Vec2f::Zero();
    float r, phi;
    if (std::abs(a) > std::abs(b)) r = a, phi = 0.25f * kPi * (b / a);
    else r = b, phi = 0.5f * kPi - 0.25f * kPi * (a / b);
    return {r * std::cos(phi), r * std::sin(phi)};
}

}  // namespace

SampledLight::SampledLight(const Light& light) : light_(light) {
    delta_ = light.isDelta();
    const Vec3f power = light.color * std::max(light.intensity, 0.f);
    switch (light.type) {
        case LightType::Point: break;
        case LightType::Directional: {
            normal_ = -light.direction.normalized();
            if (delta_) break;
            const float half = 0.5f * std::min(light.angle, 179.f) * kPi / 180.f;
            // 1 − cos x = 2 sin²(x/2), without the cancellation of small angles.
            const float s = std::sin(0.5f * half);
            cosMax_ = 1.f - 2.f * s * s;
            const float sinHalf = std::sin(half);
            radiance_ = power / (kPi * sinHalf * sinHalf);
            sampling::orthonormalBasis(normal_, &ex_, &ey_);
            break;
        }
        case LightType::Quad:
        case LightType::Disk: {
            normal_ = light.direction.normalized();
            Vec3f x = light.up.cross(normal_);
            if (x.squaredNorm() < 1e-8f) {
                Vec3f y;
                sampling::orthonormalBasis(normal_, &x, &y);
            }
            ex_ = x.normalized();
            ey_ = normal_.cross(ex_);
            const float w = std::max(light.size.x(), 1e-6f), h = std::max(light.size.y(), 1e-6f);
            area_ = light.type == LightType::Quad ? w * h : 0.25f * kPi * w * w;
            radiance_ = power / area_;
            break;
        }
    }
}

LightSample SampledLight::sample(const Vec3f& p, const Vec2f& u) const {
    LightSample s;
    if (delta_) {
        s.wi = light_.toLight(p, &s.radiance, &s.distance);
        s.valid = s.radiance.maxCoeff() > 0.f;
        return s;
    }
    if (light_.type == LightType::Directional) {
        // Uniform in the cone: cos θ uniform in [cos θmax, 1].
        const float cosT = 1.f - u.x() * (1.f - cosMax_);
        const float sinT = std::sqrt(std::max(0.f, 1.f - cosT * cosT));
        const float phi = 2.f * kPi * u.y();
        s.wi = (sinT * std::cos(phi) * ex_ + sinT * std::sin(phi) * ey_ + cosT * normal_).normalized();
        s.radiance = radiance_;
        s.pdf = 1.f / (2.f * kPi * (1.f - cosMax_));
        s.valid = true;
        return s;
    }
    Vec2f local;
    if (light_.type == LightType::Quad)
        local = Vec2f((u.x() - 0.5f) * light_.size.x(), (u.y() - 0.5f) * light_.size.y());
    else
        local = 0.5f * light_.size.x() * concentricDisk(u);
    const Vec3f q = light_.position + local.x() * ex_ + local.y() * ey_;
    const Vec3f d = q - p;
    const float r2 = d.squaredNorm();
    if (!(r2 > 0.f)) return s;
    const float r = std::sqrt(r2);
    s.wi = d / r;
    const float cosL = -s.wi.dot(normal_);
    if (!(cosL > 0.f)) return s;  // behind the one-sided emitter
    s.distance = r;
    s.radiance = radiance_;
    s.pdf = r2 / (area_ * cosL);  // area density to solid angle
    s.valid = true;
    return s;
}

bool SampledLight::hit(const Vec3f& o, const Vec3f& d, float tmax, Vec3f* radiance, float* pdf) const {
    if (delta_) return false;
    if (light_.type == LightType::Directional) {
        if (std::isfinite(tmax) || d.dot(normal_) < cosMax_) return false;
        *radiance = radiance_;
        *pdf = 1.f / (2.f * kPi * (1.f - cosMax_));
        return true;
    }
    const float dn = d.dot(normal_);
    if (!(dn < 0.f)) return false;  // parallel, or seeing its back
    const float t = (light_.position - o).dot(normal_) / dn;
    if (!(t > 0.f && t < tmax)) return false;
    const Vec3f q = o + t * d - light_.position;
    const float x = q.dot(ex_), y = q.dot(ey_);
    if (light_.type == LightType::Quad) {
        if (std::abs(x) > 0.5f * light_.size.x() || std::abs(y) > 0.5f * light_.size.y()) return false;
    } else if (x * x + y * y > 0.25f * light_.size.x() * light_.size.x()) {
        return false;
    }
    *radiance = radiance_;
    *pdf = t * t / (area_ * -dn);
    return true;
}

float SampledLight::scale(const Vec3f& p) const {
    const float c = (light_.color * std::max(light_.intensity, 0.f)).maxCoeff();
    if (light_.type == LightType::Directional) return c;
    return c / std::max((light_.position - p).squaredNorm(), 1e-8f);
}

}  // namespace hp
