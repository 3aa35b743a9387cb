#include "render/volume/density_grid.h"

#include "core/errors.h"
#include "render/volume/cell_walk.h"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>

namespace hp {

// ---------------------------------------------------------------------------
// GridTransform

GridTransform GridTransform::uniform(double voxelSize) {
    if (!(voxelSize > 0) || !std::isfinite(voxelSize)) throw Error(cat("voxel size must be > 0, got ", voxelSize));
    GridTransform t;
    t.linear = Eigen::Matrix3d::Identity() / voxelSize;
    return t;
}

GridTransform GridTransform::fromAxes(const Eigen::Matrix3d& axes, const Vec3d& origin) {
    const double det = axes.determinant();
    if (!(std::abs(det) > 0) || !std::isfinite(det) || !origin.allFinite())
        throw Error("grid transform: the voxel axes are singular or not finite");
    GridTransform t;
    t.linear = axes.inverse();
    t.offset = -t.linear * origin;
    return t;
}

GridTransform GridTransform::fromMatrix(const Eigen::Matrix4d& m) {
    if (!m.allFinite() || m(3, 0) != 0 || m(3, 1) != 0 || m(3, 2) != 0 || m(3, 3) != 1)
        throw Error("grid transform: the world-to-index matrix must be affine (last row 0 0 0 1) and finite");
    GridTransform t;
    t.linear = m.topLeftCorner<3, 3>();
    t.offset = m.topRightCorner<3, 1>();
    const double det = t.linear.determinant();
    if (!(std::abs(det) > 0)) throw Error("grid transform: the world-to-index matrix is singular");
    return t;
}

Eigen::Matrix3d GridTransform::indexToWorld() const { return linear.inverse(); }

Vec3d GridTransform::toWorld(const Vec3d& index) const { return linear.inverse() * (index - offset); }

double GridTransform::voxelVolume() const { return 1.0 / std::abs(linear.determinant()); }

double GridTransform::uniformVoxelSize() const {
    const double s = linear(0, 0);
    if (!(s > 0)) return 0;
    const Eigen::Matrix3d expected = Eigen::Matrix3d::Identity() * s;
    if ((linear - expected).cwiseAbs().maxCoeff() > 1e-12 * s) return 0;
    return 1.0 / s;
}

// ---------------------------------------------------------------------------
// Block keys

namespace {
constexpr int kKeyBits = 21;
constexpr int64_t kKeyBias = int64_t(1) << (kKeyBits - 1);
constexpr uint64_t kKeyMask = (uint64_t(1) << kKeyBits) - 1;

bool inRange(const Vec3i& voxel) {
    return std::abs(voxel.x()) <= DensityGrid::kMaxIndex && std::abs(voxel.y()) <= DensityGrid::kMaxIndex &&
           std::abs(voxel.z()) <= DensityGrid::kMaxIndex;
}

bool aligned(const Vec3i& origin) {
    constexpr int m = DensityGrid::kBlockSize - 1;
    return (origin.x() & m) == 0 && (origin.y() & m) == 0 && (origin.z() & m) == 0;
}
}  // namespace

uint64_t DensityGrid::blockKey(const Vec3i& c) {
    return (uint64_t(c.x() + kKeyBias) << (2 * kKeyBits)) | (uint64_t(c.y() + kKeyBias) << kKeyBits) |
           uint64_t(c.z() + kKeyBias);
}

Vec3i DensityGrid::blockCoordOfKey(uint64_t key) {
    return Vec3i(int(int64_t((key >> (2 * kKeyBits)) & kKeyMask) - kKeyBias),
                 int(int64_t((key >> kKeyBits) & kKeyMask) - kKeyBias), int(int64_t(key & kKeyMask) - kKeyBias));
}

// ---------------------------------------------------------------------------
// DensityGrid

DensityGrid::DensityGrid(const GridTransform& transform, std::vector<Vec3i> origins,
                         std::vector<DensityBlockPtr> density, std::vector<VelocityBlockPtr> velocity)
    : transform_(transform), origins_(std::move(origins)), density_(std::move(density)), velocity_(std::move(velocity)) {
    if (density_.size() != origins_.size() || (!velocity_.empty() && velocity_.size() != origins_.size()))
        throw Error("density grid: block arrays differ in size");
    for (size_t b = 0; b < density_.size(); ++b)
        if (!density_[b] || (!velocity_.empty() && !velocity_[b])) throw Error("density grid: missing block");
    lookup_.reserve(origins_.size());
    for (size_t b = 0; b < origins_.size(); ++b) {
        const Vec3i& origin = origins_[b];
        if (!aligned(origin) || !inRange(origin))
            throw Error(cat("density grid: block origin (", origin.transpose(), ") is not a multiple of ", kBlockSize,
                            " inside the index range"));
        const Vec3i c(origin.x() >> kBlockLog2, origin.y() >> kBlockLog2, origin.z() >> kBlockLog2);
        if (!lookup_.emplace(blockKey(c), uint32_t(b)).second)
            throw Error(cat("density grid: duplicate block at (", origin.transpose(), ")"));
    }
}

void DensityGrid::addBlock(const Vec3i& origin, const float* density, const Vec3f* velocity) {
    if (!aligned(origin) || !inRange(origin))
        throw Error(cat("density grid: block origin (", origin.transpose(), ") is not a multiple of ", kBlockSize,
                        " inside the index range"));
    if (!origins_.empty() && (velocity != nullptr) != hasVelocity())
        throw Error("density grid: velocity must be given for every block or none");
    const uint64_t key = blockKey(Vec3i(origin.x() >> kBlockLog2, origin.y() >> kBlockLog2, origin.z() >> kBlockLog2));
    if (!lookup_.emplace(key, uint32_t(origins_.size())).second)
        throw Error(cat("density grid: duplicate block at (", origin.transpose(), ")"));
    origins_.push_back(origin);
    density_.push_back(std::make_unique<DensityBlock>());
    std::copy(density, density + kBlockVoxels, density_.back()->begin());
    if (velocity) {
        velocity_.push_back(std::make_unique<VelocityBlock>());
        std::copy(velocity, velocity + kBlockVoxels, velocity_.back()->begin());
    }
}

void DensityGrid::releaseBlock(size_t b) {
    density_[b].reset();
    if (!velocity_.empty()) velocity_[b].reset();
}

void DensityGrid::clear() {
    origins_.clear();
    density_.clear();
    velocity_.clear();
    lookup_.clear();
}

long DensityGrid::findBlock(const Vec3i& voxel, int* offset) const {
    if (!inRange(voxel)) return -1;
    const Vec3i block(voxel.x() >> kBlockLog2, voxel.y() >> kBlockLog2, voxel.z() >> kBlockLog2);
    const auto it = lookup_.find(blockKey(block));
    if (it == lookup_.end()) return -1;
    constexpr int m = kBlockSize - 1;
    *offset = voxelOffset(voxel.x() & m, voxel.y() & m, voxel.z() & m);
    return long(it->second);
}

float DensityGrid::density(const Vec3i& voxel) const {
    int offset = 0;
    const long b = findBlock(voxel, &offset);
    return b < 0 ? 0.f : (*density_[size_t(b)])[size_t(offset)];
}

Vec3f DensityGrid::velocity(const Vec3i& voxel) const {
    int offset = 0;
    const long b = hasVelocity() ? findBlock(voxel, &offset) : -1;
    return b < 0 ? Vec3f::Zero() : (*velocity_[size_t(b)])[size_t(offset)];
}

namespace {

/// The 8 voxel values around dual cell `c` (corners c + {0,1}³), x-major.
void gatherCorners(const DensityGrid& g, const Vec3i& c, double v[8]) {
    for (int i = 0; i < 8; ++i) v[i] = g.density(c + Vec3i(i >> 2, (i >> 1) & 1, i & 1));
}

/// Trilinear interpolation of gatherCorners' values at fractions f ∈ [0, 1]³.
double trilinear(const double v[8], const Vec3d& f) {
    // Along z (corner pairs differing in the last index bit), then y, then x.
    const double x0y0 = v[0] + (v[1] - v[0]) * f.z(), x0y1 = v[2] + (v[3] - v[2]) * f.z();
    const double x1y0 = v[4] + (v[5] - v[4]) * f.z(), x1y1 = v[6] + (v[7] - v[6]) * f.z();
    const double x0 = x0y0 + (x0y1 - x0y0) * f.y(), x1 = x1y0 + (x1y1 - x1y0) * f.y();
    return x0 + (x1 - x0) * f.x();
}

Vec3i floorVec(const Vec3d& p) { return Vec3i(int(std::floor(p.x())), int(std::floor(p.y())), int(std::floor(p.z()))); }

bool finiteIndex(const Vec3d& p) {
    return p.allFinite() && p.cwiseAbs().maxCoeff() < double(DensityGrid::kMaxIndex);
}

}  // namespace

float DensityGrid::sample(const Vec3f& world, Reconstruction mode) const {
    const Vec3d p = transform_.toIndex(world.cast<double>());
    if (!finiteIndex(p)) return 0.f;
    if (mode == Reconstruction::Nearest) return density(floorVec(p + Vec3d::Constant(0.5)));
    const Vec3i c = floorVec(p);
    double v[8];
    gatherCorners(*this, c, v);
    return float(trilinear(v, p - c.cast<double>()));
}

double DensityGrid::integrate(const Vec3f& from, const Vec3f& to, Reconstruction mode) const {
    const Vec3d a = transform_.toIndex(from.cast<double>()), b = transform_.toIndex(to.cast<double>());
    if (!finiteIndex(a) || !finiteIndex(b)) throw Error("density grid: integration segment outside the index range");
    const double length = (to.cast<double>() - from.cast<double>()).norm();
    if (length == 0 || origins_.empty()) return 0;
    double sum = 0;  // ∫ density dt over t ∈ [0, 1]
    if (mode == Reconstruction::Nearest) {
        // Voxel cubes are unit cells shifted by half a voxel.
        const Vec3d half = Vec3d::Constant(0.5);
        walkCells(a + half, b + half, [&](const Vec3i& voxel, double t0, double t1) {
            sum += density(voxel) * (t1 - t0);
        });
    } else {
        // Between voxel centres the field is trilinear, i.e. cubic along a
        // line: 2-point Gauss-Legendre is exact.
        const double g = 0.5 / std::sqrt(3.0);
        const Vec3d d = b - a;
        walkCells(a, b, [&](const Vec3i& cell, double t0, double t1) {
            double v[8];
            gatherCorners(*this, cell, v);
            if (v[0] == 0 && v[1] == 0 && v[2] == 0 && v[3] == 0 && v[4] == 0 && v[5] == 0 && v[6] == 0 && v[7] == 0)
                return;
            const double mid = 0.5 * (t0 + t1), h = t1 - t0;
            const Vec3d base = a - cell.cast<double>();
            for (double s : {mid - g * h, mid + g * h}) {
                const Vec3d f = (base + d * s).cwiseMax(0.0).cwiseMin(1.0);
                sum += 0.5 * h * trilinear(v, f);
            }
        });
    }
    return sum * length;
}

double DensityGrid::transmittance(const Vec3f& from, const Vec3f& to, double sigma, Reconstruction mode) const {
    return std::exp(-sigma * integrate(from, to, mode));
}

double DensityGrid::totalVolume() const {
    double sum = 0;
    for (const auto& block : density_)
        for (float v : *block) sum += v;
    return sum * transform_.voxelVolume();
}

size_t DensityGrid::activeVoxelCount() const {
    size_t n = 0;
    for (const auto& block : density_)
        n += size_t(std::count_if(block->begin(), block->end(), [](float v) { return v > 0; }));
    return n;
}

bool DensityGrid::activeBounds(Vec3i* min, Vec3i* max) const {
    bool any = false;
    Vec3i lo = Vec3i::Constant(kMaxIndex), hi = Vec3i::Constant(-kMaxIndex);
    for (size_t b = 0; b < origins_.size(); ++b)
        for (int i = 0; i < kBlockVoxels; ++i)
            if ((*density_[b])[size_t(i)] > 0) {
                const Vec3i v = origins_[b] + Vec3i(i >> 6, (i >> 3) & 7, i & 7);
                lo = lo.cwiseMin(v);
                hi = hi.cwiseMax(v);
                any = true;
            }
    if (any) {
        *min = lo;
        *max = hi;
    }
    return any;
}

float DensityGrid::maxDensity() const {
    float m = 0.f;
    for (const auto& block : density_)
        for (float v : *block) m = std::max(m, v);
    return m;
}

}  // namespace hp
