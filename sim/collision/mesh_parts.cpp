#include "sim/collision/mesh_parts.h"

#include "core/errors.h"
#include "core/union_find.h"
#include "sim/collision/mesh_collider.h"
#include "sim/collision/winding_number.h"

#include <limits>
#include <numeric>

namespace hp {

TriangleMesh MeshPartition::part(const TriangleMesh& mesh, size_t k) const {
    TriangleMesh m;
    const std::vector<uint32_t>& v = vertices[k];
    m.positions.reserve(v.size());
    for (uint32_t i : v) m.positions.push_back(mesh.positions[i]);
    if (mesh.normals.size() == mesh.positions.size())
        for (uint32_t i : v) m.normals.push_back(mesh.normals[i]);
    m.triangles = triangles[k];
    return m;
}

MeshPartition partitionMesh(const TriangleMesh& mesh, const std::vector<uint32_t>& weld) {
    if (weld.size() != mesh.positions.size())
        throw Error(cat("partitionMesh: weld map has ", weld.size(), " entries for ", mesh.positions.size(), " vertices"));
    // Union-find over welded vertices: a triangle joins its three corners.
    UnionFind sets(mesh.positions.size());
    for (const Tri& t : mesh.triangles) {
        sets.unite(weld[t[0]], weld[t[1]]);
        sets.unite(weld[t[0]], weld[t[2]]);
    }
    MeshPartition out;
    out.triangleParts.resize(mesh.triangles.size());
    std::vector<uint32_t> partOfRoot(mesh.positions.size(), std::numeric_limits<uint32_t>::max());
    std::vector<uint32_t> local(mesh.positions.size(), std::numeric_limits<uint32_t>::max());
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        const Tri& tri = mesh.triangles[t];
        uint32_t& k = partOfRoot[sets.find(weld[tri[0]])];
        if (k == std::numeric_limits<uint32_t>::max()) {
            k = uint32_t(out.vertices.size());
            out.vertices.emplace_back();
            out.triangles.emplace_back();
        }
        out.triangleParts[t] = k;
    }
    // Each part's vertices ascending, then its triangles over local indices.
    for (uint32_t v = 0; v < mesh.positions.size(); ++v) {
        const uint32_t k = partOfRoot[sets.find(weld[v])];
        if (k == std::numeric_limits<uint32_t>::max()) continue;  // a vertex no triangle uses
        local[v] = uint32_t(out.vertices[k].size());
        out.vertices[k].push_back(v);
    }
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        const Tri& tri = mesh.triangles[t];
        out.triangles[out.triangleParts[t]].push_back({local[tri[0]], local[tri[1]], local[tri[2]]});
    }
    out.welds.resize(out.count());
    for (size_t k = 0; k < out.count(); ++k)
        for (uint32_t v : out.vertices[k]) out.welds[k].push_back(local[weld[v]]);
    return out;
}

PartsCollider::PartsCollider(std::vector<std::shared_ptr<const Collider>> parts) : parts_(std::move(parts)) {
    if (parts_.empty()) throw Error("PartsCollider: no parts");
}

float PartsCollider::signedDistance(const Vec3f& p, Vec3f* normal) const {
    return signedDistanceIgnoring(p, normal, 0u);
}

float PartsCollider::signedDistanceIgnoring(const Vec3f& p, Vec3f* normal, uint32_t ignoreParts) const {
    // Union of the parts kept: φ = min_k φ_k, the normal of the part that
    // gives it. Parts in a fixed order, so ties resolve alike on every thread.
    float best = std::numeric_limits<float>::infinity();
    Vec3f n = Vec3f::UnitY();
    for (size_t k = 0; k < parts_.size(); ++k) {
        if (k < kMaxIgnoredParts && (ignoreParts >> k) & 1u) continue;
        Vec3f nk;
        const float d = parts_[k]->signedDistance(p, normal ? &nk : nullptr);
        if (d < best) best = d, n = nk;
    }
    if (normal) *normal = n;
    return best;
}

bool buriedByOwnPart(const TriangleMesh& part, const MeshQuery& query, const TriangleMesh& mesh,
                     const SurfacePoint& root) {
    const Tri& t = mesh.triangles[root.triangle];
    const Vec3f a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
    const Vec3f n = (b - a).cross(c - a);
    if (!(n.norm() > 0.f)) return false;  // a degenerate triangle has no outside to test
    const Vec3f up = n.normalized();
    const Vec3f q = evaluate(mesh, root).position + kBuriedRootOffset * up;
    return windingNumber(part, query, q, up) > 0.5;
}

std::vector<uint32_t> partsAroundRoots(const MeshPartition& partition, const TriangleMesh& mesh,
                                       const std::vector<SurfacePoint>& roots, float tolerance) {
    std::vector<uint32_t> masks(roots.size(), 0u);
    if (partition.count() < 2) return masks;
    // Each part as posed, kept for the winding numbers of the roots' own
    // parts, and its exact collider.
    std::vector<TriangleMesh> posed;
    std::vector<std::unique_ptr<MeshCollider>> parts;
    for (size_t k = 0; k < std::min<size_t>(partition.count(), kMaxIgnoredParts); ++k) {
        posed.push_back(partition.part(mesh, k));
        parts.push_back(std::make_unique<MeshCollider>(posed.back(), partition.welds[k]));
    }
    for (size_t r = 0; r < roots.size(); ++r) {
        const uint32_t own = partition.triangleParts[roots[r].triangle];
        const Vec3f p = evaluate(mesh, roots[r]).position;
        for (size_t k = 0; k < parts.size(); ++k)
            if (k != own && parts[k]->signedDistance(p) < -tolerance) masks[r] |= 1u << k;
        if (own < parts.size() && buriedByOwnPart(posed[own], parts[own]->query(), mesh, roots[r]))
            masks[r] |= 1u << own;
    }
    return masks;
}

}  // namespace hp
