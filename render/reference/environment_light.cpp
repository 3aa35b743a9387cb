#include "render/reference/environment_light.h"

#include "core/errors.h"
#include "render/image/image_io.h"

#include <algorithm>
#include <cmath>

namespace hp {

namespace {

constexpr float kPi = float(M_PI);

float luminance(const Vec3f& c) { return 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z(); }

/// Index of the interval of a CDF (n + 1 values, cdf[0] = 0, cdf[n] = 1)
/// that holds x, skipping empty intervals, and x's position in it.
int findInterval(const float* cdf, int n, float x, float* within) {
    const int i = int(std::upper_bound(cdf + 1, cdf + n, x) - (cdf + 1));
    const int k = std::clamp(i, 0, n - 1);
    const float width = cdf[k + 1] - cdf[k];
    *within = width > 0.f ? std::clamp((x - cdf[k]) / width, 0.f, 0.99999994f) : 0.5f;
    return k;
}

}  // namespace

Vec3f latLongDirection(float u, float v) {
    const float phi = 2.f * kPi * u - kPi, theta = kPi * v;
    const float s = std::sin(theta);
    return {s * std::sin(phi), std::cos(theta), -s * std::cos(phi)};
}

Vec2f latLongCoordinates(const Vec3f& d) {
    const float phi = std::atan2(d.x(), -d.z());
    // atan2, not acos(y): acos loses most digits of θ near the poles, where
    // the density's 1/sin θ needs them.
    const float theta = std::atan2(std::sqrt(d.x() * d.x() + d.z() * d.z()), d.y());
    return {(phi + kPi) / (2.f * kPi), theta / kPi};
}

EnvironmentMap loadEnvironmentMap(const std::string& path, float intensity, float rotationDegrees) {
    const Image img = readImage(path);  // AssetError naming the file
    if (img.width <= 0 || img.height <= 0 || img.channelCount() < 1)
        throw AssetError(path, "the environment map is empty");
    const int nc = img.channelCount();
    int ch[3] = {img.channelIndex("R"), img.channelIndex("G"), img.channelIndex("B")};
    for (int c = 0; c < 3; ++c)
        if (ch[c] < 0) ch[c] = nc >= 3 ? c : 0;  // unnamed channels in order; grey fills all three
    auto rgb = std::make_shared<std::vector<float>>(size_t(img.width) * size_t(img.height) * 3);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double weight = 0.0;
    for (int y = 0; y < img.height; ++y) {
        const double sinT = std::sin(M_PI * (y + 0.5) / img.height);
        for (int x = 0; x < img.width; ++x) {
            float* out = &(*rgb)[(size_t(y) * img.width + x) * 3];
            for (int c = 0; c < 3; ++c) {
                const float v = img.at(x, y, ch[c]);
                out[c] = std::isfinite(v) ? std::max(v, 0.f) : 0.f;
                sum[c] += out[c] * sinT;
            }
            weight += sinT;
        }
    }
    EnvironmentMap m;
    m.path = path;
    m.width = img.width;
    m.height = img.height;
    m.rgb = rgb;
    m.intensity = intensity;
    m.rotationDegrees = rotationDegrees;
    m.mean = (sum / weight).cast<float>() * intensity;
    return m;
}

EnvironmentLight::EnvironmentLight(const Vec3f& constant, const EnvironmentMap& map) {
    const bool hasMap = !map.empty() && map.intensity > 0.f;
    const Vec3f c = constant.cwiseMax(0.f);
    if (!hasMap && !(c.maxCoeff() > 0.f)) return;
    hasMap_ = hasMap;
    width_ = hasMap ? map.width : 64;
    height_ = hasMap ? map.height : 32;
    const float rot = hasMap ? map.rotationDegrees * kPi / 180.f : 0.f;
    cosRot_ = std::cos(rot);
    sinRot_ = std::sin(rot);
    radiance_.assign(size_t(width_) * height_, c);
    if (hasMap)
        for (size_t k = 0; k < radiance_.size(); ++k)
            radiance_[k] += map.intensity * Vec3f((*map.rgb)[3 * k], (*map.rgb)[3 * k + 1], (*map.rgb)[3 * k + 2]);
    conditionalCdf_.assign(size_t(width_ + 1) * height_, 0.f);
    rowSum_.assign(size_t(height_), 0.f);
    marginalCdf_.assign(size_t(height_ + 1), 0.f);
    double total = 0.0;
    for (int j = 0; j < height_; ++j) {
        const double sinT = std::sin(M_PI * (j + 0.5) / height_);
        float* cdf = &conditionalCdf_[size_t(j) * (width_ + 1)];
        double row = 0.0;
        for (int i = 0; i < width_; ++i) {
            row += double(luminance(radiance_[size_t(j) * width_ + i])) * sinT;
            cdf[i + 1] = float(row);
        }
        for (int i = 1; i <= width_; ++i) cdf[i] = row > 0.0 ? float(cdf[i] / row) : float(i) / float(width_);
        rowSum_[size_t(j)] = float(row);
        total += row;
        marginalCdf_[size_t(j) + 1] = float(total);
    }
    if (!(total > 0.0)) return;  // a map of colours without luminance: nothing to sample
    for (int j = 1; j <= height_; ++j) marginalCdf_[size_t(j)] = float(marginalCdf_[size_t(j)] / total);
    total_ = float(total);
    active_ = true;
}

Vec2f EnvironmentLight::toMap(const Vec3f& d) const {
    // Undo the map's turn about +y: rotate the direction by −rotation.
    const Vec3f r(cosRot_ * d.x() - sinRot_ * d.z(), d.y(), sinRot_ * d.x() + cosRot_ * d.z());
    return latLongCoordinates(r);
}

Vec3f EnvironmentLight::fromMap(const Vec2f& uv) const {
    const Vec3f r = latLongDirection(uv.x(), uv.y());
    return Vec3f(cosRot_ * r.x() + sinRot_ * r.z(), r.y(), -sinRot_ * r.x() + cosRot_ * r.z());
}

float EnvironmentLight::pdfUv(int i, int j) const {
    const float sinT = std::sin(kPi * (float(j) + 0.5f) / float(height_));
    return luminance(radiance_[size_t(j) * width_ + i]) * sinT * float(width_) * float(height_) / total_;
}

Vec3f EnvironmentLight::radiance(const Vec3f& dir) const {
    if (!active_) return Vec3f::Zero();
    const Vec2f uv = toMap(dir);
    const int i = std::clamp(int(uv.x() * float(width_)), 0, width_ - 1);
    const int j = std::clamp(int(uv.y() * float(height_)), 0, height_ - 1);
    return radiance_[size_t(j) * width_ + i];
}

LightSample EnvironmentLight::sample(const Vec2f& u) const {
    LightSample s;
    if (!active_) return s;
    float fv, fu;
    const int j = findInterval(marginalCdf_.data(), height_, u.y(), &fv);
    const int i = findInterval(&conditionalCdf_[size_t(j) * (width_ + 1)], width_, u.x(), &fu);
    const Vec2f uv((float(i) + fu) / float(width_), (float(j) + fv) / float(height_));
    const float sinT = std::sin(kPi * uv.y());
    if (!(sinT > 0.f)) return s;
    s.wi = fromMap(uv).normalized();
    s.radiance = radiance_[size_t(j) * width_ + i];
    s.pdf = pdfUv(i, j) / (2.f * kPi * kPi * sinT);
    s.valid = s.pdf > 0.f;
    return s;
}

float EnvironmentLight::pdf(const Vec3f& dir) const {
    if (!active_) return 0.f;
    const Vec2f uv = toMap(dir);
    const float sinT = std::sin(kPi * uv.y());
    if (!(sinT > 0.f)) return 0.f;
    const int i = std::clamp(int(uv.x() * float(width_)), 0, width_ - 1);
    const int j = std::clamp(int(uv.y() * float(height_)), 0, height_ - 1);
    return pdfUv(i, j) / (2.f * kPi * kPi * sinT);
}

}  // namespace hp
