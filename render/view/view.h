// Camera, lights and hair material shared by the GL preview and the Embree
// reference, so both render the same shot with the same parameters.
#pragma once

#include "sim/strands/strand.h"

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace hp {

using Vec4f = Eigen::Vector4f;
using Mat4f = Eigen::Matrix4f;

/// World-to-view matrix (OpenGL convention: looking down -Z, `up` roughly +Y
/// on screen) of an eye at `eye` looking at `target`; `up` must not be
/// parallel to the viewing direction.
Mat4f lookAt(const Vec3f& eye, const Vec3f& target, const Vec3f& up);

/// A pinhole perspective camera. Right-handed, Y up, looking down -Z in view space.
struct Camera {
    Vec3f position{0.f, 0.05f, 0.9f};
    Vec3f target{0.f, 0.f, 0.f};
    Vec3f up{0.f, 1.f, 0.f};
    float fovY = 40.f;  ///< vertical field of view, degrees
    int width = 1920;
    int height = 1080;
    float nearClip = 0.01f;
    float farClip = 100.f;

    float aspect() const { return float(width) / float(height); }
    /// World-to-view matrix (OpenGL convention).
    Mat4f view() const;
    /// View-to-clip matrix (OpenGL convention, depth in [-1, 1]).
    Mat4f projection() const;
    /// Unit direction of the ray through image position (x, y) in pixels,
    /// (0, 0) the top-left corner of the top-left pixel, y pointing down.
    Vec3f rayDirection(float x, float y) const;
};

/// Camera::rayDirection with the camera basis and field-of-view factors
/// computed once: renderers call it for millions of rays per frame.
class CameraRays {
  public:
    explicit CameraRays(const Camera& camera);
    /// Same as camera.rayDirection(x, y), bit for bit.
    Vec3f direction(float x, float y) const {
        const float ndcX = (2.f * x / width_ - 1.f) * tanHalf_ * aspect_;
        const float ndcY = (1.f - 2.f * y / height_) * tanHalf_;
        return (forward_ + ndcX * side_ + ndcY * up_).normalized();
    }

  private:
    Vec3f forward_, side_, up_;
    float tanHalf_, aspect_;
    float width_, height_;
};

enum class LightType { Directional, Point };

struct Light {
    LightType type = LightType::Directional;
    Vec3f direction{-1.f, -1.f, -1.f};  ///< directional: the way the light travels (normalised on use)
    Vec3f position{0.f, 1.f, 1.f};      ///< point lights
    Vec3f color{1.f, 1.f, 1.f};
    float intensity = 3.f;              ///< radiance scale (directional) or power/(4π) (point)
    /// Whether the light is blocked by hair and head. The preview shadows one
    /// light (PreviewShadowSettings::light); the rig's fill and rim lights are
    /// unshadowed in both renderers, so the two stay the same picture.
    bool castsShadows = true;
    /// Direction and position are given in the camera's frame (x right, y up,
    /// z toward the viewer; positions relative to the camera target), so a
    /// rig follows any camera. View::worldLights() resolves them.
    bool cameraRelative = false;

    /// Unit vector from `p` toward the light, and the light's radiance at `p`.
    Vec3f toLight(const Vec3f& p, Vec3f* radiance, float* distance) const;
};

/// Kajiya-Kay hair material. The preview's GLSL (shaders/) mirrors kajiyaKay().
struct HairMaterial {
    Vec3f color{0.35f, 0.22f, 0.12f};          ///< diffuse albedo (linear)
    Vec3f specularColor{1.f, 1.f, 1.f};
    float kd = 0.6f;                            ///< diffuse weight
    float ks = 0.3f;                            ///< specular weight
    float shininess = 80.f;                     ///< specular exponent alpha
    bool twoLobes = false;                      ///< Scheuermann's shifted-tangent two-lobe variant
    float primaryShift = 0.f;                   ///< tangent shift along the normal, lobe 1
    float secondaryShift = -0.1f;               ///< lobe 2
    float secondaryKs = 0.15f;
    float secondaryShininess = 20.f;
    Vec3f secondaryColor{0.6f, 0.45f, 0.3f};
    /// Fraction of light a shadow ray keeps at each strand it crosses (0..1):
    /// the one parameter of hair self-shadowing in both renderers. The
    /// reference multiplies it per traced crossing; the preview's voxel grid
    /// counts expected crossings C and uses exp(-(1 - T) C), the mean of T^n
    /// over the Poisson-distributed crossing counts n of thin fibres.
    float transmittance = 0.8f;
};

/// Opaque head material: a skin-like wrapped diffuse plus a faint specular
/// sheen (see skinShade()); wrap = specular = 0 is plain Lambert.
struct SurfaceMaterial {
    Vec3f color{0.75f, 0.6f, 0.5f};
    float ambient = 0.05f;
    /// Light wrapping past the terminator, (n·l + w) / (1 + w): the soft
    /// falloff light scattered under skin gives (0 = Lambert).
    float wrap = 0.f;
    float specular = 0.f;    ///< Blinn-Phong weight of the oily sheen (untinted)
    float shininess = 30.f;  ///< its exponent
};

/// Reflected radiance factor of the head material for unit normal n, light
/// direction l and view direction v, without the ambient term: albedo ·
/// max(0, (n·l + w)/(1 + w)) + specular · (n·h)^shininess · [n·l > 0].
/// Multiply by the light's radiance. shaders/head.frag mirrors it.
Vec3f skinShade(const SurfaceMaterial& m, const Vec3f& n, const Vec3f& l, const Vec3f& v);

/// Everything a renderer needs about the shot besides geometry.
struct View {
    Camera camera;
    std::vector<Light> lights{Light{}};
    Vec3f environment{0.f, 0.f, 0.f};  ///< constant environment radiance (black by default)
    HairMaterial hair;
    SurfaceMaterial head;

    /// The lights in world space: camera-relative ones turned by the camera.
    std::vector<Light> worldLights() const;
};

/// The default three-point rig (camera-relative, so it follows the camera):
/// a warm key from the upper left in front (the one shadowed light), a cool,
/// weak fill from the right and a rim light from behind and above. The
/// scene's default render.lights spells the same rig out.
std::vector<Light> threePointRig();

/// Reflected radiance factor of Kajiya-Kay for tangent `t`, normal `n` (the
/// shading normal used only to shift tangents), unit direction to the light
/// `l` and to the viewer `v`: kd * color * sin(t,l) + ks * spec * sin(t,h)^alpha
/// (seed 004), with h = normalize(l + v). Multiply by the light's radiance.
Vec3f kajiyaKay(const HairMaterial& m, const Vec3f& t, const Vec3f& n, const Vec3f& l, const Vec3f& v,
                Vec3f* diffuseOut = nullptr, Vec3f* specularOut = nullptr);

}  // namespace hp
