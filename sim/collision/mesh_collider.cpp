#include "sim/collision/mesh_collider.h"

#include "core/errors.h"
#include "core/union_find.h"

#include <algorithm>
#include <array>
#include <map>
#include <cmath>
#include <numeric>
#include <tuple>

namespace hp {

std::vector<uint32_t> weldVertices(const std::vector<Vec3f>& positions, float tolerance) {
    const size_t n = positions.size();
    UnionFind sets(n);  // the root of a set is its lowest index
    if (n == 0) return {};
    Eigen::AlignedBox3f box;
    for (const Vec3f& p : positions) box.extend(p);
    const float eps = std::max(tolerance * box.diagonal().norm(), std::numeric_limits<float>::min());
    // A hash grid of cell size eps: copies lie in the same or a neighbouring cell.
    auto cellOf = [&](const Vec3f& p) {
        const Vec3f c = ((p - box.min()) / eps).array().floor();
        return std::array<int64_t, 3>{int64_t(c.x()), int64_t(c.y()), int64_t(c.z())};
    };
    std::map<std::array<int64_t, 3>, std::vector<uint32_t>> cells;
    for (uint32_t i = 0; i < n; ++i) cells[cellOf(positions[i])].push_back(i);
    for (const auto& [cell, members] : cells)
        for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dz = -1; dz <= 1; ++dz) {
                    const auto it = cells.find({cell[0] + dx, cell[1] + dy, cell[2] + dz});
                    if (it == cells.end()) continue;
                    for (uint32_t i : members)
                        for (uint32_t j : it->second)
                            if (i < j && (positions[i] - positions[j]).norm() <= eps) sets.unite(i, j);
                }
    return sets.roots();
}

MeshCollider::MeshCollider(const TriangleMesh& mesh, std::vector<uint32_t> weld)
    : query_(mesh), weld_(std::move(weld)) {
    if (weld_.empty()) weld_ = weldVertices(mesh.positions);
    if (weld_.size() != mesh.positions.size())
        throw Error(cat("MeshCollider: weld map has ", weld_.size(), " entries for ", mesh.positions.size(),
                        " vertices"));
    const size_t nt = mesh.triangles.size();
    faceNormals_.resize(nt);
    vertexNormals_.assign(mesh.positions.size(), Vec3f::Zero());
    for (size_t t = 0; t < nt; ++t) {
        const Tri& tri = mesh.triangles[t];
        const Vec3f& a = mesh.positions[tri[0]];
        const Vec3f& b = mesh.positions[tri[1]];
        const Vec3f& c = mesh.positions[tri[2]];
        const Vec3f n = (b - a).cross(c - a);
        faceNormals_[t] = n.norm() > 0.f ? Vec3f(n.normalized()) : Vec3f::Zero();
        // Angle-weighted vertex pseudonormal: Σ α_i n_i over incident faces.
        const Vec3f* p[3] = {&a, &b, &c};
        for (int k = 0; k < 3; ++k) {
            const Vec3f e1 = *p[(k + 1) % 3] - *p[k], e2 = *p[(k + 2) % 3] - *p[k];
            const float angle = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
            vertexNormals_[weld_[tri[k]]] += angle * faceNormals_[t];
        }
    }
    // Edge pseudonormal: the sum of the (one or two) faces sharing the welded
    // edge. Sorting the edges by their welded corners groups them.
    struct EdgeRef {
        uint32_t u, v, tri, edge;
    };
    std::vector<EdgeRef> edges;
    edges.reserve(3 * nt);
    for (uint32_t t = 0; t < nt; ++t)
        for (uint32_t e = 0; e < 3; ++e) {
            uint32_t u = weld_[mesh.triangles[t][e]], v = weld_[mesh.triangles[t][(e + 1) % 3]];
            if (u > v) std::swap(u, v);
            edges.push_back({u, v, t, e});
        }
    std::sort(edges.begin(), edges.end(), [](const EdgeRef& a, const EdgeRef& b) {
        return std::tie(a.u, a.v, a.tri, a.edge) < std::tie(b.u, b.v, b.tri, b.edge);
    });
    edgeNormals_.resize(nt);
    for (size_t k = 0; k < edges.size();) {
        size_t end = k;
        Vec3f sum = Vec3f::Zero();
        while (end < edges.size() && edges[end].u == edges[k].u && edges[end].v == edges[k].v)
            sum += faceNormals_[edges[end++].tri];
        for (size_t j = k; j < end; ++j) edgeNormals_[edges[j].tri][edges[j].edge] = sum;
        k = end;
    }
}

MeshPoint MeshCollider::closest(const Vec3f& p, float* signedDistance) const {
    const MeshPoint c = query_.closest(p);
    if (!signedDistance || !c.found()) return c;
    const Tri& tri = query_.triangle(c.point.triangle);
    Vec3f pseudo;
    switch (c.feature) {
        case TriangleFeature::Face: pseudo = faceNormals_[c.point.triangle]; break;
        case TriangleFeature::EdgeAB: pseudo = edgeNormals_[c.point.triangle][0]; break;
        case TriangleFeature::EdgeBC: pseudo = edgeNormals_[c.point.triangle][1]; break;
        case TriangleFeature::EdgeCA: pseudo = edgeNormals_[c.point.triangle][2]; break;
        case TriangleFeature::VertexA: pseudo = vertexNormals_[weld_[tri[0]]]; break;
        case TriangleFeature::VertexB: pseudo = vertexNormals_[weld_[tri[1]]]; break;
        default: pseudo = vertexNormals_[weld_[tri[2]]]; break;
    }
    *signedDistance = (p - c.position).dot(pseudo) < 0.f ? -c.distance : c.distance;
    return c;
}

float MeshCollider::signedDistance(const Vec3f& p, Vec3f* normal) const {
    float d = std::numeric_limits<float>::infinity();
    const MeshPoint c = closest(p, &d);
    if (normal) {
        if (!c.found()) *normal = Vec3f::UnitY();
        else if (c.distance > 1e-7f) *normal = (p - c.position) / d;  // points outward on both sides
        else *normal = faceNormals_[c.point.triangle];
    }
    return d;
}

LevelSetCollider::LevelSetCollider(std::shared_ptr<const LevelSet> grid, const Eigen::Isometry3f& restToWorld,
                                   std::shared_ptr<const MeshCollider> exact)
    : grid_(std::move(grid)), exact_(std::move(exact)), rotation_(restToWorld.linear()),
      worldToRest_(restToWorld.inverse()) {
    if (!grid_) throw Error("LevelSetCollider: no grid");
}

float LevelSetCollider::signedDistance(const Vec3f& p, Vec3f* normal) const {
    const Vec3f r = worldToRest_ * p;
    const Eigen::AlignedBox3f& box = grid_->bounds();
    const float boxDistance = box.exteriorDistance(r);
    if (boxDistance > 0.f) {
        // Outside the box of the band's voxel centres, which reaches at least
        // (band - voxel) beyond every surface point: a lower bound without a
        // grid lookup (most strand vertices away from the head).
        if (normal) *normal = rotation_ * (r - box.center()).normalized();
        const LevelSetSettings& s = grid_->settings();
        return boxDistance + std::max(0.f, s.exteriorBand - s.voxelSize);
    }
    float d = 0.f;
    Vec3f g;
    if (grid_->sample(r, d, normal ? &g : nullptr)) {
        if (normal) {
            const float len = g.norm();
            *normal = len > 0.f ? Vec3f(rotation_ * (g / len)) : Vec3f(rotation_ * Vec3f::UnitY());
        }
        return d;
    }
    if (d < 0.f && exact_) {
        // Deeper inside than the interior band: rare (a strand vertex far
        // inside the head), so the exact query's cost does not matter. The
        // depth is the closest triangle's distance; the side is the grid's.
        // OpenVDB's flood fill from outside marks a pocket the surface
        // encloses as inside, while the closest triangle's pseudonormal
        // sign is exact only for a surface that does not cross itself: in a
        // skinned neck folded through itself the closest triangle may be a
        // buried sheet seen from its outside (docs/colliders.md). There the
        // normal is turned to point away from that sheet, out of the inside.
        Vec3f n;
        const float e = exact_->signedDistance(r, normal ? &n : nullptr);
        if (normal) *normal = rotation_ * (e < 0.f ? n : Vec3f(-n));
        return -std::abs(e);
    }
    if (normal) {
        const Vec3f away = r - box.center();
        *normal = rotation_ * (away.norm() > 0.f ? Vec3f(away.normalized()) : Vec3f::UnitY());
    }
    return d;
}

}  // namespace hp
