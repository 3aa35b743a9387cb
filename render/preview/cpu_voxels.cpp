// The light passes' voxelization on the CPU (render/preview/cpu_voxels.h):
// strand.tesc's pieces, the rasterizer's fragments along each, and
// voxelize.frag's deposits, mirrored line by line.
#include "render/preview/cpu_voxels.h"

#include "render/preview/gl_context.h"  // softwareRasterizer
#include "render/preview/preview_gpu.h"  // kVoxelUnit, kSortedPatchSegments (no GL headers)

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace hp {

namespace {

/// A light-pass piece's end: what strand.tese hands the rasterizer.
struct PieceEnd {
    Vec3f world, tangent;
    float radius = 0.f;
};

/// shaders/strand_curve.glsl strandCurve: segment p1 -> p2 at u, with
/// neighbours c0, c3 mirrored (2b - c) where the patch repeats an end vertex.
///   Catmull-Rom: P(u) = 1/2 [2 p1 + (p2 - p0) u + (2 p0 - 5 p1 + 4 p2 - p3) u^2 + (-p0 + 3 p1 - 3 p2 + p3) u^3]
///   B-spline:    P(u) = 1/6 [(1 - u)^3 p0 + (3 u^3 - 6 u^2 + 4) p1 + (-3 u^3 + 3 u^2 + 3 u + 1) p2 + u^3 p3]
void strandCurve(const Vec3f& c0, const Vec3f& p1, const Vec3f& p2, const Vec3f& c3, float u, bool bspline,
                 Vec3f& position, Vec3f& derivative) {
    const Vec3f p0 = c0 == p1 ? Vec3f(2.f * p1 - p2) : c0;
    const Vec3f p3 = c3 == p2 ? Vec3f(2.f * p2 - p1) : c3;
    const float u2 = u * u, u3 = u2 * u;
    if (!bspline) {
        position = 0.5f * (2.f * p1 + (p2 - p0) * u + (2.f * p0 - 5.f * p1 + 4.f * p2 - p3) * u2 +
                           (-p0 + 3.f * p1 - 3.f * p2 + p3) * u3);
        derivative = 0.5f * ((p2 - p0) + 2.f * (2.f * p0 - 5.f * p1 + 4.f * p2 - p3) * u +
                             3.f * (-p0 + 3.f * p1 - 3.f * p2 + p3) * u2);
    } else {
        const float v = 1.f - u;
        position = (v * v * v * p0 + (3.f * u3 - 6.f * u2 + 4.f) * p1 + (-3.f * u3 + 3.f * u2 + 3.f * u + 1.f) * p2 +
                    u3 * p3) / 6.f;
        derivative = (-3.f * v * v * p0 + (9.f * u2 - 12.f * u) * p1 + (-9.f * u2 + 6.f * u + 3.f) * p2 +
                      3.f * u2 * p3) / 6.f;
    }
    if (derivative.squaredNorm() < 1e-20f) derivative = p2 - p1;
}

/// One light's raster and grid: the fragments of a piece and their deposits.
class GridRaster {
  public:
    GridRaster(const CpuVoxelTarget& t, const PreviewShadowSettings& shadow)
        : g_(t.grid), res_(t.resolution), voxels_(t.voxels->data()),
          mode_(shadow.mode == VoxelMode::Binary ? 0 : (shadow.splat == VoxelSplat::Trilinear ? 2 : 1)),
          crossings_(shadow.weight == VoxelWeight::Crossings) {}

    /// The fragments of the line a -> b by GL's diamond-exit rule (OpenGL
    /// 4.5 core, 14.5.1): pixel f is drawn when the segment leaves its
    /// diamond |x - xf| + |y - yf| < 1/2 (a strand's pieces share their
    /// ends, so no pixel is counted twice), one per pixel along the major
    /// axis, in the row the line crosses at that column's centre. Its
    /// attributes are the line's at that centre along the major axis
    /// (measured against llvmpipe: the projection of the pixel centre onto
    /// the line puts 5 % of the deposits in other voxels along the light),
    /// perspective-correct (1/w interpolated) for a point light.
    void line(const PieceEnd& a, const PieceEnd& b) const {
        const float r = float(res_);
        const Vec3f ga = g_.toGrid(a.world), gb = g_.toGrid(b.world);
        const float xa = ga.x() * r, ya = ga.y() * r, dx = gb.x() * r - xa, dy = gb.y() * r - ya;
        const bool xMajor = std::abs(dx) >= std::abs(dy);
        const float s0 = xMajor ? xa : ya, d = xMajor ? dx : dy, m0 = xMajor ? ya : xa, dm = xMajor ? dy : dx;
        if (d == 0.f) return;
        const float s1 = s0 + d, sigma = d > 0.f ? 1.f : -1.f, q = dm / std::abs(d);  // minor per unit of travel
        // Exit points lie within half a pixel past the column's centre.
        const int first = std::max(int(std::floor(std::min(s0, s1))) - 1, 0);
        const int last = std::min(int(std::ceil(std::max(s0, s1))) + 1, res_ - 1);
        const float wa = g_.perspective ? depthOf(a.world) : 1.f, wb = g_.perspective ? depthOf(b.world) : 1.f;
        // A directional light's grid is affine in world space: grid position
        // and light-view tangent interpolate along the line as they are.
        const Vec3f gla = ga * r, dg = (gb - ga) * r;
        const Eigen::Matrix3f rotation = g_.view.topLeftCorner<3, 3>();
        const Vec3f dva = rotation * a.tangent, ddv = rotation * b.tangent - dva;
        for (int i = first; i <= last; ++i) {
            const float c = float(i) + 0.5f;
            const float minor = m0 + (c - s0) / d * dm;
            const int j = int(std::floor(minor));
            if (j < 0 || j >= res_) continue;  // outside the viewport
            const float exit = c + sigma * diamondExit(minor - (float(j) + 0.5f), q);
            if (!(sigma * (exit - s0) > 0.f && sigma * (exit - s1) <= 0.f)) continue;
            const float t = (c - s0) / d;
            if (!g_.perspective) {
                const float w = crossings_ ? orthographicWeight(dva + t * ddv, a.radius + t * (b.radius - a.radius)) : 1.f;
                deposit(gla + t * dg, w);
                continue;
            }
            const float tp = g_.perspective ? (t / wb) / ((1.f - t) / wa + t / wb) : t;
            const Vec3f world = a.world + tp * (b.world - a.world);
            const float w = crossings_ ? crossingWeight(world, a.tangent + tp * (b.tangent - a.tangent),
                                                        a.radius + tp * (b.radius - a.radius))
                                       : 1.f;
            deposit(g_.toGrid(world) * r, w);
        }
    }

  private:
    /// Where a line leaves a pixel's diamond, in pixels of travel past the
    /// centre's column: the root v > 0 of v + |e + q v| = 1/2, e the line's
    /// minor offset from the centre there (|e| < 1/2), q its minor slope per
    /// unit of travel (|q| <= 1).
    static float diamondExit(float e, float q) {
        if (1.f + q > 0.f) {
            const float v = (0.5f - e) / (1.f + q);
            if (e + q * v >= 0.f) return v;
        }
        return (0.5f + e) / (1.f - q);
    }

    /// crossingWeight for a directional light, from the light-view tangent
    /// dv (any length): sin(theta) = |dv.xy| / |dv|, a raster pixel is
    /// 1 / (scale res) metres, perMetre = max(|dv.x| scale.x, |dv.y| scale.y)
    /// res / |dv|, so 2 r sin(theta) / (pixel.x pixel.y perMetre) =
    /// 2 r |dv.xy| scale.x scale.y res / max(|dv.x| scale.x, |dv.y| scale.y).
    float orthographicWeight(const Vec3f& dv, float radius) const {
        const float sx = g_.scale.x(), sy = g_.scale.y();
        const float m = std::max(std::abs(dv.x()) * sx, std::abs(dv.y()) * sy);
        return m > 0.f ? 2.f * radius * std::sqrt(dv.x() * dv.x() + dv.y() * dv.y()) * sx * sy * float(res_) / m : 0.f;
    }

    float depthOf(const Vec3f& world) const { return -(g_.view * world.homogeneous()).z(); }

    /// voxelize.frag crossingWeight: the strand crossings a light ray through
    /// a random point of the fragment's voxel column expects from the piece
    /// of strand the fragment stands for, (projected area) / (pixel area):
    /// 2 r sin(theta) / (pixel.x pixel.y perMetre), perMetre the fragments a
    /// metre of strand gives (max of its raster pixels per metre in x, y).
    float crossingWeight(const Vec3f& world, const Vec3f& tangent, float radius) const {
        const float len = tangent.norm();
        if (len <= 0.f) return 0.f;
        const Vec3f v = (g_.view * world.homogeneous()).head<3>();
        const Vec3f dv = g_.view.topLeftCorner<3, 3>() * (tangent / len);
        const float r = float(res_);
        Vec2f pixel, dq;
        float sinTheta;
        if (g_.perspective) {
            const float depth = std::max(-v.z(), 1e-6f);
            pixel = Vec2f(depth / (g_.scale.x() * r), depth / (g_.scale.y() * r));
            dq = (dv.head<2>() + v.head<2>() / depth * dv.z()) / depth;
            const Vec3f ray = v.normalized();
            sinTheta = (dv - dv.dot(ray) * ray).norm();
        } else {
            pixel = Vec2f(1.f / (g_.scale.x() * r), 1.f / (g_.scale.y() * r));
            dq = dv.head<2>();
            sinTheta = dv.head<2>().norm();
        }
        const float perMetre = std::max(std::abs(dq.x()) * g_.scale.x() * r, std::abs(dq.y()) * g_.scale.y() * r);
        return perMetre > 0.f ? 2.f * radius * sinTheta / (pixel.x() * pixel.y() * perMetre) : 0.f;
    }

    static uint32_t units(float w) { return uint32_t(std::nearbyint(w * kVoxelUnit)); }

    size_t index(int x, int y, int z) const { return cpuVoxelIndex(x, y, z, res_); }
    bool inside(int x, int y, int z) const {
        return x >= 0 && y >= 0 && z >= 0 && x < res_ && y < res_ && z < res_;
    }
    // Integer adds (and maxima) in any order give the same sum: the grid's
    // bits do not depend on the threads.
    void add(size_t i, uint32_t u) const { __atomic_fetch_add(voxels_ + i, u, __ATOMIC_RELAXED); }
    void max(size_t i, uint32_t u) const {
        uint32_t current = __atomic_load_n(voxels_ + i, __ATOMIC_RELAXED);
        while (current < u &&
               !__atomic_compare_exchange_n(voxels_ + i, &current, u, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
        }
    }

    /// voxelize.frag main: mode 0 binary (largest kept), 1 additive into the
    /// fragment's voxel, 2 additive with trilinear weights over the 8 voxel
    /// centres around it.
    void deposit(const Vec3f& g, float w) const {  // g: grid coordinates times the resolution
        if (mode_ != 2) {
            const int x = int(std::floor(g.x())), y = int(std::floor(g.y())), z = int(std::floor(g.z()));
            if (!inside(x, y, z)) return;
            const uint32_t u = units(w);
            if (mode_ == 0) max(index(x, y, z), u);
            else if (u > 0) add(index(x, y, z), u);
            return;
        }
        const Vec3f c = g - Vec3f::Constant(0.5f);
        const int bx = int(std::floor(c.x())), by = int(std::floor(c.y())), bz = int(std::floor(c.z()));
        const Vec3f f(c.x() - float(bx), c.y() - float(by), c.z() - float(bz));
        for (int k = 0; k < 8; ++k) {
            const int ox = k & 1, oy = (k >> 1) & 1, oz = (k >> 2) & 1;
            if (!inside(bx + ox, by + oy, bz + oz)) continue;
            const float wx = ox ? f.x() : 1.f - f.x(), wy = oy ? f.y() : 1.f - f.y(), wz = oz ? f.z() : 1.f - f.z();
            const uint32_t u = units(w * wx * wy * wz);
            if (u > 0) add(index(bx + ox, by + oy, bz + oz), u);
        }
    }

    const LightGrid& g_;
    int res_;
    uint32_t* voxels_;
    int mode_;
    bool crossings_;
};

}  // namespace

void voxelizeStrandsOnCpu(const StrandFrame& s, const LightPieceRule& rule, const LightGrid& pieceGrid,
                          int pieceResolution, const PreviewShadowSettings& shadow,
                          const std::vector<CpuVoxelTarget>& targets) {
    std::vector<GridRaster> rasters;
    for (const CpuVoxelTarget& t : targets) {
        const size_t n = cpuVoxelCount(t.resolution);
        t.voxels->resize(n);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, size_t(1) << 20), [&](const tbb::blocked_range<size_t>& r) {
            std::fill(t.voxels->begin() + std::ptrdiff_t(r.begin()), t.voxels->begin() + std::ptrdiff_t(r.end()), 0u);
        });
        rasters.emplace_back(t, shadow);
    }
    const bool radii = s.radii.size() == s.vertexCount();
    const bool bspline = rule.curve == CurveType::BSpline;
    const uint32_t perPatch = uint32_t(std::max(rule.segmentsPerPatch, 1));
    const float level = float(std::clamp(rule.level, 1, 64));
    const float res = float(pieceResolution);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, s.strandCount(), 64), [&](const tbb::blocked_range<size_t>& range) {
        std::vector<uint32_t> c;  // the patch's control points (render/preview/preview_buffers.cpp upload)
        for (size_t k = range.begin(); k != range.end(); ++k) {
            const uint32_t first = s.offsets[k], count = s.vertexCount(k);
            for (uint32_t start = 0; start + 1 < count; start += perPatch) {
                const uint32_t m = std::min(perPatch, count - 1 - start);
                c.assign(1, first + (start > 0 ? start - 1 : 0));
                for (uint32_t i = 0; i <= m; ++i) c.push_back(first + start + i);
                c.push_back(first + std::min(start + m + 1, count - 1));
                // strand.tesc: the polyline's raster length decides the pieces.
                float pixels = 0.f;
                Vec2f previous = pieceGrid.toGrid(s.positions[c[1]]).head<2>() * res;
                for (uint32_t i = 2; i <= m + 1; ++i) {
                    const Vec2f p = pieceGrid.toGrid(s.positions[c[i]]).head<2>() * res;
                    pixels += (p - previous).norm();
                    previous = p;
                }
                const float most = float(m) * level;
                float pieces = rule.pixels > 0.f ? std::clamp(std::ceil(pixels / rule.pixels), 1.f, most) : most;
                if (rule.minSegmentsPerPiece > 0)
                    pieces = std::max(pieces, std::min(std::ceil(float(m) / float(rule.minSegmentsPerPiece)), most));
                const float lines = std::ceil(pieces / 64.f);
                const int perLine = int(std::ceil(pieces / lines));
                // strand.tese: the isolines cover the parameter range [0, m] one after the other.
                auto point = [&](float sParam) {
                    const int i = std::min(int(sParam), int(m) - 1);
                    const float u = sParam - float(i);
                    PieceEnd e;
                    strandCurve(s.positions[c[size_t(i)]], s.positions[c[size_t(i) + 1]], s.positions[c[size_t(i) + 2]],
                                s.positions[c[size_t(i) + 3]], u, bspline, e.world, e.tangent);
                    const float ra = radii ? s.radii[c[size_t(i) + 1]] : 0.00004f;
                    const float rb = radii ? s.radii[c[size_t(i) + 2]] : 0.00004f;
                    e.radius = ra + (rb - ra) * u;
                    return e;
                };
                for (int l = 0; l < int(lines); ++l) {
                    PieceEnd a = point(float(l) / lines * float(m));
                    for (int j = 1; j <= perLine; ++j) {
                        const float x = float(j) / float(perLine);
                        const PieceEnd b = point((float(l) + x) / lines * float(m));
                        for (const GridRaster& raster : rasters) raster.line(a, b);
                        a = b;
                    }
                }
            }
        }
    });
}

void voxelizeSlotsOnCpu(const StrandFrame* strands, const std::vector<ShadowSlot>& slots, const int* resolutions,
                        const PreviewSettings& settings, int maxPatchVertices, bool share,
                        std::vector<uint32_t>* voxels) {
    static const StrandFrame none;
    const StrandFrame& f = strands ? *strands : none;
    size_t longest = 2;  // StrandBuffers::upload's patch size
    for (size_t k = 0; k < f.strandCount(); ++k) longest = std::max<size_t>(longest, f.vertexCount(k));
    LightPieceRule rule;
    rule.segmentsPerPatch = int(std::min<size_t>(size_t(maxPatchVertices), longest + 2)) - 3;
    rule.level = settings.tessellationLevel;
    rule.pixels = settings.tessellationPixels * float(std::clamp(settings.supersample, 1, 4));
    rule.minSegmentsPerPiece = settings.blend == HairBlend::Sorted ? kSortedPatchSegments : 0;
    rule.curve = settings.curve;
    std::vector<CpuVoxelTarget> targets;
    for (size_t k = 0; k < slots.size(); ++k) targets.push_back({slots[k].grid, resolutions[k], &voxels[k]});
    if (share) voxelizeStrandsOnCpu(f, rule, slots[0].grid, resolutions[0], settings.shadow, targets);
    for (size_t k = 0; k < slots.size() && !share; ++k)
        voxelizeStrandsOnCpu(f, rule, slots[k].grid, resolutions[k], settings.shadow, {targets[k]});
}

size_t cpuVoxelCount(int resolution) {
    const size_t bricks = size_t((resolution + 7) / 8);
    return bricks * bricks * bricks * 512;
}

void sumCpuVoxels(const std::vector<uint32_t>& voxels, int resolution, bool sum, std::vector<float>& out) {
    const size_t r = size_t(resolution);
    out.resize(r * r * r);
    tbb::parallel_for(tbb::blocked_range<int>(0, resolution, 8), [&](const tbb::blocked_range<int>& rows) {
        std::vector<float> acc(r);
        for (int y = rows.begin(); y != rows.end(); ++y) {
            std::fill(acc.begin(), acc.end(), 0.f);
            for (int z = 0; z < resolution; ++z) {
                float* row = out.data() + (size_t(z) * r + size_t(y)) * r;
                for (int x = 0; x < resolution; ++x) {
                    const float v = float(voxels[cpuVoxelIndex(x, y, z, resolution)]) / kVoxelUnit;
                    row[x] = sum ? acc[size_t(x)] : v;
                    acc[size_t(x)] += v;
                }
            }
        }
    });
}

void linearCpuVoxels(const std::vector<uint32_t>& voxels, int resolution, std::vector<uint32_t>& out) {
    const size_t r = size_t(resolution);
    out.resize(r * r * r);
    tbb::parallel_for(tbb::blocked_range<int>(0, resolution, 8), [&](const tbb::blocked_range<int>& slabs) {
        for (int z = slabs.begin(); z != slabs.end(); ++z)
            for (int y = 0; y < resolution; ++y)
                for (int x = 0; x < resolution; ++x)
                    out[(size_t(z) * r + size_t(y)) * r + size_t(x)] = voxels[cpuVoxelIndex(x, y, z, resolution)];
    });
}

std::vector<float> cpuVoxelValues(const std::vector<uint32_t>& voxels, int resolution) {
    std::vector<uint32_t> units;
    linearCpuVoxels(voxels, resolution, units);
    std::vector<float> values(units.size());
    for (size_t i = 0; i < units.size(); ++i) values[i] = float(units[i]) / kVoxelUnit;
    return values;
}

bool voxelizeOnCpu(VoxelizeOn voxelize, const std::string& renderer) {
    if (voxelize != VoxelizeOn::Auto) return voxelize == VoxelizeOn::Cpu;
    return softwareRasterizer(renderer);
}

}  // namespace hp
