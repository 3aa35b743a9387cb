// simulation.*: the guide solver (sim/guides/guides.h, mapped by pipeline/scene/sim_settings.h),
// and the guide shape keys hair.guides.segments / length / collision_radius
// and hair.radius.* (the guides' render radii).
#include "pipeline/scene/scene_keys.h"

namespace hp {

void addSimKeys(SchemaBuilder& b) {
    b.section("hair.guides", "Guide strands: the simulated hairs followers are built from (seed 000).")
        .integer("hair.guides.segments", 23, 1, 200, "", "Segments per guide (vertices = segments + 1).")
        .number("hair.guides.length", 0.25, 1e-4, 100, "m", "Rest length of a guide.")
        .number("hair.guides.collision_radius", 0.001, 0, 0.1, "m",
                "Radius kept clear of the head, and capsule radius for strand-strand collision.");
    b.section("hair.radius", "Render radius of every strand, tapering linearly from root to tip.")
        .number("hair.radius.root", 0.00004, 0, 0.01, "m", "Radius at the root.")
        .number("hair.radius.tip", 0.00001, 0, 0.01, "m", "Radius at the tip.");

    b.section("hair.material",
              "The fibre and the wisp a guide stands for (SI units), read by the rod formulation and by the "
              "curly model (hair.model: curly-wet, whose springs follow from it unless hair.curly.* sets them). "
              "Mass per length N·ρ·πr², bending stiffness N·E·πr⁴/4, twist stiffness N·G·πr⁴/2, "
              "r = hair.radius.root.")
        .number("hair.material.youngs_modulus", 3.8e9, 0, 1e12, "Pa", "Young's modulus E of one hair (human: 3.5–4 GPa).")
        .number("hair.material.shear_modulus", 1.3e9, 0, 1e12, "Pa",
                "Shear modulus G of one hair (twist stiffness; an isotropic fibre with a free tip carries no "
                "twist moment, see README).")
        .number("hair.material.density", 1300, 1, 1e5, "kg/m³", "Density ρ of hair.")
        .number("hair.material.hairs_per_guide", 100, 1e-3, 1e7, "",
                "Hairs N of the wisp a guide stands for: its mass and bending stiffness are N times one hair's.");
    b.section("simulation",
              "Guide dynamics. `rod` (default): inextensible elastic rods from hair.material, XPBD with a direct "
              "banded solve per strand; `rope`: Bullet soft-body ropes with joint springs, limits, exact lengths "
              "and head projection after each Bullet step; `rigid`: the seed's capsule rigid bodies and 6-DoF "
              "spring joints, kept for comparison.")
        .choice("simulation.formulation", "rod", {"rod", "rope", "rigid"}, "Which model simulates the guides.")
        .number("simulation.time_step", 0.02, 1e-4, 1, "s", "Fixed simulation step (seed: 0.02 s).")
        .integer("simulation.substeps", 1, 1, 64, "", "Bullet steps per simulation step.")
        .integer("simulation.iterations", 20, 1, 1000, "", "Bullet solver iterations per Bullet step (seed: 20).")
        .integer("simulation.rod_substeps", 2, 1, 64, "", "Rod: XPBD steps per simulation substep.")
        .number("simulation.friction", 0.2, 0, 10, "", "Coulomb friction against the head and between strands.")
        .number("simulation.damping", 1, 0, 1000, "1/s",
                "Velocity decay rate: v·exp(-damping·t), the same whatever the time step (rod: air drag, a force "
                "-damping·μ·v per length).")
        .vec3("simulation.gravity", 0, -9.81, 0, "m/s²", "Gravity.")
        .number("simulation.mass_per_length", 0.005, 1e-9, 100, "kg/m", "Rope, rigid: mass of a guide per metre.")
        .number("simulation.bend_stiffness", 5e-5, 0, 1e3, "N·m/rad",
                "Rope, rigid: joint spring toward the rest shape (rigid: Bullet caps it for stability).")
        .number("simulation.bend_damping", 0, 0, 1e3, "N·m·s/rad", "Rigid only: damping of the joint springs.")
        .flag("simulation.preload", true,
              "Pre-load the joint springs so the rest shape is an equilibrium under gravity at the first frame.")
        .flag("simulation.head_collision", true,
              "Project vertices out of the head's signed distance (with friction) after every Bullet step.")
        .flag("simulation.strand_collision", false,
              "Strand-strand collision (seed table row 7): couples all guides, so it costs speed.")
        .integer("simulation.strands_per_world", 16, 1, 100000, "",
                 "Guides per Bullet world; worlds run in parallel. A fixed partition: results do not depend on "
                 "the thread count.")
        .number("simulation.max_speed", 50, 0, 1e4, "m/s",
                "Guard (rod and rope formulations): a guide vertex faster than this after a step is slowed to it; the "
                "frame's statistics count the clamped vertices. 0: no clamp.")
        // Scene cuts (sim/solver/scene_cut.h); `hairpipe info` lists the cuts of the clip.
        .number("simulation.cut_distance", 0.1, 0, 1e6, "m",
                "Scene cut: the head or a root moving farther than this in one step is a cut; every guide restarts "
                "in its rest shape on the new pose, placed outside the colliders before the frame is written.")
        .number("simulation.cut_angle", 45, 0, 180, "deg", "Scene cut: the head turning more than this in one step.");
    b.section("simulation.limits", "Joint limits (seed: ±30° bend, ±10° twist, soft, with a projection limit).")
        .number("simulation.limits.bend", 30, 0.1, 179, "deg", "Bend limit about the two bending axes.")
        .number("simulation.limits.twist", 10, 0.1, 89, "deg", "Rigid only: twist limit about the segment.")
        .number("simulation.limits.stiffness", 1e-3, 0, 1e3, "N·m/rad", "Spring pushing a joint back inside its limit.")
        .number("simulation.limits.projection_angle", 5, 0, 180, "deg",
                "A joint beyond its limit by more than this is snapped back.")
        .number("simulation.limits.projection_distance", 0.1, 0, 10, "",
                "Rigid only: a joint pulled apart by more than this fraction of a segment is snapped back.");
}

}  // namespace hp

namespace hp {

void addGroomKeys(SchemaBuilder& b) {
    b.section("hair.groom", "The guides' rest shape at the first frame (the rigid-chain model).")
        .choice("hair.groom.style", "straight", {"straight", "combed"},
                "straight: along the root normal (seed 000); combed: leaving the scalp upright and "
                "turning toward hair.groom.direction, laid over the head.")
        .number("hair.groom.droop", 0.85, 0, 1, "",
                "Combed: how far strands turn toward the comb direction (1: the tips point along it).")
        .vec3("hair.groom.direction", 0, -1, 0, "", "Combed: the world direction hair is combed toward.")
        .number("hair.groom.settle", 5, 0, 60, "s",
                "Procedural grooms: before the first frame, simulate the groom on the first frame's pose held "
                "still (gravity, collisions) until its kinetic energy is below 1e-6 J or this much time has "
                "passed, and take that shape as the rest shape, so hair lies on the head from frame 1. Cached "
                "in cache.settled_groom. 0: no settling.")
        .number("hair.groom.settle_stiffness", 0.001, 0, 1, "",
                "Settling: the bend and limit springs scaled by this, so the groom drapes under gravity onto the "
                "head (1: the solver's own stiffness, which holds a drawn shape almost rigidly).")
        .file("hair.groom.file", "",
              "The user's own groom: OBJ polylines (.obj), Cem Yuksel's .hair, or the .usda BasisCurves "
              "export-usd writes. Each strand is bound to the nearest scalp triangle and resampled to "
              "hair.guides.segments + 1 points; with more strands than hair.guides.count, guides are chosen "
              "among them and the others become followers keeping their own shape. Empty: a procedural groom.")
        .number("hair.groom.unit_scale", 1, 1e-9, 1e9, "", "Groom file: metres per file unit (0.01 for centimetres).")
        .choice("hair.groom.up_axis", "y", {"y", "z", "x"}, "Groom file: its up axis, turned to Y up as head.up_axis.")
        .vec3("hair.groom.translate", 0, 0, 0, "m", "Groom file: translation after unit scale and up axis.")
        .vec3("hair.groom.rotate", 0, 0, 0, "deg", "Groom file: rotation about X, then Y, then Z (before translate).")
        .number("hair.groom.max_root_distance", 0.01, 0, 10, "m",
                "Groom file: a strand whose first point is further than this from the scalp is reported and dropped.");
}

}  // namespace hp
