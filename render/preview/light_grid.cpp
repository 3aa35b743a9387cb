#include "render/preview/light_grid.h"

#include <algorithm>
#include <cmath>

namespace hp {

namespace {

/// The light's view of the grid; any up vector not parallel to the beam
/// will do, the grid's roll does not matter.
Mat4f lightView(const Vec3f& eye, const Vec3f& target) {
    const Vec3f f = (target - eye).normalized();
    return lookAt(eye, target, std::abs(f.y()) < 0.9f ? Vec3f::UnitY() : Vec3f::UnitX());
}

}  // namespace

LightGrid LightGrid::fit(const Light& light, const Eigen::AlignedBox3f& bounds, float margin) {
    LightGrid g;
    if (bounds.isEmpty()) return g;
    const Vec3f centre = bounds.center();
    const float radius = std::max(0.5f * bounds.diagonal().norm(), 1e-4f);
    if (light.type == LightType::Directional) {
        const Vec3f dir = light.direction.normalized();
        g.view = lightView(centre - 2.f * radius * dir, centre);
    } else {
        if ((centre - light.position).norm() <= radius * 1.001f) return g;  // inside: no single frustum sees it all
        g.perspective = true;
        g.view = lightView(light.position, centre);
    }
    Vec2f qMin(1e30f, 1e30f), qMax(-1e30f, -1e30f);
    float dMin = 1e30f, dMax = -1e30f;
    for (int i = 0; i < 8; ++i) {
        const Vec3f corner = bounds.corner(Eigen::AlignedBox3f::CornerType(i));
        const Vec4f v = g.view * corner.homogeneous();
        const float depth = -v.z();
        const Vec2f q = g.perspective ? Vec2f(v.x() / depth, v.y() / depth) : Vec2f(v.x(), v.y());
        qMin = qMin.cwiseMin(q);
        qMax = qMax.cwiseMax(q);
        dMin = std::min(dMin, depth);
        dMax = std::max(dMax, depth);
    }
    const Vec2f pad = (qMax - qMin).cwiseMax(Vec2f(1e-6f, 1e-6f)) * margin;
    qMin -= pad;
    qMax += pad;
    const float dPad = std::max(dMax - dMin, 1e-6f) * margin;
    g.nearDepth = dMin - dPad;
    g.farDepth = dMax + dPad;
    if (g.perspective) g.nearDepth = std::max(g.nearDepth, 1e-4f);
    g.scale = (qMax - qMin).cwiseInverse();
    g.offset = -qMin.cwiseProduct(g.scale);
    g.valid = true;
    return g;
}

Vec3f LightGrid::toGrid(const Vec3f& world) const {
    const Vec4f v = view * world.homogeneous();
    const float depth = -v.z();
    const Vec2f q = perspective ? Vec2f(v.x() / depth, v.y() / depth) : Vec2f(v.x(), v.y());
    const Vec2f uv = q.cwiseProduct(scale) + offset;
    return Vec3f(uv.x(), uv.y(), (depth - nearDepth) / (farDepth - nearDepth));
}

Mat4f LightGrid::clip() const {
    const float n = nearDepth, f = farDepth;
    Mat4f p = Mat4f::Zero();
    if (perspective) {
        // x_clip = (2u - 1) * depth with u = (x / depth) * sx + ox and depth = -z.
        p(0, 0) = 2.f * scale.x();
        p(0, 2) = -(2.f * offset.x() - 1.f);
        p(1, 1) = 2.f * scale.y();
        p(1, 2) = -(2.f * offset.y() - 1.f);
        p(2, 2) = (f + n) / (n - f);
        p(2, 3) = 2.f * f * n / (n - f);
        p(3, 2) = -1.f;
    } else {
        p(0, 0) = 2.f * scale.x();
        p(0, 3) = 2.f * offset.x() - 1.f;
        p(1, 1) = 2.f * scale.y();
        p(1, 3) = 2.f * offset.y() - 1.f;
        p(2, 2) = -2.f / (f - n);
        p(2, 3) = -2.f * n / (f - n) - 1.f;
        p(3, 3) = 1.f;
    }
    return p * view;
}

std::vector<ShadowSlot> fitShadowSlots(const std::vector<Light>& lights, int maxLights,
                                       const Eigen::AlignedBox3f& bounds, std::vector<int>* unfitted) {
    std::vector<ShadowSlot> slots;
    int considered = 0;
    for (size_t i = 0; i < lights.size() && considered < maxLights; ++i) {
        if (!lights[i].castsShadows) continue;
        ++considered;
        ShadowSlot slot{int(i), LightGrid::fit(lights[i], bounds)};
        if (slot.grid.valid) slots.push_back(slot);
        else if (unfitted) unfitted->push_back(int(i));
    }
    return slots;
}

}  // namespace hp
