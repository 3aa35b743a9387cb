// head.*: the animated head mesh (import, placement, clip, scalp, collider).
// Mapped onto HeadImportSettings, HeadAnimationSettings and ScalpSettings by
// pipeline/head/head_setup.cpp.
#include "pipeline/scene/scene_keys.h"

namespace hp {

void addHeadKeys(SchemaBuilder& b) {
    b.section("head",
              "The animated head the hair grows on, read through assimp (glTF/GLB, FBX, Collada, OBJ, ...). "
              "Node animation, skinning (every bone weight) and morph targets are evaluated at each frame's "
              "time. Without a file the shot has no head.")
        .file("head.file", "", "Mesh or animation file. Empty: no head.")
        .text("head.meshes", "",
              "Comma-separated meshes to use, each a name (of the mesh or of the node placing it; a glTF mesh "
              "'Head' split into primitives matches 'Head-0', 'Head-1', ...) or an index as `hairpipe info` "
              "lists them. Empty: every mesh.")
        .text("head.clip", "",
              "Animation clip by name or index. Empty: the first clip (none: the rest pose); 'none': keep the "
              "mesh in its rest pose.")
        .number("head.clip_offset", 0, -1e6, 1e6, "s", "Clip time at shot time 0: clip time = time · clip_speed + clip_offset.")
        .number("head.clip_speed", 1, 0, 1000, "", "Playback speed of the clip.")
        .flag("head.loop", false, "Repeat the clip; otherwise the last pose holds after the clip ends.")
        .number("head.rest_time", 0, -1e6, 1e6, "s",
                "Shot time of the rest pose: hair roots are placed on it, the rigid transform and the rest "
                "collision grid are relative to it.")
        .number("head.unit_scale", 1, 1e-9, 1e9, "",
                "Metres per asset unit (0.01 for centimetres). hairpipe works in metres.")
        .choice("head.up_axis", "y", {"y", "z", "x"},
                "The asset's up axis; z and x are turned to hairpipe's Y up (z: -90° about X). glTF is Y up.")
        .vec3("head.translate", 0, 0, 0, "m", "Places the head: translation after unit scale and up axis.")
        .vec3("head.rotate", 0, 0, 0, "deg", "Places the head: rotation about X, then Y, then Z (before translate).");
    b.section("head.animate",
              "Extra rigid motion on top of the file's animation (e.g. to turn a static scan), keyed per frame.")
        .curve("head.animate.yaw", 0, -1e6, 1e6, "deg", "Rotation about +Y through the pivot.")
        .curve("head.animate.pitch", 0, -1e6, 1e6, "deg", "Rotation about +X through the pivot (after yaw).")
        .curve("head.animate.roll", 0, -1e6, 1e6, "deg", "Rotation about +Z through the pivot (after pitch).")
        .vec3("head.animate.pivot", 0, 0, 0, "m", "Centre of the rotations (world).");
    b.section("head.colliders",
              "Colliders beside the head (body, shoulders, hat, hand, props), each a Bullet collision object in one "
              "collision world that every hair vertex queries (sim/collision/collision_world.h); the head keeps its own "
              "collider (head.collider) as the fast path.")
        .list("head.colliders", "[]", 64, "The colliders, a list of maps.")
        .choice("head.colliders[].type", "box", {"sphere", "capsule", "box", "mesh", "hull", "skinned"},
                "sphere, capsule, box: Bullet's primitives; mesh: a rigid prop's triangles as a GImpact mesh "
                "(hollows such as a hat's inside stay open; the mesh should be closed and wound outward); hull: "
                "the convex hull of the file's vertices (cheaper, fills every hollow); skinned: a mesh file "
                "played by its own clip (a body), a triangle mesh whose BVH is refitted to each pose's vertices.")
        .number("head.colliders[].radius", 0.05, 1e-5, 100, "m", "sphere, capsule: radius.")
        .number("head.colliders[].length", 0.1, 0, 100, "m", "capsule: distance between the cap centres (along local Y).")
        .vec3("head.colliders[].size", 0.1, 0.1, 0.1, "m", "box: full extents along local X, Y, Z.")
        .file("head.colliders[].file", "",
              "mesh, hull, skinned: the mesh file (any format assimp reads). Empty: the head's own file, imported and "
              "placed as the head (head.unit_scale, up_axis, translate, rotate).")
        .text("head.colliders[].meshes", "",
              "mesh, hull, skinned: comma-separated meshes of the file (names or indices as `hairpipe info` lists them); "
              "empty: every mesh.")
        .text("head.colliders[].clip", "",
              "skinned: the file's clip by name or index, on the head's timing (head.clip_offset, clip_speed, loop); "
              "empty: the clip head.clip names; 'none': the rest pose.")
        .number("head.colliders[].unit_scale", 1, 1e-9, 1e9, "", "mesh, hull, skinned: metres per file unit.")
        .choice("head.colliders[].parent", "world", {"world", "head"},
                "world: placed in the world; head: carried by the head's rigid motion (placement in the rest "
                "pose's world frame).")
        .flag("head.colliders[].visible", true,
              "mesh, hull, skinned: drawn beside the head in the preview and reference (the file's triangles, "
              "posed); false: collides unseen. Primitives are never drawn.")
        .vec3("head.colliders[].translate", 0, 0, 0, "m", "Placement: translation (after rotate).")
        .vec3("head.colliders[].rotate", 0, 0, 0, "deg", "Placement: rotation about X, then Y, then Z.")
        .curve("head.colliders[].move_x", 0, -1e6, 1e6, "m", "Keyed motion per frame, added to translate along X.")
        .curve("head.colliders[].move_y", 0, -1e6, 1e6, "m", "Keyed motion along Y.")
        .curve("head.colliders[].move_z", 0, -1e6, 1e6, "m", "Keyed motion along Z.");
    b.section("head.scalp", "Which triangles of the rest mesh grow hair.")
        .choice("head.scalp.method", "auto", {"auto", "all", "material", "vertex_color", "texture", "region"},
                "auto: the materials whose name contains 'scalp' or 'hair', else a cap over the top and back of "
                "the head fitted to the mesh (never face, chin or neck; stderr says which); all: every triangle; material: triangles of the named materials; vertex_color: the corners' "
                "mean channel value at least the threshold; texture: the mask image, read through the uvs, at "
                "least the threshold; region: a spherical cap (centre, axis, angle), as the seed's partial sphere.")
        .text("head.scalp.materials", "", "material: comma-separated material names.")
        .choice("head.scalp.channel", "r", {"r", "g", "b", "a"}, "vertex_color and texture: the channel read.")
        .number("head.scalp.threshold", 0.5, 0, 1, "", "vertex_color and texture: the selecting value.")
        .file("head.scalp.mask", "",
              "texture: the mask image (any format OpenImageIO reads; uv (0, 0) is its bottom-left corner).")
        .vec3("head.scalp.center", 0, 0, 0, "m", "region: centre of the cap (world, after placement).")
        .vec3("head.scalp.axis", 0, 1, 0, "", "region: direction of the cap's pole.")
        .number("head.scalp.angle", 90, 0, 180, "deg", "region: half-angle of the cap (90: a hemisphere).");
    b.section("head.collider",
              "Collision data handed to the solvers each frame: a signed distance (negative inside the head).")
        .choice("head.collider.method", "rigid", {"rigid", "per_frame", "exact", "none"},
                "rigid: a narrow-band distance grid of the rest pose moved by the head's rigid motion (built "
                "once, fast queries; ignores non-rigid deformation such as a skinned neck); per_frame: a grid of "
                "each frame's deformed mesh (a build per frame); exact: closest-triangle queries on the "
                "deformed mesh (slower queries); none: no head collision.")
        .number("head.collider.voxel_size", 0.002, 1e-5, 1, "m", "Grid voxel size (trilinear error ≲ voxel/2 at sharp features).")
        .number("head.collider.exterior_band", 0.006, 1e-5, 10, "m",
                "Exact distances are kept this far outside the surface; beyond, a lower bound.")
        .number("head.collider.interior_band", 0.006, 1e-5, 10, "m",
                "And this far inside; deeper points are measured exactly against the rest mesh.");
}

}  // namespace hp
