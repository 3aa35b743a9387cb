#include "pipeline/head/head_setup.h"

#include "core/log.h"

#include "sim/collision/mesh_collider.h"
#include "sim/strands/roots.h"

#include <chrono>
#include <map>
#include <sstream>

namespace hp {

namespace {

std::vector<std::string> splitList(const std::string& text) {
    std::vector<std::string> items;
    std::stringstream in(text);
    for (std::string item; std::getline(in, item, ',');) {
        const size_t b = item.find_first_not_of(" \t"), e = item.find_last_not_of(" \t");
        if (b != std::string::npos) items.push_back(item.substr(b, e - b + 1));
    }
    return items;
}

Eigen::Matrix3f eulerXYZ(const Vec3f& degrees) {
    const Vec3f r = degrees * float(M_PI / 180.0);
    // X first, then Y, then Z: R = Rz · Ry · Rx.
    return (Eigen::AngleAxisf(r.z(), Vec3f::UnitZ()) * Eigen::AngleAxisf(r.y(), Vec3f::UnitY()) *
            Eigen::AngleAxisf(r.x(), Vec3f::UnitX()))
        .toRotationMatrix();
}

double seconds(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

bool sceneHasHead(const Scene& scene) { return !scene.file("head.file").empty(); }

UpAxis sceneUpAxis(const Scene& scene, const std::string& prefix) {
    const std::string up = scene.text(prefix + ".up_axis");
    return up == "z" ? UpAxis::Z : up == "x" ? UpAxis::X : UpAxis::Y;
}

Affine3f scenePlacement(const Scene& scene, const std::string& prefix) {
    Affine3f placement = Affine3f::Identity();
    placement.translate(scene.vec3f(prefix + ".translate"));
    placement.linear() = eulerXYZ(scene.vec3f(prefix + ".rotate"));
    return placement;
}

HeadImportSettings headImportSettings(const Scene& scene) {
    HeadImportSettings s;
    s.file = scene.file("head.file");
    s.meshes = splitList(scene.text("head.meshes"));
    s.unitScale = scene.number("head.unit_scale");
    s.unitScaleGiven = scene.given("head.unit_scale");
    s.upAxis = sceneUpAxis(scene, "head");
    s.upAxisGiven = scene.given("head.up_axis");
    s.placement = scenePlacement(scene, "head");
    return s;
}

std::vector<ExtraCollider> extraColliders(const Scene& scene, const HeadAnimationSettings& head) {
    std::vector<ExtraCollider> out;
    const double fps = scene.number("fps");
    for (size_t i = 0; i < scene.count("head.colliders"); ++i) {
        const std::string k = cat("head.colliders[", i, "].");
        ExtraCollider c;
        const std::string type = scene.text(k + "type");
        c.shape.kind = type == "sphere"    ? ColliderShape::Kind::Sphere
                       : type == "capsule" ? ColliderShape::Kind::Capsule
                       : type == "mesh"    ? ColliderShape::Kind::Mesh
                       : type == "hull"    ? ColliderShape::Kind::ConvexMesh
                       : type == "skinned" ? ColliderShape::Kind::SkinnedMesh
                                           : ColliderShape::Kind::Box;
        c.shape.radius = float(scene.number(k + "radius"));
        c.shape.length = float(scene.number(k + "length"));
        c.shape.halfExtents = 0.5f * scene.vec3f(k + "size");
        if (c.shape.kind == ColliderShape::Kind::Box && !(c.shape.halfExtents.minCoeff() > 0.f))
            scene.fail(k + "size", "a box needs positive extents");
        if (type == "mesh" || type == "hull" || type == "skinned") {
            // Another file, or (no file) meshes of the head's own file, placed as the head is.
            HeadImportSettings mesh = headImportSettings(scene);
            if (!scene.file(k + "file").empty()) {
                mesh = HeadImportSettings{};
                mesh.file = scene.file(k + "file");
                mesh.unitScale = scene.number(k + "unit_scale");
            }
            if (mesh.file.empty()) scene.fail(k + "file", cat("a ", type, " collider needs a file (or head.file)"));
            mesh.meshes = splitList(scene.text(k + "meshes"));
            std::shared_ptr<const HeadRig> rig;
            try {
                rig = std::make_shared<const HeadRig>(importHead(mesh));
            } catch (const RigSelectionError& e) {
                scene.fail(k + "meshes", e.what());
            }
            const TriangleMesh rest = rig->restMesh();
            c.shape.points = rest.positions;
            c.shape.triangles = rest.triangles;
            if (c.shape.kind == ColliderShape::Kind::SkinnedMesh) {
                // The file's clip on the head's timing (clip_offset, clip_speed, loop).
                HeadAnimationSettings body = head;
                body.motion = nullptr;
                body.collider = ColliderMethod::None;
                body.colliders.clear();
                try {
                    const std::string clip = scene.text(k + "clip");
                    body.clip = findClip(*rig, clip.empty() ? scene.text("head.clip") : clip);
                } catch (const RigSelectionError& e) {
                    scene.fail(k + "clip", e.what());
                }
                auto skin = std::make_shared<const AnimatedHead>(rig, body);
                c.shape.points = skin->rest().positions;  // the tree is built on the rest pose, then refitted
                c.skin = std::move(skin);
            }
            if (c.shape.points.size() < 4)
                scene.fail(k + "file", cat(mesh.file.string(), " has ", c.shape.points.size(),
                                           " vertices; a collider needs at least 4"));
        }
        c.followsHead = scene.text(k + "parent") == "head";
        c.visible = scene.flag(k + "visible");
        Eigen::Isometry3f base = Eigen::Isometry3f::Identity();
        base.linear() = eulerXYZ(scene.vec3f(k + "rotate"));
        base.translation() = scene.vec3f(k + "translate");
        const Curve& mx = scene.curve(k + "move_x");
        const Curve& my = scene.curve(k + "move_y");
        const Curve& mz = scene.curve(k + "move_z");
        // Curves are keyed by frame; the placement is asked by time.
        c.place = [=](double time) {
            const double f = time * fps;
            Eigen::Isometry3f t = base;
            t.translation() += Vec3f(float(mx.eval(f)), float(my.eval(f)), float(mz.eval(f)));
            return t;
        };
        out.push_back(std::move(c));
    }
    return out;
}

HeadAnimationSettings headAnimationSettings(const Scene& scene, const HeadRig& rig) {
    HeadAnimationSettings s;
    try {
        s.clip = findClip(rig, scene.text("head.clip"));
    } catch (const RigSelectionError& e) {
        scene.fail("head.clip", e.what());
    }
    s.clipOffset = scene.number("head.clip_offset");
    s.clipSpeed = scene.number("head.clip_speed");
    s.loop = scene.flag("head.loop");
    s.restTime = scene.number("head.rest_time");
    const Curve& yaw = scene.curve("head.animate.yaw");
    const Curve& pitch = scene.curve("head.animate.pitch");
    const Curve& roll = scene.curve("head.animate.roll");
    const bool animated = yaw.animated() || pitch.animated() || roll.animated() || yaw.eval(0) != 0.0 ||
                          pitch.eval(0) != 0.0 || roll.eval(0) != 0.0;
    if (animated) {
        const Vec3f pivot = scene.vec3f("head.animate.pivot");
        const double fps = scene.number("fps");
        // Curves are keyed by frame; the motion is asked by time.
        s.motion = [=](double time) {
            const double f = time * fps, k = M_PI / 180.0;
            const Eigen::Matrix3f r = (Eigen::AngleAxisf(float(roll.eval(f) * k), Vec3f::UnitZ()) *
                                       Eigen::AngleAxisf(float(pitch.eval(f) * k), Vec3f::UnitX()) *
                                       Eigen::AngleAxisf(float(yaw.eval(f) * k), Vec3f::UnitY()))
                                          .toRotationMatrix();
            Eigen::Isometry3f a = Eigen::Isometry3f::Identity();
            a.linear() = r;
            a.translation() = pivot - r * pivot;
            return a;
        };
    }
    const std::string method = scene.text("head.collider.method");
    s.collider = method == "per_frame" ? ColliderMethod::PerFrame
                 : method == "exact"   ? ColliderMethod::Exact
                 : method == "none"    ? ColliderMethod::None
                                       : ColliderMethod::Rigid;
    s.levelSet.voxelSize = float(scene.number("head.collider.voxel_size"));
    s.levelSet.exteriorBand = float(scene.number("head.collider.exterior_band"));
    s.levelSet.interiorBand = float(scene.number("head.collider.interior_band"));
    // The colliders beside the head are exact this far out (a mesh query
    // gathers the triangles within it: 1 cm instead of 5 cut the default
    // shot's frame from 670 to 170 ms and left every strand bit for bit the same).
    s.collidersBand = float(scene.number("head.collider.colliders_band"));
    if (s.levelSet.exteriorBand < s.levelSet.voxelSize)
        scene.fail("head.collider.exterior_band", "must be at least head.collider.voxel_size");
    if (s.levelSet.interiorBand < s.levelSet.voxelSize)
        scene.fail("head.collider.interior_band", "must be at least head.collider.voxel_size");
    s.colliders = extraColliders(scene, s);
    return s;
}

ScalpSettings scalpSettings(const Scene& scene) {
    ScalpSettings s;
    const std::string method = scene.text("head.scalp.method");
    s.method = method == "material"       ? ScalpMethod::Material
               : method == "vertex_color" ? ScalpMethod::VertexColor
               : method == "texture"      ? ScalpMethod::Texture
               : method == "region"       ? ScalpMethod::Region
                                          : ScalpMethod::All;
    s.materials = splitList(scene.text("head.scalp.materials"));
    if (s.method == ScalpMethod::Material && s.materials.empty())
        scene.fail("head.scalp.materials", "head.scalp.method is material: name at least one material");
    s.channel = int(std::string("rgba").find(scene.text("head.scalp.channel")));
    s.threshold = float(scene.number("head.scalp.threshold"));
    s.mask = scene.file("head.scalp.mask");
    if (s.method == ScalpMethod::Texture && s.mask.empty())
        scene.fail("head.scalp.mask", "head.scalp.method is texture: give the mask image");
    s.center = scene.vec3f("head.scalp.center");
    s.axis = scene.vec3f("head.scalp.axis");
    if (s.axis.norm() == 0.f) scene.fail("head.scalp.axis", "must not be zero");
    s.angleDegrees = float(scene.number("head.scalp.angle"));
    return s;
}

namespace {

/// Warns about defects of the rest mesh (after welding seams), counted per
/// edge. Warnings, not errors: scanned heads are often open at the neck, and
/// a defect far from the scalp does no harm.
/// - open: boundary edges (one triangle), and non-manifold: edges shared by
///   more than two triangles (fins, doubled faces). The level-set colliders'
///   flood fill finds the inside only of a closed manifold mesh
///   (sim/collision/level_set.h), so hair may be pushed the wrong way there; the exact
///   collider and `none` do not depend on it.
/// - inconsistent winding: two triangles that run along their shared edge the
///   same way, so one of them faces inward. Root normals come from the
///   winding (hair rooted there grows into the head), and so does the exact
///   collider's inside (angle-weighted pseudonormals).
/// - inside out: closed, consistently wound, but with negative volume
///   (divergence theorem: V = Σ p0 · (p1 × p2) / 6), so every triangle faces
///   inward.
void warnIfNotClosed(const TriangleMesh& mesh, const std::string& colliderMethod, const std::string& file) {
    const bool levelSet = colliderMethod == "rigid" || colliderMethod == "per_frame";
    const std::vector<uint32_t> weld = weldVertices(mesh.positions);
    struct EdgeUse {
        int uses = 0;
        int direction = 0;  ///< +1 per use from the lower to the higher vertex, -1 the other way
    };
    std::map<std::pair<uint32_t, uint32_t>, EdgeUse> edges;
    for (const auto& t : mesh.triangles)
        for (int e = 0; e < 3; ++e) {
            uint32_t a = weld[t[e]], b = weld[t[(e + 1) % 3]];
            if (a == b) continue;  // a degenerate triangle's collapsed edge
            EdgeUse& use = edges[{std::min(a, b), std::max(a, b)}];
            ++use.uses;
            use.direction += a < b ? 1 : -1;
        }
    size_t boundary = 0, nonManifold = 0, flipped = 0;
    for (const auto& [edge, use] : edges) {
        boundary += use.uses == 1;
        nonManifold += use.uses > 2;
        flipped += use.uses == 2 && use.direction != 0;
    }
    const char* advice = "; fix the mesh or use head.collider.method: exact";
    if (levelSet && boundary > 0)
        logWarning("head: ", file, " is open (", boundary, " boundary edges): the collider's inside/outside is "
                   "unreliable near the holes", advice);
    if (levelSet && nonManifold > 0)
        logWarning("head: ", file, " is non-manifold (", nonManifold, " edges shared by more than two triangles): "
                   "the collider's inside/outside is unreliable there", advice);
    if (boundary == 0 && nonManifold == 0 && flipped == 0) {  // a volume only for a closed, consistent mesh
        double volume = 0.0;
        for (const auto& t : mesh.triangles)
            volume += double(mesh.positions[t[0]].dot(mesh.positions[t[1]].cross(mesh.positions[t[2]]))) / 6.0;
        if (volume < 0.0)
            logWarning("head: ", file, " is inside out (every triangle faces inward, volume ", volume,
                       " m³): hair grows into the head; reverse the winding");
    }
    if (flipped > 0)
        logWarning("head: ", file, " has inconsistently wound triangles (", flipped, " edges whose two triangles "
                   "run the same way): hair rooted on inward-facing ones grows into the head, and the exact "
                   "collider's inside/outside is wrong near them; make the winding consistent");
}

/// A head is some 0.15-0.3 m tall; bounds beyond 1 m or under 5 cm are a
/// unit the file did not declare (or declared wrongly).
void warnIfImplausibleSize(const TriangleMesh& rest, const HeadRig& rig) {
    const float size = rest.bounds().sizes().maxCoeff();
    if (size > 1.f || size < 0.05f)
        logWarning("head: ", rig.file, " measures ", size, " m across at rest (", rig.unitScale,
                   " m per file unit), implausible for a head: set head.unit_scale to the file's metres per unit "
                   "(0.01 for centimetres, 0.001 for millimetres)");
}

}  // namespace

HeadSetup loadHead(const Scene& scene) {
    if (!sceneHasHead(scene)) scene.fail("head.file", "the scene has no head file");
    const auto start = std::chrono::steady_clock::now();
    HeadSetup h;
    try {
        h.rig = std::make_shared<const HeadRig>(importHead(headImportSettings(scene)));
    } catch (const RigSelectionError& e) {
        scene.fail("head.meshes", e.what());
    }
    auto motion = std::make_shared<AnimatedHead>(h.rig, headAnimationSettings(scene, *h.rig));
    h.rest = motion->rest();
    ScalpSettings scalp = scalpSettings(scene);
    h.scalpGiven = scene.text("head.scalp.method") != "auto";
    if (!h.scalpGiven) {
        std::string why;
        scalp = defaultScalp(*h.rig, h.rest, why);
        // An imported groom binds to every triangle; the scalp then only
        // places procedural followers, not worth a line.
        if (scene.file("hair.groom.file").empty())
            logInfo("head: hair grows on ", why, "; choose another scalp with head.scalp.method (material, "
                "vertex_color, texture, region, or all for every triangle)");
    }
    h.scalpUsed = scalp;
    try {
        h.scalp = selectScalp(*h.rig, h.rest, scalp);
    } catch (const AssetError&) {
        throw;
    } catch (const Error& e) {
        scene.fail(scalp.method == ScalpMethod::Material ? "head.scalp.materials" : "head.scalp.method", e.what());
    }
    motion->setFitTriangles(h.scalp);
    h.motion = std::move(motion);
    size_t scalpTriangles = 0;
    for (uint8_t s : h.scalp) scalpTriangles += s;
    if (scalpTriangles > 0 && !(surfaceArea(h.rest, h.scalp) > 0.0))
        scene.fail(scalp.method == ScalpMethod::All ? "head.file" : "head.scalp.method",
                   cat("the scalp (", scalpTriangles, scalpTriangles == 1 ? " triangle" : " triangles",
                       ") has zero area in ", h.rig->file, ": only degenerate triangles, no hair can grow"));
    warnIfNotClosed(h.rest, scene.text("head.collider.method"), h.rig->file);
    warnIfImplausibleSize(h.rest, *h.rig);
    logVerbose("head: ", h.rest.triangleCount(), " triangles, ", scalpTriangles, " on the scalp (",
               surfaceArea(h.rest, h.scalp) * 1e4, " cm²), set up in ", seconds(start), " s");
    return h;
}

RootSettings rootSettings(const Scene& scene, const HeadSetup& head, size_t count, uint64_t seed) {
    RootSettings r;
    r.count = count;
    r.seed = seed;
    r.method = scene.text("hair.roots.method") == "blue-noise" ? RootMethod::BlueNoise : RootMethod::Fibonacci;
    if (head.scalpUsed.method == ScalpMethod::Region) {
        // Gomes 2024's partial sphere: the lattice shares the cap's centre and pole.
        r.center = head.scalpUsed.center;
        r.axis = head.scalpUsed.axis.normalized();
    }
    return r;
}

GroomRoots placeGroomRoots(const Scene& scene, const HeadSetup& head) {
    const auto start = std::chrono::steady_clock::now();
    const uint64_t seed = uint64_t(scene.integer("seed"));
    GroomRoots g;
    // Independent placements: the followers' stream differs from the guides'.
    g.guides = placeRoots(head.rest, head.scalp,
                          rootSettings(scene, head, size_t(scene.integer("hair.guides.count")), seed * 2 + 0));
    g.followers = placeRoots(head.rest, head.scalp,
                             rootSettings(scene, head, size_t(scene.integer("hair.followers.count")), seed * 2 + 1));
    logVerbose("roots: ", g.guides.size(), " guides, ", g.followers.size(), " followers (",
               scene.text("hair.roots.method"), ") in ", seconds(start), " s");
    return g;
}

}  // namespace hp
