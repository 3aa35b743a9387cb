#include "pipeline/head/fold_head.h"

#include "pipeline/head/default_head.h"

#include <algorithm>
#include <cmath>

namespace hp {

namespace {

const Vec3f kNeckBase(0.f, kFoldNeckTop - kFoldNeckLength, 0.f);  // the Neck bone: the neck pivots at its base
const Vec3f kHeadJoint(0.f, -0.09f, 0.f);  // the Head bone: where the neck's side enters the sphere

/// The neck: a closed cylinder about +Y, wound counter-clockwise seen from
/// outside (the sphere's convention: direction (cos φ, 0, -sin φ)), its side
/// and caps with vertices of their own (the caps' normals are ±Y; the
/// collider welds the copies).
TriangleMesh cylinder(const FoldHeadOptions& o) {
    TriangleMesh m;
    const float pi = float(M_PI), top = kFoldNeckTop, bottom = kFoldNeckTop - kFoldNeckLength;
    auto around = [&](int s) {
        const float phi = 2.f * pi * float(s) / float(o.sectors);
        return Vec3f(std::cos(phi), 0.f, -std::sin(phi));
    };
    const uint32_t stride = uint32_t(o.sectors + 1);
    for (int r = 0; r <= o.neckRings; ++r)
        for (int s = 0; s <= o.sectors; ++s) {
            const float y = top + (bottom - top) * float(r) / float(o.neckRings);
            m.positions.push_back(kFoldNeckRadius * around(s) + Vec3f(0.f, y, 0.f));
            m.normals.push_back(around(s));
            m.uvs.emplace_back(float(s) / float(o.sectors), 1.f - float(r) / float(o.neckRings));
        }
    for (int r = 0; r < o.neckRings; ++r)
        for (int s = 0; s < o.sectors; ++s) {
            const uint32_t a = uint32_t(r) * stride + uint32_t(s), b = a + stride, c = b + 1, d = a + 1;
            m.triangles.push_back({a, b, d});
            m.triangles.push_back({d, b, c});
        }
    for (const float y : {top, bottom}) {
        const float up = y == top ? 1.f : -1.f;
        const uint32_t centre = uint32_t(m.positions.size());
        m.positions.emplace_back(0.f, y, 0.f);
        m.normals.emplace_back(0.f, up, 0.f);
        m.uvs.emplace_back(0.5f, 0.5f);
        for (int s = 0; s < o.sectors; ++s) {
            m.positions.push_back(kFoldNeckRadius * around(s) + Vec3f(0.f, y, 0.f));
            m.normals.emplace_back(0.f, up, 0.f);
            m.uvs.emplace_back(0.5f + 0.5f * around(s).x(), 0.5f - 0.5f * around(s).z());
        }
        for (int s = 0; s < o.sectors; ++s) {
            const uint32_t p = centre + 1 + uint32_t(s), q = centre + 1 + uint32_t((s + 1) % o.sectors);
            if (up > 0.f) m.triangles.push_back({centre, p, q});
            else m.triangles.push_back({centre, q, p});
        }
    }
    return m;
}

/// Degrees of the head bone's pitch in "fold_tip" at time t: back 70° over
/// [0.2, 0.4] s, through to 70° forward by 0.8 s, upright again by 1.0 s.
double tipPitch(double t) {
    if (t < 0.2 || t >= 1.0) return 0.0;
    if (t < 0.4) return -70.0 * smoothstep(0.f, 1.f, float((t - 0.2) / 0.2));
    if (t < 0.8) return -70.0 + 140.0 * smoothstep(0.f, 1.f, float((t - 0.4) / 0.4));
    return 70.0 * (1.0 - smoothstep(0.f, 1.f, float((t - 0.8) / 0.2)));
}

/// Degrees of the neck bone's pitch in "fold_jump": 40° forward over [0.2, 0.7] s.
double bendPitch(double t) { return 40.0 * smoothstep(0.f, 1.f, float((t - 0.2) / 0.5)); }

NodeTrack restTrack(const HeadRig& rig, int node) {
    NodeTrack t;
    t.node = node;
    t.translation.times = {0.0};
    t.translation.values = {rig.nodes[size_t(node)].local.translation()};
    t.scale.times = {0.0};
    t.scale.values = {Vec3f::Ones()};
    return t;
}

void addPitchKeys(NodeTrack& t, const std::vector<double>& times, double (*pitch)(double)) {
    for (const double time : times) {
        t.rotation.times.push_back(time);
        t.rotation.values.emplace_back(Eigen::AngleAxisf(float(pitch(time) * M_PI / 180.0), Vec3f::UnitX()));
    }
}

void addClips(HeadRig& rig, const FoldHeadOptions& o) {
    auto keyTimes = [&](double duration) {
        std::vector<double> times;
        for (int k = 0; k <= int(std::lround(duration * o.keyRate)); ++k) times.push_back(k / o.keyRate);
        return times;
    };
    RigClip tip;
    tip.name = "fold_tip";
    tip.duration = kFoldTipSeconds;
    tip.keyRate = o.keyRate;
    tip.tracks.push_back(restTrack(rig, 3));
    addPitchKeys(tip.tracks.back(), keyTimes(kFoldTipSeconds), tipPitch);
    rig.clips.push_back(std::move(tip));

    RigClip jump;
    jump.name = "fold_jump";
    jump.duration = kFoldJumpSeconds;
    jump.keyRate = o.keyRate;
    NodeTrack neck = restTrack(rig, 2);
    addPitchKeys(neck, keyTimes(kFoldJumpSeconds), bendPitch);
    // The jump: two translation keys one key interval apart, which the
    // sampler interpolates linearly.
    const Vec3f base = neck.translation.values[0];
    neck.translation.times = {0.0, kFoldJumpStart, kFoldJumpStart + 1.0 / o.keyRate};
    neck.translation.values = {base, base, base + Vec3f(kFoldJumpDistance, 0.f, 0.f)};
    jump.tracks.push_back(std::move(neck));
    rig.clips.push_back(std::move(jump));
}

}  // namespace

HeadRig makeFoldHead(const FoldHeadOptions& o) {
    const TriangleMesh sphere = makeSphereMesh(Vec3f::Zero(), kFoldHeadRadius, o.rings, o.sectors);
    const TriangleMesh neck = cylinder(o);

    HeadRig rig;
    rig.file = "folding head";
    rig.nodes = {{"FoldRig", -1, Affine3f::Identity()},
                 {"Fold", 0, Affine3f::Identity()},
                 {"Neck", 0, Affine3f(Eigen::Translation3f(kNeckBase))},
                 {"Head", 2, Affine3f(Eigen::Translation3f(kHeadJoint - kNeckBase))}};
    rig.materials = {"scalp", "skin"};

    RigMesh m;
    m.name = "fold";
    m.node = 1;
    m.material = 0;
    for (const TriangleMesh* part : {&sphere, &neck}) {
        const uint32_t first = uint32_t(m.positions.size());
        m.positions.insert(m.positions.end(), part->positions.begin(), part->positions.end());
        m.normals.insert(m.normals.end(), part->normals.begin(), part->normals.end());
        m.uvs.insert(m.uvs.end(), part->uvs.begin(), part->uvs.end());
        for (const Tri& t : part->triangles) m.triangles.push_back({t[0] + first, t[1] + first, t[2] + first});
    }
    m.colors.assign(m.positions.size(), Eigen::Vector4f(1.f, 1.f, 1.f, 1.f));
    // Skin: the sphere follows the head bone; the neck blends from the neck
    // bone at its base to the head bone where it enters the sphere, so the
    // part of it inside the sphere stays buried whatever the head does.
    m.boneNodes = {2, 3};
    m.boneOffsets = {Affine3f(Eigen::Translation3f(-kNeckBase)), Affine3f(Eigen::Translation3f(-kHeadJoint))};
    m.influenceStart.push_back(0);
    for (size_t v = 0; v < m.positions.size(); ++v)
        appendNeckHeadInfluence(
            m, v < sphere.positions.size() ? 1.f : smoothstep(-0.15f, kHeadJoint.y(), m.positions[v].y()));
    rig.meshes.push_back(std::move(m));
    addClips(rig, o);
    return rig;
}

}  // namespace hp
