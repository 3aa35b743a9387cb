#include "sim/level_set.h"

#include "core/errors.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>

#include <cmath>
#include <mutex>

namespace hp {

struct LevelSet::Impl {
    openvdb::FloatGrid::Ptr grid;
    float inverseVoxel = 1.f;
};

LevelSet::LevelSet(const TriangleMesh& mesh, const LevelSetSettings& settings)
    : impl_(std::make_unique<Impl>()), settings_(settings) {
    if (mesh.triangles.empty()) throw Error("LevelSet: the mesh has no triangles");
    if (!(settings.voxelSize > 0.f) || !(settings.exteriorBand > 0.f) || !(settings.interiorBand > 0.f))
        throw Error("LevelSet: voxel size and band widths must be positive");
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });

    std::vector<openvdb::Vec3s> points(mesh.positions.size());
    for (size_t i = 0; i < points.size(); ++i)
        points[i] = openvdb::Vec3s(mesh.positions[i].x(), mesh.positions[i].y(), mesh.positions[i].z());
    std::vector<openvdb::Vec3I> triangles(mesh.triangles.size());
    for (size_t t = 0; t < triangles.size(); ++t)
        triangles[t] = openvdb::Vec3I(mesh.triangles[t][0], mesh.triangles[t][1], mesh.triangles[t][2]);
    const std::vector<openvdb::Vec4I> noQuads;
    // Voxel centres sit at integer index coordinates: index = world / voxelSize.
    const openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(settings.voxelSize);
    impl_->grid = openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(
        *xform, points, triangles, noQuads, settings.exteriorBand / settings.voxelSize,
        settings.interiorBand / settings.voxelSize);
    impl_->inverseVoxel = 1.f / settings.voxelSize;

    const openvdb::CoordBBox box = impl_->grid->evalActiveVoxelBoundingBox();
    if (!box.empty()) {
        const float v = settings.voxelSize;
        bounds_ = Eigen::AlignedBox3f(Vec3f(box.min().x(), box.min().y(), box.min().z()) * v,
                                      Vec3f(box.max().x(), box.max().y(), box.max().z()) * v);
    }
}

LevelSet::~LevelSet() = default;

bool LevelSet::sample(const Vec3f& p, float& distance, Vec3f* gradient) const {
    // An accessor that does not register with the tree: constructing it is a
    // few stores, so every query (on any thread) can have its own.
    openvdb::tree::ValueAccessor<const openvdb::FloatTree, false> acc(impl_->grid->tree());
    const Vec3f x = p * impl_->inverseVoxel;
    const Vec3f f0 = x.array().floor();
    const Vec3f f = x - f0;
    openvdb::Coord ijk(int(f0.x()), int(f0.y()), int(f0.z()));
    float v[2][2][2];
    bool active = true;
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
            for (int k = 0; k < 2; ++k)
                active &= acc.probeValue(ijk.offsetBy(i, j, k), v[i][j][k]);
    // Trilinear interpolation d = Σ w_ijk v_ijk with w = Π (f or 1 - f); the
    // gradient differentiates the weights (∂/∂x of f_x is 1/voxel).
    const float gx = 1.f - f.x(), gy = 1.f - f.y(), gz = 1.f - f.z();
    const float c00 = v[0][0][0] * gz + v[0][0][1] * f.z(), c01 = v[0][1][0] * gz + v[0][1][1] * f.z();
    const float c10 = v[1][0][0] * gz + v[1][0][1] * f.z(), c11 = v[1][1][0] * gz + v[1][1][1] * f.z();
    const float c0 = c00 * gy + c01 * f.y(), c1 = c10 * gy + c11 * f.y();
    distance = c0 * gx + c1 * f.x();
    if (gradient) {
        const float dx = c1 - c0;
        const float dy = (c01 - c00) * gx + (c11 - c10) * f.x();
        const float dz0 = (v[0][0][1] - v[0][0][0]) * gy + (v[0][1][1] - v[0][1][0]) * f.y();
        const float dz1 = (v[1][0][1] - v[1][0][0]) * gy + (v[1][1][1] - v[1][1][0]) * f.y();
        const float dz = dz0 * gx + dz1 * f.x();
        *gradient = Vec3f(dx, dy, dz) * impl_->inverseVoxel;
    }
    return active;
}

size_t LevelSet::activeVoxelCount() const { return size_t(impl_->grid->activeVoxelCount()); }
size_t LevelSet::memoryBytes() const { return size_t(impl_->grid->memUsage()); }

}  // namespace hp
