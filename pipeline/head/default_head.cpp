#include "pipeline/head/default_head.h"

#include <algorithm>
#include <cmath>

namespace hp {

namespace {

constexpr float kPi = float(M_PI);

/// Ellipsoid distance estimate (Quílez): exact on the surface, smooth and
/// monotone off it, which is all the ray marching and blending need.
float ellipsoid(const Vec3f& p, const Vec3f& c, const Vec3f& r) {
    const Vec3f q = p - c;
    const float k0 = q.cwiseQuotient(r).norm();
    const float k1 = q.cwiseQuotient(r.cwiseProduct(r)).norm();
    return k1 > 0.f ? k0 * (k0 - 1.f) / k1 : -r.minCoeff();
}

/// Polynomial smooth minimum (blend radius k): rounds the joins between parts.
float smin(float a, float b, float k) {
    const float h = std::clamp(0.5f + 0.5f * (b - a) / k, 0.f, 1.f);
    return b + (a - b) * h - k * h * (1.f - h);
}

const Vec3f kSkull(0.f, 0.015f, -0.01f), kSkullRadii(0.075f, 0.092f, 0.098f);
const Vec3f kEarRadii(0.012f, 0.027f, 0.017f);
const Vec3f kNeckJoint(0.f, -0.235f, -0.018f);  // world bind positions: the neck pivots at its base
const Vec3f kHeadJoint(0.f, -0.035f, -0.015f);
const Vec3f kChest(0.f, -0.27f, -0.03f);  // centre of the shoulders' trapezius-and-chest ellipsoid, and its bone

/// Hairline height above which the scalp starts, by angle from the front.
float hairline(float angle) {
    static const float table[][2] = {{0.f, 0.055f}, {0.9f, 0.045f}, {1.35f, 0.02f},
                                     {1.75f, 0.0f}, {2.3f, -0.05f}, {kPi, -0.075f}};
    for (int i = 1; i < 6; ++i)
        if (angle <= table[i][0]) {
            const float t = (angle - table[i - 1][0]) / (table[i][0] - table[i - 1][0]);
            return table[i - 1][1] + t * (table[i][1] - table[i - 1][1]);
        }
    return table[5][1];
}

/// The clip's total head rotation (degrees) at time t: nods, shakes, a fast
/// turn, then stillness.
void headAngles(double t, double& pitch, double& yaw) {
    const double twoPi = 2.0 * M_PI;
    pitch = yaw = 0.0;
    if (t >= 0.25 && t <= 1.25) pitch = 20.0 * std::sin(twoPi * (t - 0.25) / 0.5);  // two nods
    if (t >= 1.4 && t <= 2.4) yaw = 35.0 * std::sin(twoPi * (t - 1.4) / 0.5);       // two shakes
    if (t > 2.55) yaw = 75.0 * smoothstep(0.f, 1.f, float((t - 2.55) / 0.3));      // fast turn, ~375°/s peak
}

/// The stress clip (seconds, degrees): the head tips back 70° in 0.25 s
/// and forward again (the nape folds onto the neck: hair there is pinched),
/// turns 180° in 0.3 s, holds, and at kStressCut cuts to a pose looking
/// down and to the side.
void stressAngles(double t, double& pitch, double& yaw) {
    pitch = yaw = 0.0;
    if (t < kStressCut) {
        if (t >= 0.25 && t < 0.5) pitch = -70.0 * smoothstep(0.f, 1.f, float((t - 0.25) / 0.25));
        if (t >= 0.5 && t < 0.75) pitch = -70.0 * (1.0 - smoothstep(0.f, 1.f, float((t - 0.5) / 0.25)));
        if (t > 1.0) yaw = 180.0 * smoothstep(0.f, 1.f, float((t - 1.0) / 0.3));
    } else {
        pitch = 25.0;
        yaw = -40.0;
    }
}

/// A clip keyed at `times` from an angle function: the neck bone takes 40 %
/// of the rotation, the head bone the rest.
RigClip headClip(const HeadRig& rig, const char* name, double duration, double keyRate,
                 const std::vector<double>& times, void (*angles)(double, double&, double&)) {
    RigClip clip;
    clip.name = name;
    clip.duration = duration;
    clip.keyRate = keyRate;
    for (int node : {3, 4}) {
        NodeTrack t;
        t.node = node;
        const double share = node == 3 ? 0.4 : 0.6;
        t.translation.times = {0.0};
        t.translation.values = {rig.nodes[size_t(node)].local.translation()};
        t.scale.times = {0.0};
        t.scale.values = {Vec3f::Ones()};
        for (const double time : times) {
            double pitch, yaw;
            angles(time, pitch, yaw);
            const float toRad = float(M_PI / 180.0 * share);
            t.rotation.times.push_back(time);
            t.rotation.values.push_back(Eigen::Quaternionf(Eigen::AngleAxisf(float(yaw) * toRad, Vec3f::UnitY()) *
                                                           Eigen::AngleAxisf(float(pitch) * toRad, Vec3f::UnitX())));
        }
        clip.tracks.push_back(std::move(t));
    }
    return clip;
}

/// The two clips of DefaultHeadOptions on a rig whose nodes 3 and 4 are
/// the Neck and Head bones.
void addClips(HeadRig& rig, const DefaultHeadOptions& o) {
    std::vector<double> times;
    for (int k = 0; k <= int(std::lround(kDefaultHeadClipSeconds * o.keyRate)); ++k) times.push_back(k / o.keyRate);
    rig.clips.push_back(headClip(rig, "nod_shake_turn", kDefaultHeadClipSeconds, o.keyRate, times, headAngles));
    // The stress clip's cut: the pose before it is held until 1 ms before.
    times.clear();
    for (int k = 0; k <= int(std::lround(kStressClipSeconds * o.keyRate)); ++k) {
        const double t = k / o.keyRate;
        if (t >= kStressCut && times.back() < kStressCut) times.push_back(kStressCut - 1e-3);
        times.push_back(t);
    }
    rig.clips.push_back(headClip(rig, "stress", kStressClipSeconds, o.keyRate, times, stressAngles));
}

}  // namespace

float defaultHeadField(const Vec3f& p) {
    float f = ellipsoid(p, kSkull, kSkullRadii);
    f = smin(f, ellipsoid(p, Vec3f(0.f, -0.045f, 0.018f), Vec3f(0.058f, 0.065f, 0.075f)), 0.02f);  // jaw and face
    f = smin(f, ellipsoid(p, Vec3f(0.f, -0.015f, 0.088f), Vec3f(0.011f, 0.022f, 0.016f)), 0.008f);  // nose
    for (float side : {-1.f, 1.f})
        f = smin(f, ellipsoid(p, Vec3f(side * 0.074f, -0.01f, -0.008f), kEarRadii), 0.006f);  // ears
    const float radial = Eigen::Vector2f(p.x(), p.z() + 0.018f).norm() - 0.05f;
    const float neck = std::max(radial, std::max(-0.24f - p.y(), p.y() + 0.02f));
    return smin(f, neck, 0.025f);
}

float defaultHeadHairMask(const Vec3f& p) {
    for (float side : {-1.f, 1.f})
        if ((p - Vec3f(side * 0.074f, -0.01f, -0.008f)).cwiseQuotient(1.4f * kEarRadii).norm() < 1.f) return 0.f;
    const float angle = std::abs(std::atan2(p.x(), p.z() - kSkull.z()));
    return std::clamp((p.y() - hairline(angle)) / 0.01f + 0.5f, 0.f, 1.f);
}

namespace {

/// The outermost surface of `field` (negative inside) as a UV sphere's
/// directions from `centre` see it: each direction is marched inward from
/// 0.45 m to the first point inside, then bisected. Normals: the field's
/// gradient.
void marchSurface(float (*field)(const Vec3f&), const Vec3f& centre, const TriangleMesh& dirs,
                  std::vector<Vec3f>& positions, std::vector<Vec3f>& normals) {
    positions.resize(dirs.positions.size());
    normals.resize(dirs.positions.size());
    for (size_t i = 0; i < dirs.positions.size(); ++i) {
        const Vec3f d = dirs.positions[i];
        float outside = 0.45f, inside = outside;
        while (inside > 0.f && field(centre + inside * d) > 0.f) inside -= 0.001f;
        outside = inside + 0.001f;
        for (int k = 0; k < 40; ++k) {
            const float mid = 0.5f * (inside + outside);
            (field(centre + mid * d) > 0.f ? outside : inside) = mid;
        }
        const Vec3f p = centre + inside * d;
        positions[i] = p;
        const float h = 1e-4f;
        const Vec3f g(field(p + h * Vec3f::UnitX()) - field(p - h * Vec3f::UnitX()),
                      field(p + h * Vec3f::UnitY()) - field(p - h * Vec3f::UnitY()),
                      field(p + h * Vec3f::UnitZ()) - field(p - h * Vec3f::UnitZ()));
        normals[i] = g.norm() > 0.f ? Vec3f(g.normalized()) : d;
    }
}

}  // namespace

HeadRig makeDefaultHead(const DefaultHeadOptions& o) {
    // Star-shaped about a point inside skull, jaw and neck.
    const TriangleMesh dirs = makeSphereMesh(Vec3f::Zero(), 1.f, o.rings, o.sectors);
    std::vector<Vec3f> positions, normals;
    marchSurface(defaultHeadField, Vec3f(0.f, -0.05f, -0.012f), dirs, positions, normals);

    HeadRig rig;
    rig.file = "default head";
    // One node per mesh, so the glTF keeps the two meshes (and their names)
    // apart instead of merging them into primitives of one mesh.
    rig.nodes = {{"HeadRig", -1, Affine3f::Identity()},
                 {"Scalp", 0, Affine3f::Identity()},
                 {"Skin", 0, Affine3f::Identity()},
                 {"Neck", 0, Affine3f(Eigen::Translation3f(kNeckJoint))},
                 {"Head", 3, Affine3f(Eigen::Translation3f(kHeadJoint - kNeckJoint))}};
    rig.materials = {"scalp", "skin"};

    // Two meshes, one per material: a triangle is scalp when its centroid is
    // above the hairline. Each keeps its own copy of the shared vertices.
    for (uint32_t material : {0u, 1u}) {
        RigMesh m;
        m.name = material == 0 ? "scalp" : "skin";
        m.instance = int(material);
        m.node = 1 + int(material);
        m.material = material;
        m.boneNodes = {3, 4};
        m.boneOffsets = {Affine3f(Eigen::Translation3f(-kNeckJoint)), Affine3f(Eigen::Translation3f(-kHeadJoint))};
        std::vector<int64_t> local(positions.size(), -1);
        for (const Tri& t : dirs.triangles) {
            const Vec3f c = (positions[t[0]] + positions[t[1]] + positions[t[2]]) / 3.f;
            if ((defaultHeadHairMask(c) > 0.5f) != (material == 0)) continue;
            Tri out;
            for (int k = 0; k < 3; ++k) {
                const uint32_t v = t[k];
                if (local[v] < 0) {
                    local[v] = int64_t(m.positions.size());
                    m.positions.push_back(positions[v]);
                    m.normals.push_back(normals[v]);
                    m.uvs.push_back(dirs.uvs[v]);
                    const float hair = defaultHeadHairMask(positions[v]);
                    m.colors.emplace_back(hair, hair, hair, 1.f);
                }
                out[k] = uint32_t(local[v]);
            }
            m.triangles.push_back(out);
        }
        // The head bone carries everything above the jaw, the neck bone the
        // base of the neck, blended smoothly in between.
        m.influenceStart.push_back(0);
        for (const Vec3f& p : m.positions) appendNeckHeadInfluence(m, smoothstep(-0.15f, -0.05f, p.y()));
        rig.meshes.push_back(std::move(m));
    }

    addClips(rig, o);
    return rig;
}

float defaultBodyField(const Vec3f& p) {
    // Trapezius and chest: a wide, flat ellipsoid whose top slopes from the
    // neck (y -0.14 beside it) to the shoulder (-0.2 at x ±0.17); deltoid
    // caps round the shoulders; cut flat at mid-chest. Heights from an
    // adult of 1.75 m: the neck-shoulder point ~0.25 m under the top of the
    // head (0.107 here), the acromion ~0.3 m.
    float f = ellipsoid(p, kChest, Vec3f(0.2f, 0.135f, 0.11f));
    for (float side : {-1.f, 1.f})
        f = smin(f, ellipsoid(p, Vec3f(side * 0.165f, -0.24f, -0.03f), Vec3f(0.055f, 0.05f, 0.055f)), 0.03f);
    return std::max(f, -0.4f - p.y());
}

HeadRig makeDefaultBody(const DefaultHeadOptions& o) {
    const TriangleMesh dirs = makeSphereMesh(Vec3f::Zero(), 1.f, o.rings, o.sectors);
    RigMesh m;
    marchSurface(defaultBodyField, kChest, dirs, m.positions, m.normals);
    m.name = "shoulders";
    m.node = 1;
    m.material = 1;  // skin
    m.uvs = dirs.uvs;
    m.triangles = dirs.triangles;
    m.colors.assign(m.positions.size(), Eigen::Vector4f(0.f, 0.f, 0.f, 1.f));  // no hair grows here
    // The chest bone carries the body; skin next to the neck follows the
    // neck bone halfway, as a trapezius does when the head tips.
    m.boneNodes = {2, 3};
    m.boneOffsets = {Affine3f(Eigen::Translation3f(-kChest)), Affine3f(Eigen::Translation3f(-kNeckJoint))};
    m.influenceStart.push_back(0);
    for (const Vec3f& p : m.positions) {
        const float radial = Eigen::Vector2f(p.x(), p.z() - kNeckJoint.z()).norm();
        const float neck = 0.5f * (1.f - smoothstep(0.05f, 0.09f, radial)) * smoothstep(-0.19f, -0.14f, p.y());
        m.influenceBone.push_back(0), m.influenceWeight.push_back(1.f - neck);
        if (neck > 0.f) m.influenceBone.push_back(1), m.influenceWeight.push_back(neck);
        m.influenceStart.push_back(uint32_t(m.influenceBone.size()));
    }
    HeadRig rig;
    rig.file = "default body";
    // Nodes 3 and 4 are the head's Neck and Head bones (same places, same clips).
    rig.nodes = {{"BodyRig", -1, Affine3f::Identity()},
                 {"Shoulders", 0, Affine3f::Identity()},
                 {"Chest", 0, Affine3f(Eigen::Translation3f(kChest))},
                 {"Neck", 0, Affine3f(Eigen::Translation3f(kNeckJoint))},
                 {"Head", 3, Affine3f(Eigen::Translation3f(kHeadJoint - kNeckJoint))}};
    rig.materials = {"scalp", "skin"};
    rig.meshes.push_back(std::move(m));
    addClips(rig, o);
    return rig;
}

float smoothstep(float e0, float e1, float x) {
    const float t = std::clamp((x - e0) / (e1 - e0), 0.f, 1.f);
    return t * t * (3.f - 2.f * t);
}

void appendNeckHeadInfluence(RigMesh& m, float head) {
    if (head < 1.f) m.influenceBone.push_back(0), m.influenceWeight.push_back(1.f - head);
    if (head > 0.f) m.influenceBone.push_back(1), m.influenceWeight.push_back(head);
    m.influenceStart.push_back(uint32_t(m.influenceBone.size()));
}

}  // namespace hp
