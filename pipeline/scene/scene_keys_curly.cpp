// hair.model, hair.curly.*, hair.wet.*: the choice of strand model and the
// curly/wet model's settings (seed 001, sim/curly/curly_wet.h), mapped onto
// CurlyWetSettings by pipeline/scene/curly_settings.cpp. Defaults are the seed's
// values where it gives one.
#include "pipeline/scene/scene_keys.h"

namespace hp {

void addCurlyKeys(SchemaBuilder& b) {
    b.section("hair", "Hair grown on the head: guide strands simulated, followers interpolated.")
        .choice("hair.model", "rigid-chain", {"rigid-chain", "curly-wet"},
                "Strand model of the guides. rigid-chain: seed 000's chains of segments (formulation in "
                "simulation.formulation); curly-wet: seed 001's curly mass-spring strands with wet effects "
                "(hair.curly, hair.wet).");
    b.section("hair.curly",
              "Curly guides (hair.model: curly-wet; seed 001 after Iben et al. 2013): particles joined by "
              "stretch, bending and core springs, rest shape a helix along the root normal. Bullet integrates "
              "and keeps the strands inextensible; the springs enter through a linearly implicit step.")
        .integer("hair.curly.particles", 24, 2, 1000, "", "Particles per guide.")
        .number("hair.curly.length", 0.25, 1e-4, 10, "m", "Arc length of a guide.")
        .number("hair.curly.radius", 0.01, 0, 1, "m", "Curl (helix) radius of the rest shape; 0: straight.")
        .number("hair.curly.pitch", 0.04, 0, 10, "m", "Curl advance per turn of the rest shape.")
        .number("hair.curly.collision_radius", 0.001, 0, 0.1, "m", "Clearance kept between particles and the head.")
        .number("hair.curly.root_radius", 0.00004, 0, 0.01, "m", "Render radius at the root.")
        .number("hair.curly.tip_radius", 0.00001, 0, 0.01, "m", "Render radius at the tip.")
        .number("hair.curly.time_step", 0.02, 1e-4, 0.1, "s", "Simulation step.")
        .integer("hair.curly.substeps", 1, 1, 64, "", "Bullet steps per simulation step.")
        .integer("hair.curly.iterations", 8, 1, 200, "", "Bullet link (inextensibility) iterations per Bullet step.")
        .number("hair.curly.mass_per_length", 0.005, 1e-6, 10, "kg/m",
                "Only when given (the seed's value is the default shown): mass per length of a guide. Unset, it is "
                "the wisp's N·ρ·πr² from hair.material and hair.radius.root, as for the rod.")
        .vec3("hair.curly.gravity", 0, -9.81, 0, "m/s²", "Gravity.")
        .flag("hair.curly.preload", true, "Pre-load the bending springs so the rest shape holds under gravity at the "
                                          "first frame.")
        .number("hair.curly.stretch_stiffness", 5000, 0, 1e7, "N/m",
                "Only when given (the seed's value is the default shown): ks of the stretch springs (seed eq. 1). "
                "Unset, it follows the particle mass m and the Bullet step h: ks = 10⁴·m/h² (the links keep the "
                "edges inextensible; a stiffer spring destabilises the step with light, physical particles).")
        .number("hair.curly.stretch_damping", 0.05, 0, 1e4, "N·s/m", "cs of the stretch springs.")
        .number("hair.curly.bend_stiffness", 20, 0, 1e6, "N/m",
                "Only when given (the seed's value is the default shown): kb of the bending springs (seed eq. 4). "
                "Unset, it is derived from hair.material and the curl so that a curl stretches under load as a "
                "helical coil of that wire does (Castigliano; README, curly hair).")
        .number("hair.curly.bend_damping", 0.02, 0, 1e4, "N·s/m", "cb of the bending springs.")
        .number("hair.curly.bend_smoothing", 0.05, 0, 10, "m",
                "α of the smoothing filter whose curve carries the bending frames (seed eq. 2); 0: none.")
        .number("hair.curly.core_stiffness", 20, 0, 1e6, "N/m",
                "Only when given (the seed's value is the default shown): kc of the core springs on the smoothed "
                "curve (seed eq. 5), stiffening curls against being pulled straight. Unset, 0: the derived kb already "
                "carries the coil's whole stiffness.")
        .number("hair.curly.core_damping", 0.02, 0, 1e4, "N·s/m", "cc of the core springs.")
        .number("hair.curly.core_smoothing", 0.05, 0, 10, "m", "α_c of the core curve's smoothing filter.")
        .number("hair.curly.max_strain", 0.001, 1e-5, 0.5, "", "Strain limit |l/l_rest - 1| of an edge.")
        .number("hair.curly.max_relative_velocity", 2, 1e-3, 1e3, "m/s",
                "Root-to-tip limit on the velocity difference of neighbouring particles.")
        .number("hair.curly.friction", 0.2, 0, 10, "", "Coulomb friction against the head.")
        .number("hair.curly.teleport_distance", 0.1, 1e-4, 1e3, "m",
                "A root or the head moving farther in one step is a cut: the guides restart at rest.")
        .number("hair.curly.teleport_angle", 45, 0.1, 180, "deg", "The same for a head rotation in one step.")
        .integer("hair.curly.strands_per_world", 16, 1, 100000,
                 "", "Guides per Bullet world (worlds run in parallel; results do not depend on the thread count).");
    b.section("hair.wet",
              "Wet effects of the curly-wet model (seed 001), driven by the saturation σ of each particle: the "
              "scene's saturation curve times a linear root-to-tip profile. Every effect vanishes at σ = 0.")
        .flag("hair.wet.enabled", true, "Apply the wet effects (false: the hair is dry whatever the saturation).")
        .curve("hair.wet.saturation", 0, 0, 1, "",
               "Saturation σ of the hair over the shot (a curve over frames: hair can get wet or dry mid-shot).")
        .number("hair.wet.saturation_root", 1, 0, 10, "", "Profile factor at the root (σ_i = σ·profile, clamped to 1).")
        .number("hair.wet.saturation_tip", 1, 0, 10, "", "Profile factor at the tip; linear in between.")
        .number("hair.wet.helix_radius", 0, 0, 1, "m",
                "Radius of the wet helix that curl exaggeration pulls toward (seed eq. 6); 0: hair.curly.radius.")
        .number("hair.wet.helix_pitch", 0, 0, 10, "m", "Advance per turn of the wet helix; 0: hair.curly.pitch.")
        .number("hair.wet.helix_weight", 100, 0, 1e6, "N/m",
                "Only when given (the seed's value is the default shown): w_h of curl exaggeration (seed eq. 9). "
                "Unset, 5× the bending springs' kb that hold the dry curl: soaked hair takes most of the wet "
                "helix's shape.")
        .flag("hair.wet.cohesion", true, "Cohesion between wet strands (seed eq. 10).")
        .number("hair.wet.cohesion_tightness", 0.85, 0, 1, "", "λ, the tightness of the cohesive position (seed: 0.85).")
        .number("hair.wet.cohesion_radius", 0.01, 1e-5, 1, "m", "Kernel radius of the neighbour average.")
        .number("hair.wet.cohesion_stiffness", 1e4, 0, 1e8, "1/s²",
                "Pull toward the cohesive position per unit mass and metre.")
        .flag("hair.wet.adhesion", true, "Adhesion of wet hair to the head (seed eq. 11-12).")
        .number("hair.wet.adhesion_weight", 1300, 0, 1e8, "", "ν (seed: 1300); the kernel is evaluated in cm.")
        .number("hair.wet.adhesion_radius", 0.005, 1e-5, 1, "m",
                "h of the adhesion kernel: wet hair between h/2 and h from the head is pulled back to it.")
        .number("hair.wet.global_stiffness", 0.999995, 1e-6, 1, "", "ξ, velocity scale per reference step (seed: 0.999995).")
        .number("hair.wet.wet_stiffness", 0.9999, 1e-6, 1, "", "γ0, velocity scale of soaked hair (seed: 0.9999).")
        .number("hair.wet.dry_stiffness", 1, 1e-6, 1, "", "γ1, velocity scale of dry hair (seed: 1.0).")
        .number("hair.wet.stiffness_step", 1e-4, 1e-7, 1, "s",
                "Reference step of ξ and γ: each step scales velocities by (ξζ)^(time_step/this).");
}

}  // namespace hp
