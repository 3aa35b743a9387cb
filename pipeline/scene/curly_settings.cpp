#include "pipeline/scene/curly_settings.h"

#include <algorithm>

namespace hp {

bool usesCurlyWetModel(const Scene& scene) { return scene.text("hair.model") == "curly-wet"; }

CurlyWetSettings curlyWetSettings(const Scene& scene) {
    auto f = [&](const char* key) { return float(scene.number(key)); };
    auto i = [&](const char* key) { return int(scene.integer(key)); };
    CurlyWetSettings s;
    s.particles = i("hair.curly.particles");
    s.length = f("hair.curly.length");
    s.curlRadius = f("hair.curly.radius");
    s.curlPitch = f("hair.curly.pitch");
    s.collisionRadius = f("hair.curly.collision_radius");
    s.rootRadius = f("hair.curly.root_radius");
    s.tipRadius = f("hair.curly.tip_radius");
    s.timeStep = f("hair.curly.time_step");
    s.substeps = i("hair.curly.substeps");
    s.iterations = i("hair.curly.iterations");
    // The wisp's material: the rod formulation's keys (pipeline/scene/sim_settings.cpp).
    s.material.youngs = f("hair.material.youngs_modulus");
    s.material.shear = f("hair.material.shear_modulus");
    s.material.density = f("hair.material.density");
    s.material.hairsPerGuide = f("hair.material.hairs_per_guide");
    s.material.radius = f("hair.radius.root");
    // Mass and springs the scene gives are the seed's model; the others
    // follow from the material (CurlyWetSettings::resolved).
    auto given = [&](const char* key) { return scene.given(key) ? f(key) : kFromMaterial; };
    s.massPerLength = given("hair.curly.mass_per_length");
    s.gravity = scene.vec3f("hair.curly.gravity");
    s.preload = scene.flag("hair.curly.preload");
    s.stretchStiffness = given("hair.curly.stretch_stiffness");
    s.stretchDamping = f("hair.curly.stretch_damping");
    s.bendStiffness = given("hair.curly.bend_stiffness");
    s.bendDamping = f("hair.curly.bend_damping");
    s.bendSmoothing = f("hair.curly.bend_smoothing");
    s.coreStiffness = given("hair.curly.core_stiffness");
    s.coreDamping = f("hair.curly.core_damping");
    s.coreSmoothing = f("hair.curly.core_smoothing");
    s.maxStrain = f("hair.curly.max_strain");
    s.maxRelativeVelocity = f("hair.curly.max_relative_velocity");
    s.friction = f("hair.curly.friction");
    s.teleportDistance = f("hair.curly.teleport_distance");
    s.teleportAngle = f("hair.curly.teleport_angle");
    s.strandsPerWorld = i("hair.curly.strands_per_world");

    s.wetEffects = scene.flag("hair.wet.enabled");
    s.saturation = sceneSaturation(scene, 0.0);
    s.saturationRoot = f("hair.wet.saturation_root");
    s.saturationTip = f("hair.wet.saturation_tip");
    s.helixRadius = f("hair.wet.helix_radius");
    s.helixPitch = f("hair.wet.helix_pitch");
    s.helixWeight = given("hair.wet.helix_weight");
    s.cohesion = scene.flag("hair.wet.cohesion");
    s.cohesionTightness = f("hair.wet.cohesion_tightness");
    s.cohesionRadius = f("hair.wet.cohesion_radius");
    s.cohesionStiffness = f("hair.wet.cohesion_stiffness");
    s.adhesion = scene.flag("hair.wet.adhesion");
    s.adhesionWeight = f("hair.wet.adhesion_weight");
    s.adhesionRadius = f("hair.wet.adhesion_radius");
    s.globalStiffness = f("hair.wet.global_stiffness");
    s.wetStiffness = f("hair.wet.wet_stiffness");
    s.dryStiffness = f("hair.wet.dry_stiffness");
    s.stiffnessStep = f("hair.wet.stiffness_step");

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
