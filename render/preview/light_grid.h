// A shadowed light's view of the scene: one mapping from world space to a
// unit cube used by both the voxel grid (Dehlin and Styngberg's self-shadowing) and the
// shadow map, and which lights get one (fitShadowSlots). Plain CPU code, so tests can voxelize on the CPU with exactly
// the mapping the GPU used.
#pragma once

#include "render/view/view.h"

#include <Eigen/Geometry>

#include <vector>

namespace hp {

/// Light space fitted around the scene. Grid coordinates (u, v, w) in [0,1]^3
/// cover the scene: u, v across the light's beam, w the depth along the
/// light, linear in distance. A directional light gets an orthographic box;
/// a point light a perspective frustum from its position, in which every
/// light ray has constant (u, v), so a sum along w is a sum along the ray.
struct LightGrid {
    bool valid = false;         ///< false when the light cannot see the scene from outside (point light inside it)
    bool perspective = false;   ///< point light
    Mat4f view = Mat4f::Identity();  ///< world -> light view; the light looks down -Z
    Vec2f scale{1.f, 1.f};      ///< (u, v) = q * scale + offset, q = view xy (orthographic) or xy / depth
    Vec2f offset{0.f, 0.f};
    float nearDepth = 0.f;      ///< depth (-view z) at w = 0
    float farDepth = 1.f;       ///< depth at w = 1

    /// Fits `light` around `bounds`, padded by `margin` of the extent on each side.
    static LightGrid fit(const Light& light, const Eigen::AlignedBox3f& bounds, float margin = 0.02f);

    /// Grid coordinates of a world point (inside [0,1]^3 for points within the bounds).
    Vec3f toGrid(const Vec3f& world) const;
    /// Clip matrix for rasterizing from the light: NDC x, y = 2u-1, 2v-1;
    /// depth increasing with w (linear for directional lights).
    Mat4f clip() const;
};

/// A light the preview shadows and its grid.
struct ShadowSlot {
    int light = -1;  ///< index into the lights
    LightGrid grid;
};

/// The preview's shadowed lights: those with Light::castsShadows, in order,
/// at most `maxLights` (limitShadowedLights in render/view/view.h is the same
/// rule), each fitted around `bounds`. A light whose grid cannot be fitted (a
/// point light inside the bounds) gets no slot and is listed in `unfitted`.
std::vector<ShadowSlot> fitShadowSlots(const std::vector<Light>& lights, int maxLights,
                                       const Eigen::AlignedBox3f& bounds, std::vector<int>* unfitted = nullptr);

}  // namespace hp
