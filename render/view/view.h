// Camera, lights and hair material shared by the GL preview and the Embree
// reference, so both render the same shot with the same parameters.
#pragma once

#include "sim/strands/strand.h"

#include <Eigen/Geometry>

#include <array>
#include <memory>
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

/// Directional: a distant light (the sun), a delta direction or, with an
/// angle, a cone of directions. Point: a delta point. Quad and disk: one-sided
/// area lights at `position`, emitting toward `direction`.
enum class LightType { Directional, Point, Quad, Disk };

struct Light {
    LightType type = LightType::Directional;
    Vec3f direction{-1.f, -1.f, -1.f};  ///< directional: the way the light travels; quad/disk: the way it faces (normalised on use)
    Vec3f position{0.f, 1.f, 1.f};      ///< point lights and the centre of quad/disk lights
    Vec3f color{1.f, 1.f, 1.f};
    /// What `intensity` means, chosen so that a light's size never changes
    /// how bright it is:
    /// - directional: irradiance on a surface facing it (delta or with angle:
    ///   a cone of half-angle α has radiance intensity / (π sin²α));
    /// - point: radiant intensity (irradiance intensity / r² at distance r);
    /// - quad/disk: radiant intensity along the normal (radiance = intensity /
    ///   area, a Lambertian emitter: far away it is a point light of the same
    ///   intensity in front of it, times the cosine off its normal).
    float intensity = 3.f;
    float angle = 0.f;            ///< directional: angular diameter in degrees (0 = a delta direction)
    Vec2f size{0.1f, 0.1f};       ///< quad: width × height (m); disk: diameter = size.x()
    /// Quad: the edge of height size.y() lies in the plane of `up` and the
    /// normal (its width is horizontal for up = +y).
    Vec3f up{0.f, 1.f, 0.f};
    /// Whether the light is blocked by hair and head in the preview and the
    /// Kajiya-Kay reference. The preview shadows the first
    /// PreviewShadowSettings::maxLights (at most 4) such lights, each with its
    /// own voxel grid and head shadow map; limitShadowedLights() clears the
    /// flag of the lights past that cap, so the Kajiya-Kay reference shadows
    /// exactly the lights the preview does. The default rig shadows all three
    /// of its lights. The physical reference shadows every light unless
    /// ReferenceSettings::unshadowedLights says otherwise.
    bool castsShadows = true;
    /// Direction, up and position are given in the camera's frame (x right, y
    /// up, z toward the viewer; positions relative to the camera target), so a
    /// rig follows any camera. View::worldLights() resolves them.
    bool cameraRelative = false;

    bool isDelta() const { return type == LightType::Point || (type == LightType::Directional && !(angle > 0.f)); }
    /// Unit vector from `p` toward the light, and the light's radiance at `p`
    /// (irradiance factor: multiply by a BRDF × cosine). Lights with size are
    /// approximated the way the preview draws them: a directional light with
    /// an angle as its delta direction, quad and disk as a point light of the
    /// same intensity at their centre (the physical reference samples their
    /// true shape, render/reference/light_sampling.h).
    Vec3f toLight(const Vec3f& p, Vec3f* radiance, float* distance) const;
};

/// An HDR lat-long environment image (equirectangular: column u is the
/// azimuth φ = 2π u − π, φ = 0 looking down −z and φ = π/2 toward +x; row v
/// the polar angle θ = π v from +y at the top row), scaled and turned about
/// +y. Read by loadEnvironmentMap (render/reference/environment_light.h).
struct EnvironmentMap {
    std::string path;                                 ///< the file, for messages
    int width = 0, height = 0;
    std::shared_ptr<const std::vector<float>> rgb;    ///< width × height × 3 linear radiance, top row first
    float intensity = 1.f;
    float rotationDegrees = 0.f;                      ///< about +y: the map turns by this angle (right-handed)
    Vec3f mean = Vec3f::Zero();                       ///< intensity × the solid-angle mean radiance

    bool empty() const { return !rgb || width <= 0 || height <= 0; }
};

/// How hair is shaded: Kajiya-Kay's hand-set terms, or the same family with
/// every term fitted to the physical fibre (render/reference/hair_fit.h).
enum class HairShading { KajiyaKay, Fitted };

/// Nodes of a fitted lobe's strength table over |θo|: 0°, 11.25°, ..., 90°.
inline constexpr int kHairLobeNodes = 9;

/// One fitted lobe of the Kajiya-Kay family (render/reference/hair_fit.h):
///   k(|θo|) cos(θi + θo − shift)^exponent / √(cos θi cos θo) · N(φ),
/// Kajiya & Kay 1989's specular cone, moved along the fibre by a shift angle
/// as Scheuermann 2004 moves it with a shifted tangent; 1/√(cos θi cos θo) is
/// the large-argument form of d'Eon et al. 2011's longitudinal lobe (whose
/// Bessel I0(x) ≈ e^x/√(2πx)) and k(|θo|) the lobe's attenuation (Fresnel,
/// absorption along the refracted path), which depends on θo alone in Chiang
/// et al. 2016, tabulated at kHairLobeNodes angles and interpolated linearly.
/// N(|φ|; |θo|) is a table too, each row (one |θo|) normalised to ∫ N dφ = 1
/// over (−π, π]: the lobe's azimuthal distribution as the fit measures it at
/// that θo (a smooth fibre's reflection is |cos(φ/2)|/4; its transmission
/// peaks at φ = π and spreads toward the sides as the refracted path
/// steepens with |θo|, Chiang et al. 2016's γt(θo)), as real-time hair
/// shading tabulates Marschner's N(φ, θd) (Nguyen and Donnelly 2005, "Hair
/// Animation and Rendering in the Nalu Demo", GPU Gems 2). θ are angles to
/// the fibre's normal plane (sin θ = t·w), φ the azimuth between light and
/// view around the fibre (0: back toward the light).
struct HairLobe {
    std::array<Vec3f, kHairLobeNodes> strength{};  ///< k (1/sr) at |θo| = 90° i / (nodes − 1)
    /// N (1/rad): [a][b] at |θo| = 90° a / (nodes − 1), |φ| = 180° b / (nodes − 1).
    std::array<std::array<float, kHairLobeNodes>, kHairLobeNodes> azimuth{};
    float exponent = 1.f;
    float shift = 0.f;               ///< radians, peak at θi + θo = shift

    bool empty() const;
    /// k at |θo| = `absThetaO` (radians), linear between the nodes.
    Vec3f strengthAt(float absThetaO) const;
    void setStrength(const Vec3f& k) { strength.fill(k); }
    /// N at |θo| = `absThetaO`, |φ| = `absPhi` (radians), bilinear between the nodes.
    float azimuthAt(float absThetaO, float absPhi) const;
    /// Every row N ∝ ((1 + sign cos φ)/2)^m (sign +1: back toward the light),
    /// sampled at the nodes and scaled so that the piecewise-linear row integrates to 1.
    void setAzimuthPower(float m, float sign);
};

/// Zinke, Yuksel, Weber and Keyser 2008's dual-scattering constants of a
/// fibre (render/reference/hair_fit.h derives them from the physical BSDF),
/// averaged over the longitudinal angle. Behind n fibre crossings toward a
/// light (Poisson with mean C) a point receives the light straight with
/// probability exp(−C), and forward-scattered, T_f = E[a_f^n] = exp(−(1 − a_f) C)
/// less that, spread along the fibre by n β_f² and turned about it by n s_φ²;
/// the fibres around it add the light they scatter back (the `back` lobe).
struct HairDualScattering {
    Vec3f forward = Vec3f::Ones();  ///< a_f: fraction of light one fibre scatters forward
    float forwardVariance = 0.f;    ///< β_f² (rad²): longitudinal spread per fibre crossed
    /// s_φ² (rad²): variance of the azimuthal turn π − |φ| of light one fibre
    /// scatters forward; n crossings turn it by variance n s_φ²
    float forwardAzimuthVariance = 0.f;
    HairLobe back;                  ///< d_b f_back: local multiple back-scattering, a lobe of the same family
};

/// Kajiya-Kay hair material. The preview's GLSL (shaders/) mirrors kajiyaKay().
struct HairMaterial {
    /// KajiyaKay: the terms below as set. Fitted: diffuse kd·color·cos θi
    /// plus the lobes r, trt, tt (hair_fit.h); kd = 1, color the fitted
    /// diffuse colour; the plain specular fields are unused.
    HairShading shading = HairShading::KajiyaKay;
    HairLobe r, trt, tt;  ///< fitted: reflection (white), TRT (coloured), transmission (back light)
    HairDualScattering dual;
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
    /// Light wrapping past the terminator, max(0, n·l + w), normalised: the
    /// soft falloff light scattered under skin gives (0 = Lambert).
    float wrap = 0.f;
    float specular = 0.f;    ///< share ks of the normalised Blinn-Phong sheen (untinted); the diffuse keeps 1 − ks
    float shininess = 30.f;  ///< its exponent
};

/// The head material's BRDF times the cosine, f(l, v)·cos, for unit normal n,
/// light direction l and view direction v, without the ambient term; multiply
/// by the light's irradiance (delta light) or radiance (over a solid angle).
/// Energy-conserving, so a path tracer can use it as it is:
///   (1 − ks) · albedo · max(0, n·l + w) / (π (1 + w)²)         wrapped Lambert
///   + ks · N(s) · (n·h)^s · max(0, n·l)                        normalised Blinn-Phong
///   N(s) = (s + 2)(s + 4) / (8π (2^(−s/2) + s))
/// with w the wrap, ks the specular weight, s the shininess, h = (l + v)/|l + v|.
/// The wrapped Lambert integrates to albedo over the directions n·l > −w
/// (∫ (c + w) dω = π (1 + w)²); N(s) makes the sheen reflect exactly 1 seen
/// head on and less at other angles (Giesen 2009, "Derivation of Phong and
/// Blinn-Phong BRDF normalization factors"; the popular (s + 8)/(8π) of
/// Akenine-Möller, Haines and Hoffman, "Real-Time Rendering", 3rd ed. 2008,
/// approximates it from above, by up to 5%), so the reflected fraction never
/// exceeds (1 − ks)·albedo + ks ≤ 1.
/// shaders/head.frag mirrors it.
Vec3f skinShade(const SurfaceMaterial& m, const Vec3f& n, const Vec3f& l, const Vec3f& v);

/// Everything a renderer needs about the shot besides geometry.
struct View {
    Camera camera;
    std::vector<Light> lights{Light{}};
    Vec3f environment{0.f, 0.f, 0.f};  ///< constant environment radiance (black by default)
    EnvironmentMap environmentMap;     ///< added to `environment` where it has an image
    HairMaterial hair;
    SurfaceMaterial head;

    /// The lights in world space: camera-relative ones turned by the camera.
    std::vector<Light> worldLights() const;
    /// The environment as one constant: the colour plus the map's mean (what
    /// the preview and the Kajiya-Kay reference use).
    Vec3f meanEnvironment() const { return environment + environmentMap.mean; }
};

/// The default three-point rig (camera-relative, so it follows the camera):
/// a warm key from the upper left in front, a cool, weak fill from the right
/// and a rim light from behind and above, all three shadowed. The scene's
/// default render.lights spells the same rig out.
std::vector<Light> threePointRig();

/// Keeps castsShadows on the first `maxLights` lights that have it and
/// clears it on the rest (the preview's cap, PreviewShadowSettings::maxLights);
/// returns the indices of the lights it cleared.
std::vector<int> limitShadowedLights(std::vector<Light>& lights, int maxLights);

/// Reflected radiance factor of Kajiya-Kay for tangent `t`, normal `n` (the
/// shading normal used only to shift tangents), unit direction to the light
/// `l` and to the viewer `v`: kd * color * sin(t,l) + ks * spec * sin(t,h)^alpha
/// (Kajiya & Kay 1989, with Scheuermann 2004's half vector h = normalize(l + v)).
/// Multiply by the light's radiance. HairShading::Fitted: kd * color * sin(t,l)
/// plus the fitted lobes (hairLobe), in the physical BSDF's units, so it
/// approximates HairBsdf::eval averaged over the fibre's width (no π factor);
/// `specularOut` then receives the lobes.
Vec3f kajiyaKay(const HairMaterial& m, const Vec3f& t, const Vec3f& n, const Vec3f& l, const Vec3f& v,
                Vec3f* diffuseOut = nullptr, Vec3f* specularOut = nullptr);

/// One fitted lobe (HairLobe) for unit tangent t and unit directions l, v;
/// `extraVariance` (rad²) widens the cone as light spread by the fibres it
/// crossed (Zinke 2008: variances add; the strength is rescaled so the lobe
/// keeps its integral, cos^n x ≈ exp(−n x²/2) having the integral √(2π/n)).
Vec3f hairLobe(const HairLobe& lobe, const Vec3f& t, const Vec3f& l, const Vec3f& v, float extraVariance = 0.f);

}  // namespace hp
