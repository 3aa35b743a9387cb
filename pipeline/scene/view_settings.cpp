#include "pipeline/scene/view_settings.h"
#include "pipeline/scene/key_fields.h"

#include "core/errors.h"
#include "core/log.h"
#include "render/reference/environment_light.h"
#include "render/reference/hair_bsdf.h"
#include "render/reference/hair_fit.h"

#include <algorithm>

namespace hp {

View makeView(const Scene& s) {
    View v;
    Camera& c = v.camera;
    readKeys(s, c, {
        {"render.camera.position", &Camera::position},
        {"render.camera.target", &Camera::target},
        {"render.camera.up", &Camera::up},
        {"render.camera.fov", &Camera::fovY},
        {"render.camera.width", &Camera::width},
        {"render.camera.height", &Camera::height},
        {"render.camera.near", &Camera::nearClip},
        {"render.camera.far", &Camera::farClip},
    });
    if ((c.target - c.position).norm() < 1e-6f) s.fail("render.camera.target", "must differ from the camera position");
    if ((c.target - c.position).normalized().cross(c.up).norm() < 1e-4f)
        s.fail("render.camera.up", "must not be parallel to the viewing direction");
    if (c.farClip <= c.nearClip) s.fail("render.camera.far", "must be greater than render.camera.near");

    v.lights.clear();
    for (size_t i = 0; i < s.count("render.lights"); ++i) {
        const std::string k = cat("render.lights[", i, "].");
        Light l;
        const std::string& type = s.text(k + "type");
        l.type = type == "point" ? LightType::Point
                 : type == "quad" ? LightType::Quad
                 : type == "disk" ? LightType::Disk
                                  : LightType::Directional;
        l.direction = s.vec3f(k + "direction");
        l.position = s.vec3f(k + "position");
        l.angle = float(s.number(k + "angle"));
        l.size = Vec2f(float(s.number(k + "width")), float(s.number(k + "height")));
        l.up = s.vec3f(k + "up");
        l.color = s.vec3f(k + "color");
        l.intensity = float(s.number(k + "intensity"));
        l.castsShadows = s.flag(k + "shadows");
        l.cameraRelative = s.text(k + "space") == "camera";
        if (l.type != LightType::Point && l.direction.norm() < 1e-6f)
            s.fail(k + "direction", cat("a ", type, " light needs a non-zero direction"));
        v.lights.push_back(l);
    }
    // The preview shadows at most preview.shadow.max_lights lights; the
    // Kajiya-Kay reference, the preview's diagnostic twin, shadows the same.
    for (int i : limitShadowedLights(v.lights, int(s.integer("preview.shadow.max_lights"))))
        logWarning(s.where(cat("render.lights[", i, "].shadows")).str(), ": render.lights[", i,
                   "] is unshadowed in the preview and the Kajiya-Kay reference: preview.shadow.max_lights is ",
                   s.integer("preview.shadow.max_lights"));
    v.environment = s.vec3f("render.environment");
    const std::filesystem::path map = s.file("render.environment_map");
    if (!map.empty()) {
        try {
            v.environmentMap = loadEnvironmentMap(map.string(), float(s.number("render.environment_intensity")),
                                                  float(s.number("render.environment_rotation")));
        } catch (const Error& e) {
            s.fail("render.environment_map", e.what());
        }
    }

    HairMaterial& h = v.hair;
    h.color = s.number("render.hair.melanin") >= 0 ? hairColorFromAbsorption(hairAbsorption(s), hairRoughness(s))
                                                    : s.vec3f("render.hair.color");
    readKeys(s, h, {
        {"render.hair.specular_color", &HairMaterial::specularColor},
        {"render.hair.kd", &HairMaterial::kd},
        {"render.hair.ks", &HairMaterial::ks},
        {"render.hair.shininess", &HairMaterial::shininess},
        {"render.hair.two_lobes", &HairMaterial::twoLobes},
        {"render.hair.primary_shift", &HairMaterial::primaryShift},
        {"render.hair.secondary_shift", &HairMaterial::secondaryShift},
        {"render.hair.secondary_ks", &HairMaterial::secondaryKs},
        {"render.hair.secondary_shininess", &HairMaterial::secondaryShininess},
        {"render.hair.secondary_color", &HairMaterial::secondaryColor},
        {"render.hair.transmittance", &HairMaterial::transmittance},
    });
    // Fitted: the diffuse colour, lobes and dual scattering from the
    // physical fibre (render/reference/hair_fit.h); the plain Kajiya-Kay
    // keys above then only matter in mode kajiya-kay.
    if (s.text("render.hair.shading") == "fitted") {
        fitHairMaterial(hairFiber(s), &h);
        // A shadow ray through a fibre keeps what the fibre scatters forward
        // (Zinke 2008's a_f): the Kajiya-Kay reference's grey per-crossing
        // transmittance, the preview's per channel.
        h.transmittance = std::clamp(h.dual.forward.dot(Vec3f(0.2126f, 0.7152f, 0.0722f)), 0.f, 1.f);
    }

    readKeys(s, v.head, {
        {"render.head.color", &SurfaceMaterial::color},
        {"render.head.ambient", &SurfaceMaterial::ambient},
        {"render.head.wrap", &SurfaceMaterial::wrap},
        {"render.head.specular", &SurfaceMaterial::specular},
        {"render.head.shininess", &SurfaceMaterial::shininess},
    });
    return v;
}

HairFiberParams hairFiber(const Scene& s) {
    HairFiberParams f;
    f.longitudinalRoughness = float(s.number("reference.physical.roughness"));
    f.azimuthalRoughness = float(s.number("reference.physical.azimuthal_roughness"));
    f.cuticleTiltDegrees = float(s.number("reference.physical.cuticle_tilt"));
    f.ior = float(s.number("reference.physical.ior"));
    f.sigmaA = hairAbsorption(s);
    return f;
}

float hairRoughness(const Scene& s) { return float(s.number("reference.physical.azimuthal_roughness")); }

Vec3f hairAbsorption(const Scene& s) {
    if (s.number("render.hair.melanin") >= 0) {
        // render.hair.melanin is set by default (the default shot's blond):
        // the other descriptions of the fibre would be silently ignored.
        for (const char* key : {"reference.physical.melanin", "reference.physical.pheomelanin"})
            if (s.given(key))
                s.fail(key, "is not used while render.hair.melanin is set (0.3 by default), which sets the fibre of "
                            "both renderers: set render.hair.melanin instead, or render.hair.melanin: -1");
        if (s.flag("reference.physical.use_hair_color"))
            s.fail("reference.physical.use_hair_color",
                   "needs render.hair.melanin: -1 (it is 0.3 by default, and sets the fibre itself)");
        return hairAbsorptionFromMelanin(float(s.number("render.hair.melanin")),
                                         float(s.number("render.hair.pheomelanin")));
    }
    if (s.flag("reference.physical.use_hair_color"))
        return hairAbsorptionFromColor(s.vec3f("render.hair.color"), hairRoughness(s));
    return hairAbsorptionFromMelanin(float(s.number("reference.physical.melanin")),
                                     float(s.number("reference.physical.pheomelanin")));
}

DisplaySettings makeDisplaySettings(const Scene& s) {
    DisplaySettings d;
    d.ocioConfig = s.file("render.ocio.config").string();
    d.inputSpace = s.text("render.ocio.colorspace");
    d.display = s.text("render.ocio.display");
    d.view = s.text("render.ocio.view");
    d.exposure = float(s.number("render.exposure"));
    const std::string& type = s.text("render.background.type");
    d.backdrop.kind = type == "color"      ? Backdrop::Kind::Color
                      : type == "gradient" ? Backdrop::Kind::Gradient
                                           : Backdrop::Kind::None;
    d.backdrop.top = s.vec3f("render.background.color");
    d.backdrop.bottom = s.vec3f("render.background.bottom");
    try {
        checkDisplaySettings(d);
    } catch (const SceneError&) {
        throw;
    } catch (const Error& e) {
        s.fail(d.ocioConfig.empty() ? "render.ocio.view" : "render.ocio.config", e.what());
    }
    return d;
}

}  // namespace hp
