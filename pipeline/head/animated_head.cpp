#include "pipeline/head/animated_head.h"

#include "core/errors.h"

#include <Eigen/Geometry>

#include <cmath>

namespace hp {

namespace {

/// Vertices the rigid fit uses at most: the fit is exact with any subset for
/// rigid motion, and a few thousand points average a deforming surface well.
constexpr size_t kMaxFitVertices = 4096;

std::vector<uint32_t> thinned(std::vector<uint32_t> v) {
    if (v.size() <= kMaxFitVertices) return v;
    std::vector<uint32_t> out;
    out.reserve(kMaxFitVertices);
    for (size_t i = 0; i < kMaxFitVertices; ++i) out.push_back(v[i * v.size() / kMaxFitVertices]);
    return out;
}

/// Appends `from` (positions, normals, triangles) to `to`.
void appendMesh(TriangleMesh& to, const TriangleMesh& from) {
    const uint32_t base = uint32_t(to.positions.size());
    to.positions.insert(to.positions.end(), from.positions.begin(), from.positions.end());
    to.normals.insert(to.normals.end(), from.normals.begin(), from.normals.end());
    for (Tri t : from.triangles) to.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}

/// Appends a mesh collider at `place` (its skin's vertices when skinned) to
/// the pose's scenery, with area-weighted normals.
void addScenery(TriangleMesh& scenery, const ColliderShape& shape, const Eigen::Isometry3f& place,
                const std::vector<Vec3f>& skin) {
    TriangleMesh m;
    m.triangles = shape.triangles;
    for (const Vec3f& p : skin.empty() ? shape.points : skin) m.positions.push_back(place * p);
    m.computeNormals();
    appendMesh(scenery, m);
}

}  // namespace

const TriangleMesh& drawnMesh(const HeadPose& pose, TriangleMesh& storage) {
    if (pose.scenery.triangles.empty()) return pose.mesh;
    TriangleMesh& m = storage;
    m = pose.mesh;
    if (m.normals.size() != m.positions.size()) m.computeNormals();
    appendMesh(m, pose.scenery);
    if (!m.uvs.empty()) m.uvs.resize(m.positions.size(), Vec2f::Zero());
    return m;
}

Eigen::Isometry3f fitRigidTransform(const std::vector<Vec3f>& from, const std::vector<Vec3f>& to,
                                    const std::vector<uint32_t>& indices) {
    const size_t n = indices.empty() ? from.size() : indices.size();
    if (n == 0 || from.size() != to.size()) return Eigen::Isometry3f::Identity();
    Eigen::Matrix3Xd a(3, n), b(3, n);
    for (size_t k = 0; k < n; ++k) {
        const size_t i = indices.empty() ? k : indices[k];
        a.col(Eigen::Index(k)) = from[i].cast<double>();
        b.col(Eigen::Index(k)) = to[i].cast<double>();
    }
    // Umeyama (1991) without scaling is the Kabsch solution: SVD of the
    // cross-covariance, with the reflection case handled.
    const Eigen::Matrix4d m = Eigen::umeyama(a, b, false);
    Eigen::Isometry3f t = Eigen::Isometry3f::Identity();
    t.linear() = m.topLeftCorner<3, 3>().cast<float>();
    t.translation() = m.topRightCorner<3, 1>().cast<float>();
    return t;
}

AnimatedHead::AnimatedHead(std::shared_ptr<const HeadRig> rig, HeadAnimationSettings settings)
    : rig_(std::move(rig)), settings_(std::move(settings)) {
    if (!rig_ || rig_->meshes.empty()) throw Error("AnimatedHead: the rig has no mesh");
    if (settings_.clip >= int(rig_->clips.size())) throw Error("AnimatedHead: clip index out of range");
    rest_ = rig_->restMesh();         // the topology (triangles, uvs) every pose shares
    rest_ = posed(settings_.restTime);
    weld_ = weldVertices(rest_.positions);
    parts_ = partitionMesh(rest_, weld_);
    std::vector<uint32_t> all(rest_.positions.size());
    for (uint32_t i = 0; i < all.size(); ++i) all[i] = i;
    fitVertices_ = thinned(std::move(all));
    setPartFit(std::vector<uint8_t>(rest_.positions.size(), 1));
    if (!settings_.colliders.empty()) {
        std::vector<ColliderShape> shapes;
        for (const ExtraCollider& c : settings_.colliders) shapes.push_back(c.shape);
        world_ = std::make_shared<const CollisionWorld>(shapes);
    }
}

double AnimatedHead::clipTime(double time) const {
    double t = time * settings_.clipSpeed + settings_.clipOffset;
    if (settings_.loop && settings_.clip >= 0) {
        const double d = rig_->clips[size_t(settings_.clip)].duration;
        if (d > 0.0) t -= d * std::floor(t / d);
    }
    return t;
}

void AnimatedHead::setFitTriangles(const std::vector<uint8_t>& mask) {
    if (mask.size() != rest_.triangles.size())
        throw Error(cat("AnimatedHead: fit mask has ", mask.size(), " entries for ", rest_.triangles.size(),
                        " triangles"));
    std::vector<uint8_t> used(rest_.positions.size(), 0);
    for (size_t t = 0; t < mask.size(); ++t)
        if (mask[t])
            for (uint32_t v : rest_.triangles[t]) used[v] = 1;
    std::vector<uint32_t> vertices;
    for (uint32_t v = 0; v < used.size(); ++v)
        if (used[v]) vertices.push_back(v);
    if (vertices.size() >= 3) fitVertices_ = thinned(std::move(vertices));
    setPartFit(used);
}

void AnimatedHead::setPartFit(const std::vector<uint8_t>& fitVertex) {
    partFit_.clear();
    if (parts_.count() < 2) return;
    for (size_t k = 0; k < parts_.count(); ++k) {
        std::vector<uint32_t> fit;
        for (uint32_t v : parts_.vertices[k])
            if (fitVertex[v]) fit.push_back(v);
        // A part with no fit triangles (a neck under a scalp-only fit) is
        // fitted on all of its vertices.
        partFit_.push_back(thinned(fit.size() >= 3 ? std::move(fit) : parts_.vertices[k]));
    }
}

Eigen::Isometry3f AnimatedHead::partTransform(const TriangleMesh& mesh, size_t k) const {
    if (parts_.count() < 2) return fitRigidTransform(rest_.positions, mesh.positions, fitVertices_);
    if (k >= partFit_.size()) throw Error(cat("AnimatedHead: no part ", k, " (", partFit_.size(), " parts)"));
    return fitRigidTransform(rest_.positions, mesh.positions, partFit_[k]);
}

TriangleMesh AnimatedHead::posed(double time) const {
    TriangleMesh m;
    m.triangles = rest_.triangles;
    m.uvs = rest_.uvs;
    rig_->pose(settings_.clip, clipTime(time), m);
    if (settings_.motion) {
        const Eigen::Isometry3f a = settings_.motion(time);
        for (Vec3f& p : m.positions) p = a * p;
        for (Vec3f& n : m.normals) n = a.linear() * n;
    }
    return m;
}

std::shared_ptr<const LevelSet> AnimatedHead::restLevelSet() const {
    std::call_once(gridOnce_, [this] {
        grid_ = std::make_shared<const LevelSet>(rest_, settings_.levelSet);
        restExact_ = std::make_shared<const MeshCollider>(rest_, weld_);
        if (parts_.count() > 1)
            for (size_t k = 0; k < parts_.count(); ++k) {
                const TriangleMesh part = parts_.part(rest_, k);
                partGrids_.push_back(std::make_shared<const LevelSet>(part, settings_.levelSet));
                partExact_.push_back(std::make_shared<const MeshCollider>(part, parts_.welds[k]));
            }
    });
    return grid_;
}

std::shared_ptr<const MeshCollider> AnimatedHead::restCollider() const {
    restLevelSet();
    return restExact_;
}

std::shared_ptr<const Collider> AnimatedHead::headCollider(const HeadPose& pose) const {
    if (parts_.count() > 1 && settings_.collider != ColliderMethod::None) {
        // A head that folds into itself: one collider per part, joined as
        // their union (docs/colliders.md).
        if (settings_.collider == ColliderMethod::Rigid) restLevelSet();
        std::vector<std::shared_ptr<const Collider>> parts;
        for (size_t k = 0; k < parts_.count(); ++k) {
            if (settings_.collider == ColliderMethod::Rigid) {
                // Each part's grid rides its own rigid motion, not the
                // head's: the skinned neck stays while the head bone tips.
                // A part its rigid fit misses by more than half a voxel (a
                // neck bent over its blend) gets a grid of its posed mesh:
                // below that the carried grid errs no more than its own
                // trilinear interpolation does (≲ voxel/2 at sharp features).
                const Eigen::Isometry3f t = partTransform(pose.mesh, k);
                float miss = 0.f;
                for (uint32_t v : parts_.vertices[k])
                    miss = std::max(miss, (t * rest_.positions[v] - pose.mesh.positions[v]).norm());
                if (miss <= 0.5f * settings_.levelSet.voxelSize) {
                    parts.push_back(std::make_shared<LevelSetCollider>(partGrids_[k], t, partExact_[k]));
                    continue;
                }
            }
            const TriangleMesh part = parts_.part(pose.mesh, k);
            auto exact = std::make_shared<const MeshCollider>(part, parts_.welds[k]);
            if (settings_.collider == ColliderMethod::Exact) parts.push_back(std::move(exact));
            else
                parts.push_back(std::make_shared<LevelSetCollider>(
                    std::make_shared<const LevelSet>(part, settings_.levelSet), Eigen::Isometry3f::Identity(),
                    std::move(exact)));
        }
        return std::make_shared<PartsCollider>(std::move(parts));
    }
    switch (settings_.collider) {
        case ColliderMethod::Rigid:
            return std::make_shared<LevelSetCollider>(restLevelSet(), pose.transform, restCollider());
        case ColliderMethod::PerFrame:
            return std::make_shared<LevelSetCollider>(std::make_shared<const LevelSet>(pose.mesh, settings_.levelSet),
                                                      Eigen::Isometry3f::Identity(),
                                                      std::make_shared<const MeshCollider>(pose.mesh, weld_));
        case ColliderMethod::Exact: return std::make_shared<MeshCollider>(pose.mesh, weld_);
        case ColliderMethod::None: break;
    }
    return nullptr;
}

HeadPose AnimatedHead::sample(double time) const {
    HeadPose pose;
    pose.time = time;
    pose.mesh = posed(time);
    pose.transform = fitRigidTransform(rest_.positions, pose.mesh.positions, fitVertices_);
    pose.collider = headCollider(pose);
    if (world_) {
        std::vector<Eigen::Isometry3f> poses;
        std::vector<std::vector<Vec3f>> skins(settings_.colliders.size());
        for (size_t i = 0; i < settings_.colliders.size(); ++i) {
            const ExtraCollider& c = settings_.colliders[i];
            poses.push_back(c.followsHead ? pose.transform * c.place(time) : c.place(time));
            if (c.skin) skins[i] = c.skin->sample(time).mesh.positions;
            if (c.visible && !c.shape.triangles.empty()) addScenery(pose.scenery, c.shape, poses.back(), skins[i]);
        }
        pose.collider =
            std::make_shared<CompositeCollider>(std::move(pose.collider), world_->posed(poses, settings_.collidersBand, std::move(skins)));
    }
    return pose;
}

}  // namespace hp
