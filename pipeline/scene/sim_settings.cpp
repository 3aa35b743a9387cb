#include "pipeline/scene/sim_settings.h"
#include "pipeline/scene/key_fields.h"

#include "core/errors.h"

namespace hp {

GuideSettings guideSettings(const Scene& scene) {
    GuideSettings s;
    s.formulation = parseFormulation(scene.text("simulation.formulation"));
    s.rodIntegrator = parseRodIntegrator(scene.text("simulation.rod_integrator"));
    readKeys(scene, s, {
        {"hair.guides.segments", &GuideSettings::segments},
        {"hair.guides.length", &GuideSettings::length},
        {"hair.guides.collision_radius", &GuideSettings::collisionRadius},
        {"hair.radius.root", &GuideSettings::rootRadius},
        {"hair.radius.tip", &GuideSettings::tipRadius},
        {"simulation.time_step", &GuideSettings::timeStep},
        {"simulation.substeps", &GuideSettings::substeps},
        {"simulation.iterations", &GuideSettings::iterations},
        {"simulation.friction", &GuideSettings::friction},
        {"simulation.damping", &GuideSettings::damping},
        {"simulation.gravity", &GuideSettings::gravity},
        {"simulation.mass_per_length", &GuideSettings::massPerLength},
        {"simulation.bend_stiffness", &GuideSettings::bendStiffness},
        {"simulation.bend_damping", &GuideSettings::bendDamping},
        {"hair.material.youngs_modulus", &GuideSettings::youngsModulus},
        {"hair.material.density", &GuideSettings::density},
        {"hair.material.hairs_per_guide", &GuideSettings::hairsPerGuide},
        {"simulation.rod_substeps", &GuideSettings::rodSubsteps},
        {"hair.material.tapered", &GuideSettings::taperedFibre},
        {"simulation.preload_probes", &GuideSettings::preloadProbes},
        {"simulation.preload", &GuideSettings::preload},
        {"simulation.preload_contact", &GuideSettings::preloadContact},
        {"simulation.preload_reach", &GuideSettings::preloadReach},
        {"simulation.preload_limit", &GuideSettings::preloadLimit},
        {"simulation.head_collision", &GuideSettings::headCollision},
        {"simulation.strand_collision", &GuideSettings::strandCollision},
        {"simulation.strands_per_world", &GuideSettings::strandsPerWorld},
        {"simulation.limits.bend", &GuideSettings::bendLimit},
        {"simulation.limits.twist", &GuideSettings::twistLimit},
        {"simulation.limits.stiffness", &GuideSettings::limitStiffness},
        {"simulation.limits.projection_angle", &GuideSettings::projectionAngle},
        {"simulation.limits.projection_distance", &GuideSettings::projectionDistance},
        {"simulation.cut_distance", &GuideSettings::teleportDistance},
        {"simulation.cut_angle", &GuideSettings::teleportAngle},
        {"simulation.max_speed", &GuideSettings::maxSpeed},
    });

    readKeys(scene, s.volume, {
        {"simulation.volume.enabled", &VolumeSettings::enabled},
        {"simulation.volume.cell_size", &VolumeSettings::cellSize},
        {"simulation.volume.target_density", &VolumeSettings::targetDensity},
        {"simulation.volume.friction", &VolumeSettings::friction},
        {"simulation.volume.relax_time", &VolumeSettings::relaxTime},
        {"simulation.volume.contact_scale", &VolumeSettings::contactScale},
    });

    const float segment = s.length / float(s.segments);
    if (2.f * s.collisionRadius >= segment)
        scene.fail("hair.guides.collision_radius",
                   cat("a collision radius of ", s.collisionRadius, " m does not fit segments of ", segment,
                       " m (hair.guides.length / hair.guides.segments); it must be below half a segment"));
    if (s.tipRadius > s.rootRadius)
        scene.fail("hair.radius.tip", cat("the tip radius ", s.tipRadius, " m is larger than the root radius ",
                                          s.rootRadius, " m"));
    if (s.formulation == GuideFormulation::Rod && !(s.rootRadius > 0.f))
        scene.fail("hair.radius.root", "the rod formulation takes its fibre radius from hair.radius.root, which must be > 0");
    s.validate();  // the ranges above already hold; this catches what a future key adds
    return s;
}

}  // namespace hp
