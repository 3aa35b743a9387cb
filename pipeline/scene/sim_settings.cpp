#include "pipeline/scene/sim_settings.h"

#include "core/errors.h"

namespace hp {

GuideSettings guideSettings(const Scene& scene) {
    GuideSettings s;
    s.formulation = parseFormulation(scene.text("simulation.formulation"));
    s.segments = int(scene.integer("hair.guides.segments"));
    s.length = float(scene.number("hair.guides.length"));
    s.collisionRadius = float(scene.number("hair.guides.collision_radius"));
    s.rootRadius = float(scene.number("hair.radius.root"));
    s.tipRadius = float(scene.number("hair.radius.tip"));
    s.timeStep = float(scene.number("simulation.time_step"));
    s.substeps = int(scene.integer("simulation.substeps"));
    s.iterations = int(scene.integer("simulation.iterations"));
    s.friction = float(scene.number("simulation.friction"));
    s.damping = float(scene.number("simulation.damping"));
    s.gravity = scene.vec3f("simulation.gravity");
    s.massPerLength = float(scene.number("simulation.mass_per_length"));
    s.bendStiffness = float(scene.number("simulation.bend_stiffness"));
    s.bendDamping = float(scene.number("simulation.bend_damping"));
    s.youngsModulus = float(scene.number("hair.material.youngs_modulus"));
    s.shearModulus = float(scene.number("hair.material.shear_modulus"));
    s.density = float(scene.number("hair.material.density"));
    s.hairsPerGuide = float(scene.number("hair.material.hairs_per_guide"));
    s.rodSubsteps = int(scene.integer("simulation.rod_substeps"));
    s.preload = scene.flag("simulation.preload");
    s.headCollision = scene.flag("simulation.head_collision");
    s.strandCollision = scene.flag("simulation.strand_collision");
    s.strandsPerWorld = int(scene.integer("simulation.strands_per_world"));
    s.bendLimit = float(scene.number("simulation.limits.bend"));
    s.twistLimit = float(scene.number("simulation.limits.twist"));
    s.limitStiffness = float(scene.number("simulation.limits.stiffness"));
    s.projectionAngle = float(scene.number("simulation.limits.projection_angle"));
    s.projectionDistance = float(scene.number("simulation.limits.projection_distance"));
    s.teleportDistance = float(scene.number("simulation.cut_distance"));
    s.teleportAngle = float(scene.number("simulation.cut_angle"));
    s.maxSpeed = float(scene.number("simulation.max_speed"));

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
