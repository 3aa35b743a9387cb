#include "pipeline/scene/curly_settings.h"
#include "pipeline/scene/key_fields.h"

#include <algorithm>

namespace hp {

bool usesCurlyWetModel(const Scene& scene) { return scene.text("hair.model") == "curly-wet"; }

CurlyWetSettings curlyWetSettings(const Scene& scene) {
    CurlyWetSettings s;
    readKeys(scene, s, {
        {"hair.curly.particles", &CurlyWetSettings::particles},
        {"hair.curly.length", &CurlyWetSettings::length},
        {"hair.curly.radius", &CurlyWetSettings::curlRadius},
        {"hair.curly.pitch", &CurlyWetSettings::curlPitch},
        {"hair.curly.collision_radius", &CurlyWetSettings::collisionRadius},
        {"hair.curly.root_radius", &CurlyWetSettings::rootRadius},
        {"hair.curly.tip_radius", &CurlyWetSettings::tipRadius},
        {"hair.curly.time_step", &CurlyWetSettings::timeStep},
        {"hair.curly.substeps", &CurlyWetSettings::substeps},
        {"hair.curly.iterations", &CurlyWetSettings::iterations},
        {"hair.curly.gravity", &CurlyWetSettings::gravity},
        {"hair.curly.preload", &CurlyWetSettings::preload},
        {"hair.curly.stretch_damping", &CurlyWetSettings::stretchDamping},
        {"hair.curly.bend_damping", &CurlyWetSettings::bendDamping},
        {"hair.curly.bend_smoothing", &CurlyWetSettings::bendSmoothing},
        {"hair.curly.core_damping", &CurlyWetSettings::coreDamping},
        {"hair.curly.core_smoothing", &CurlyWetSettings::coreSmoothing},
        {"hair.curly.max_strain", &CurlyWetSettings::maxStrain},
        {"hair.curly.max_relative_velocity", &CurlyWetSettings::maxRelativeVelocity},
        {"hair.curly.friction", &CurlyWetSettings::friction},
        {"hair.curly.teleport_distance", &CurlyWetSettings::teleportDistance},
        {"hair.curly.teleport_angle", &CurlyWetSettings::teleportAngle},
        {"hair.curly.strands_per_world", &CurlyWetSettings::strandsPerWorld},
        {"hair.wet.enabled", &CurlyWetSettings::wetEffects},
        {"hair.wet.saturation_root", &CurlyWetSettings::saturationRoot},
        {"hair.wet.saturation_tip", &CurlyWetSettings::saturationTip},
        {"hair.wet.helix_radius", &CurlyWetSettings::helixRadius},
        {"hair.wet.helix_pitch", &CurlyWetSettings::helixPitch},
        {"hair.wet.cohesion", &CurlyWetSettings::cohesion},
        {"hair.wet.cohesion_tightness", &CurlyWetSettings::cohesionTightness},
        {"hair.wet.cohesion_radius", &CurlyWetSettings::cohesionRadius},
        {"hair.wet.cohesion_stiffness", &CurlyWetSettings::cohesionStiffness},
        {"hair.wet.adhesion", &CurlyWetSettings::adhesion},
        {"hair.wet.adhesion_weight", &CurlyWetSettings::adhesionWeight},
        {"hair.wet.adhesion_radius", &CurlyWetSettings::adhesionRadius},
        {"hair.wet.global_stiffness", &CurlyWetSettings::globalStiffness},
        {"hair.wet.wet_stiffness", &CurlyWetSettings::wetStiffness},
        {"hair.wet.dry_stiffness", &CurlyWetSettings::dryStiffness},
        {"hair.wet.stiffness_step", &CurlyWetSettings::stiffnessStep},
    });
    s.saturation = sceneSaturation(scene, 0.0);
    // The wisp's material: the rod formulation's keys (pipeline/scene/sim_settings.cpp).
    readKeys(scene, s.material, {
        {"hair.material.youngs_modulus", &rod::Material::youngs},
        {"hair.material.shear_modulus", &rod::Material::shear},
        {"hair.material.density", &rod::Material::density},
        {"hair.material.hairs_per_guide", &rod::Material::hairsPerGuide},
        {"hair.radius.root", &rod::Material::radius},
    });
    // Mass and springs the scene gives are Kim 2023's model; the others
    // follow from the material (CurlyWetSettings::resolved).
    auto given = [&](const char* key) { return scene.given(key) ? float(scene.number(key)) : kFromMaterial; };
    s.massPerLength = given("hair.curly.mass_per_length");
    s.stretchStiffness = given("hair.curly.stretch_stiffness");
    s.bendStiffness = given("hair.curly.bend_stiffness");
    s.coreStiffness = given("hair.curly.core_stiffness");
    s.helixWeight = given("hair.wet.helix_weight");

    if (s.adhesion && s.adhesionRadius <= 2.f * s.collisionRadius)
        scene.fail("hair.wet.adhesion_radius",
                   cat("the adhesion shell (h/2, h] = (", 0.5 * s.adhesionRadius, ", ", s.adhesionRadius,
                       "] m lies within the collision clearance hair.curly.collision_radius = ", s.collisionRadius,
                       " m, so wet hair could never be held; use an adhesion radius above ",
                       2.0 * s.collisionRadius, " m"));
    const bool fromMaterial = s.massPerLength < 0.f || s.bendStiffness < 0.f || s.coreStiffness < 0.f;
    if (fromMaterial && !(s.material.radius > 0.f))
        scene.fail("hair.radius.root", "the curly model takes its fibre radius from hair.radius.root, which must be > 0 "
                                       "unless hair.curly.mass_per_length, bend_stiffness and core_stiffness are all given");
    if (fromMaterial && !(s.material.youngs > 0.f && s.material.shear > 0.f))
        scene.fail(s.material.youngs > 0.f ? "hair.material.shear_modulus" : "hair.material.youngs_modulus",
                   "the curly model's springs follow from E and G, which must be > 0 unless "
                   "hair.curly.bend_stiffness and core_stiffness are given");
    if (s.curlRadius > 0.f && s.curlPitch <= 0.f)
        scene.fail("hair.curly.pitch", "a curl with a radius needs a positive pitch (advance per turn)");
    return s;
}

float sceneSaturation(const Scene& scene, double time) {
    const double fps = scene.number("fps");
    return float(std::clamp(scene.curve("hair.wet.saturation").eval(time * fps), 0.0, 1.0));
}

}  // namespace hp
