#include "pipeline/head/head_rig.h"

#include "core/errors.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <iomanip>
#include <set>
#include <sstream>

namespace hp {

namespace {

/// Linear key interpolation, held outside the key range.
template <typename T, typename Lerp>
T sampleKeys(const KeyTrack<T>& k, double t, Lerp lerp) {
    if (k.times.size() == 1 || t <= k.times.front()) return k.values.front();
    if (t >= k.times.back()) return k.values.back();
    const size_t i = size_t(std::upper_bound(k.times.begin(), k.times.end(), t) - k.times.begin());
    const double a = (t - k.times[i - 1]) / (k.times[i] - k.times[i - 1]);
    return lerp(k.values[i - 1], k.values[i], float(a));
}

Vec3f lerpVec(const Vec3f& a, const Vec3f& b, float t) { return a + t * (b - a); }
Eigen::Quaternionf slerpQuat(const Eigen::Quaternionf& a, const Eigen::Quaternionf& b, float t) {
    return a.slerp(t, b).normalized();  // Eigen's slerp takes the shorter arc
}

/// det(A) · A⁻ᵀ: transforms normals (also under non-uniform scale) and
/// keeps them consistent with the transformed triangles' winding.
Eigen::Matrix3f cofactor(const Eigen::Matrix3f& a) {
    Eigen::Matrix3f c;
    c.col(0) = a.col(1).cross(a.col(2));
    c.col(1) = a.col(2).cross(a.col(0));
    c.col(2) = a.col(0).cross(a.col(1));
    return c;
}

Vec3f unit(const Vec3f& n) {
    const float len = n.norm();
    return len > 0.f ? Vec3f(n / len) : Vec3f::UnitY();
}

}  // namespace

size_t HeadRig::vertexCount() const {
    size_t n = 0;
    for (const RigMesh& m : meshes) n += m.positions.size();
    return n;
}

size_t HeadRig::triangleCount() const {
    size_t n = 0;
    for (const RigMesh& m : meshes) n += m.triangles.size();
    return n;
}

size_t HeadRig::boneCount() const {
    std::set<int> bones;
    for (const RigMesh& m : meshes) bones.insert(m.boneNodes.begin(), m.boneNodes.end());
    return bones.size();
}

size_t HeadRig::morphCount() const {
    size_t n = 0;
    for (const RigMesh& m : meshes) n += m.morphPositions.size();
    return n;
}

bool HeadRig::hasUvs() const {
    return std::any_of(meshes.begin(), meshes.end(), [](const RigMesh& m) { return !m.uvs.empty(); });
}

bool HeadRig::hasColors() const {
    return std::any_of(meshes.begin(), meshes.end(), [](const RigMesh& m) { return !m.colors.empty(); });
}

std::vector<Affine3f> HeadRig::nodeTransforms(int clip, double seconds) const {
    std::vector<const NodeTrack*> trackOf(nodes.size(), nullptr);
    if (clip >= 0)
        for (const NodeTrack& t : clips.at(size_t(clip)).tracks)
            if (t.node >= 0 && size_t(t.node) < nodes.size() && !trackOf[size_t(t.node)]) trackOf[size_t(t.node)] = &t;
    std::vector<Affine3f> world(nodes.size());
    for (size_t i = 0; i < nodes.size(); ++i) {
        Affine3f local = nodes[i].local;
        if (const NodeTrack* t = trackOf[i]) {
            // Channels a file leaves out keep the rest value.
            Eigen::Matrix3f restRotation, restScale;
            nodes[i].local.computeRotationScaling(&restRotation, &restScale);
            const Vec3f tr = t->translation.times.empty() ? Vec3f(nodes[i].local.translation())
                                                          : sampleKeys(t->translation, seconds, lerpVec);
            const Eigen::Quaternionf r = t->rotation.times.empty() ? Eigen::Quaternionf(restRotation)
                                                                   : sampleKeys(t->rotation, seconds, slerpQuat);
            const Eigen::Matrix3f s = t->scale.times.empty()
                                          ? restScale
                                          : Eigen::Matrix3f(sampleKeys(t->scale, seconds, lerpVec).asDiagonal());
            local = Affine3f::Identity();
            local.translate(tr);
            local.linear() = r.toRotationMatrix() * s;
        }
        const int p = nodes[i].parent;
        world[i] = (p >= 0 ? world[size_t(p)] : placement) * local;
    }
    return world;
}

TriangleMesh HeadRig::restMesh() const {
    TriangleMesh m;
    for (const RigMesh& r : meshes) {
        const uint32_t base = uint32_t(m.uvs.size());
        for (const Tri& t : r.triangles) m.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
        if (r.uvs.empty()) m.uvs.resize(m.uvs.size() + r.positions.size(), Vec2f::Zero());
        else m.uvs.insert(m.uvs.end(), r.uvs.begin(), r.uvs.end());
    }
    if (!hasUvs()) m.uvs.clear();
    pose(-1, 0.0, m);
    return m;
}

void HeadRig::pose(int clip, double seconds, TriangleMesh& out) const {
    const std::vector<Affine3f> world = nodeTransforms(clip, seconds);
    const size_t total = vertexCount();
    out.positions.resize(total);
    out.normals.resize(total);
    bool missingNormals = false;
    size_t base = 0;
    for (const RigMesh& m : meshes) {
        // Morph weights: the mesh's defaults unless the clip drives its node.
        std::vector<float> weights = m.morphDefaults;
        weights.resize(m.morphPositions.size(), 0.f);
        if (clip >= 0)
            for (const MorphTrack& t : clips[size_t(clip)].morphs) {
                if (t.node != m.node || t.times.empty()) continue;
                KeyTrack<float> k;
                k.times = t.times;
                for (size_t w = 0; w < weights.size(); ++w) {
                    k.values.clear();
                    for (const auto& key : t.weights) k.values.push_back(w < key.size() ? key[w] : 0.f);
                    weights[w] = sampleKeys(k, seconds, [](float a, float b, float x) { return a + x * (b - a); });
                }
                break;
            }
        std::vector<std::pair<size_t, float>> active;
        for (size_t w = 0; w < weights.size(); ++w)
            if (weights[w] != 0.f) active.emplace_back(w, weights[w]);

        // Bone matrices B_b = world(bone) · offset_b, as 3×4 blocks.
        std::vector<Eigen::Matrix<float, 3, 4>> bones(m.boneNodes.size());
        for (size_t b = 0; b < bones.size(); ++b)
            bones[b] = (world[size_t(m.boneNodes[b])] * m.boneOffsets[b]).matrix().topRows<3>();
        const Affine3f rigid = world[size_t(m.node)];
        const Eigen::Matrix3f rigidNormal = cofactor(rigid.linear());
        const bool hasNormals = m.normals.size() == m.positions.size();
        missingNormals |= !hasNormals;

        tbb::parallel_for(tbb::blocked_range<size_t>(0, m.positions.size(), 2048), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t v = r.begin(); v != r.end(); ++v) {
                Vec3f p = m.positions[v];
                Vec3f n = hasNormals ? m.normals[v] : Vec3f::Zero();
                for (const auto& [t, w] : active) {
                    p += w * m.morphPositions[t][v];
                    if (!m.morphNormals[t].empty()) n += w * m.morphNormals[t][v];
                }
                const uint32_t begin = m.skinned() ? m.influenceStart[v] : 0, end = m.skinned() ? m.influenceStart[v + 1] : 0;
                if (begin == end) {
                    out.positions[base + v] = rigid * p;
                    out.normals[base + v] = unit(rigidNormal * n);
                    continue;
                }
                // Linear blend skinning: x' = (Σ w_i B_i) x.
                Eigen::Matrix<float, 3, 4> a = m.influenceWeight[begin] * bones[m.influenceBone[begin]];
                for (uint32_t i = begin + 1; i < end; ++i) a += m.influenceWeight[i] * bones[m.influenceBone[i]];
                out.positions[base + v] = a.leftCols<3>() * p + a.col(3);
                out.normals[base + v] = unit(cofactor(a.leftCols<3>()) * n);
            }
        });
        base += m.positions.size();
    }
    if (missingNormals && out.triangles.size() == triangleCount()) out.computeNormals();
}

std::vector<uint32_t> HeadRig::triangleMaterials() const {
    std::vector<uint32_t> mats;
    for (const RigMesh& m : meshes) mats.insert(mats.end(), m.triangles.size(), m.material);
    return mats;
}

std::vector<Eigen::Vector4f> HeadRig::vertexColors() const {
    std::vector<Eigen::Vector4f> colors;
    for (const RigMesh& m : meshes) {
        if (m.colors.empty()) colors.insert(colors.end(), m.positions.size(), Eigen::Vector4f::Ones());
        else colors.insert(colors.end(), m.colors.begin(), m.colors.end());
    }
    return colors;
}

std::string HeadRig::summary() const {
    std::ostringstream s;
    s << std::fixed << std::setprecision(2);
    s << "  file:      " << file << "\n";
    s << "  meshes:    " << meshes.size() << "\n";
    for (const RigMesh& m : meshes) {
        s << "    " << m.instance << ": " << m.name << ", " << m.triangles.size() << " triangles";
        if (m.material < materials.size() && !materials[m.material].empty()) s << ", material " << materials[m.material];
        if (m.skinned()) s << ", skinned";
        if (!m.morphNames.empty()) s << ", " << m.morphNames.size() << " morph targets";
        s << "\n";
    }
    s << "  triangles: " << triangleCount() << ", vertices: " << vertexCount() << "\n";
    size_t skinned = 0, morphed = 0;
    for (const RigMesh& m : meshes) skinned += m.skinned(), morphed += !m.morphPositions.empty();
    s << "  bones:     " << boneCount() << " (" << skinned << " skinned mesh" << (skinned == 1 ? "" : "es") << ")\n";
    s << "  morphs:    " << morphCount() << " targets on " << morphed << " mesh" << (morphed == 1 ? "" : "es") << "\n";
    s << std::defaultfloat << std::setprecision(6) << "  unit:      " << unitScale << " m per file unit ("
      << (fileUnitScale > 0 ? cat("the file declares ", fileUnitScale, " m") : std::string("the file declares none"))
      << "; head.unit_scale overrides)\n" << std::fixed;
    s << "  up axis:   " << upAxis << " ("
      << (fileUpAxis ? std::string("the file declares ") + fileUpAxis : std::string("the file declares none"))
      << "; head.up_axis overrides)\n";
    const Eigen::AlignedBox3f box = restMesh().bounds();
    s << std::setprecision(3) << "  bounds:    [" << box.min().transpose() << "] - [" << box.max().transpose()
      << "] m (rest pose, after unit scale and up axis)\n";
    s << std::setprecision(2) << "  clips:     " << clips.size() << "\n";
    for (size_t i = 0; i < clips.size(); ++i)
        s << "    " << i << ": " << (clips[i].name.empty() ? "(unnamed)" : clips[i].name) << ", " << clips[i].duration
          << " s, " << clips[i].keyRate << " fps, " << clips[i].tracks.size() << " node tracks, "
          << clips[i].morphs.size() << " morph tracks\n";
    return s.str();
}

}  // namespace hp
