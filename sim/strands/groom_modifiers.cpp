// Groom modifiers on the followers' rest shapes; sim/strands/groom_modifiers.h has
// the equations.
#include "sim/strands/groom_modifiers.h"

#include "core/errors.h"
#include "sim/followers/follower_kernels.h"
#include "sim/followers/follower_neighbours.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace hp {

namespace {

using Vec3d = Eigen::Vector3d;
using Mat3d = Eigen::Matrix3d;

/// A value in [0, 1) fixed per (seed, item, salt): MurmurHash3's finaliser
/// (the same as the followers' rand_xy), so nothing is stored or seeded.
double hash01(uint32_t seed, uint32_t item, uint32_t salt) {
    const uint32_t h = follower::mix32(follower::followerHash(seed, item) ^ follower::mix32(salt * 0x27d4eb2fu + 1u));
    return double(h) * (1.0 / 4294967296.0);
}

/// Length factor λ of follower f: 1 - lengthVariation · u_f.
double lengthFactor(const GroomModifiers& m, uint32_t f) { return 1.0 - double(m.lengthVariation) * hash01(m.seed, f, 1); }

/// Smooth noise along a strand: random vectors (components in [-1, 1)) at
/// control points every `scale` of the strand, blended by smoothstep.
Vec3d frizzNoise(const GroomModifiers& m, uint32_t f, double s) {
    const double u = s / double(m.frizzScale);
    const double j = std::floor(u), a = u - j;
    const double w = a * a * (3.0 - 2.0 * a);
    auto control = [&](double index) {
        const uint32_t base = 16u + 3u * uint32_t(index);
        return Vec3d(2.0 * hash01(m.seed, f, base) - 1.0, 2.0 * hash01(m.seed, f, base + 1) - 1.0,
                     2.0 * hash01(m.seed, f, base + 2) - 1.0);
    };
    return (1.0 - w) * control(j) + w * control(j + 1.0);
}

void checkModifiers(const GroomModifiers& m) {
    auto in = [](float v, float lo, float hi) { return v >= lo && v <= hi; };
    if (!in(m.lengthVariation, 0.f, 0.99f)) throw Error("groom modifiers: length variation must be in [0, 0.99]");
    if (!in(m.clump, 0.f, 1.f)) throw Error("groom modifiers: clump must be in [0, 1]");
    if (!(m.clumpProfile > 0.f) || !std::isfinite(m.clumpProfile))
        throw Error("groom modifiers: clump profile must be > 0");
    if (!in(m.wave, 0.f, 1.f) || !in(m.frizz, 0.f, 1.f)) throw Error("groom modifiers: wave and frizz must be in [0, 1] m");
    if (!(m.waveLength > 0.f) || !std::isfinite(m.waveLength)) throw Error("groom modifiers: wave length must be > 0");
    if (!in(m.curl, 0.f, 1.f)) throw Error("groom modifiers: curl must be in [0, 1]");
    if (!in(m.frizzScale, 0.01f, 1.f)) throw Error("groom modifiers: frizz scale must be in [0.01, 1]");
}

/// Clump centres: followers whose hash falls under clumps / F (about
/// `clumps` of them, spread like the roots), at least one.
std::vector<uint32_t> clumpCentres(const GroomModifiers& m, size_t F) {
    std::vector<uint32_t> centres;
    const double p = std::min(1.0, double(m.clumps) / double(F));
    for (uint32_t f = 0; f < F; ++f)
        if (hash01(m.seed, f, 2) < p) centres.push_back(f);
    if (centres.empty()) centres.push_back(0);
    return centres;
}

}  // namespace

RestShapes modifyFollowerShapes(const RestShapes& base, const std::vector<SurfaceFrame>& roots,
                                const GroomModifiers& m) {
    checkModifiers(m);
    const size_t F = base.count();
    if (roots.size() != F)
        throw Error(cat("groom modifiers: ", F, " follower rest shapes but ", roots.size(), " root frames"));
    RestShapes out;
    out.offsets = base.offsets;
    out.points.resize(base.points.size());
    if (F == 0) return out;

    std::vector<Mat3d> frames(F);
    for (size_t f = 0; f < F; ++f) frames[f] = restRootFrame(roots[f], "follower", f);
    const bool clumping = m.clump > 0.f && m.clumps > 0;
    const std::vector<uint32_t> centres = clumping ? clumpCentres(m, F) : std::vector<uint32_t>{};
    std::vector<Vec3f> centreRoots;
    for (uint32_t c : centres) centreRoots.push_back(roots[c].position);
    const PointGrid centreGrid(std::move(centreRoots));

    tbb::parallel_for(tbb::blocked_range<size_t>(0, F, 256), [&](const tbb::blocked_range<size_t>& range) {
        std::vector<Vec3d> target;
        std::vector<double> length, arc;
        for (size_t fi = range.begin(); fi != range.end(); ++fi) {
            const uint32_t f = uint32_t(fi);
            const uint32_t a = base.offsets[f], n = base.offsets[f + 1] - a;
            const double lambda = lengthFactor(m, f);
            target.resize(n);
            length.resize(n);
            arc.resize(n);
            double total = 0.0;
            arc[0] = 0.0;
            for (uint32_t k = 0; k < n; ++k) {
                target[k] = lambda * base.points[a + k].cast<double>();
                if (k + 1 < n) {
                    length[k] = lambda * double((base.points[a + k + 1] - base.points[a + k]).norm());
                    total += length[k];
                    arc[k + 1] = total;
                }
            }
            for (uint32_t k = 0; k < n; ++k) arc[k] = total > 0.0 ? arc[k] / total : 0.0;

            // Clump: toward the nearest centre's vertex at the same arc
            // fraction, through world space (the centre has its own frame).
            uint32_t clumpId = f;
            if (clumping) {
                float d2 = 0.f;
                uint32_t ci = 0;
                centreGrid.nearest(roots[f].position, 1, &ci, &d2);
                clumpId = centres[ci];
                const uint32_t c = centres[ci];
                const uint32_t ca = base.offsets[c], cn = base.offsets[c + 1] - ca;
                const double cl = lengthFactor(m, c);
                const Vec3d offset = roots[c].position.cast<double>() - roots[f].position.cast<double>();
                for (uint32_t k = 1; k < n; ++k) {
                    const uint32_t kc = uint32_t(std::lround(double(k) * double(cn - 1) / double(n - 1)));
                    const Vec3d centre = frames[f].transpose() * (offset + frames[c] * (cl * base.points[ca + kc].cast<double>()));
                    const double pull = double(m.clump) * std::pow(arc[k], double(m.clumpProfile));
                    target[k] += pull * (centre - target[k]);
                }
            }
            // Wave / curl across the chord; phase and axis from the clump so a clump waves together.
            if (m.wave > 0.f) {
                Vec3d chord = target[n - 1] - target[0];
                chord = chord.norm() > 0.0 ? Vec3d(chord.normalized()) : Vec3d::UnitY();
                Vec3d e = Vec3d::UnitX() - chord * chord.x();
                e = e.norm() > 1e-6 ? Vec3d(e.normalized()) : Vec3d(chord.unitOrthogonal());
                const double psi = 2.0 * M_PI * hash01(m.seed, clumpId, 3);
                const Vec3d b1 = std::cos(psi) * e + std::sin(psi) * chord.cross(e), b2 = chord.cross(b1);
                const double phase = 2.0 * M_PI * hash01(m.seed, clumpId, 4);
                for (uint32_t k = 1; k < n; ++k) {
                    const double phi = 2.0 * M_PI * arc[k] * total / double(m.waveLength) + phase;
                    const double ramp = std::min(1.0, 5.0 * arc[k]);
                    target[k] += double(m.wave) * ramp * (std::cos(phi) * b1 + double(m.curl) * std::sin(phi) * b2);
                }
            }
            if (m.frizz > 0.f)
                for (uint32_t k = 1; k < n; ++k) target[k] += double(m.frizz) * arc[k] * arc[k] * frizzNoise(m, f, arc[k]);

            // Follow the leader: each segment toward its target at its own length.
            Vec3d x = base.points[a].cast<double>();
            out.points[a] = base.points[a];
            for (uint32_t k = 0; k + 1 < n; ++k) {
                Vec3d d = target[k + 1] - x;
                if (!(d.norm() > 1e-12)) d = (base.points[a + k + 1] - base.points[a + k]).cast<double>();
                x += length[k] * d.normalized();
                out.points[a + k + 1] = x.cast<float>();
            }
        }
    });
    return out;
}

void applyGroomModifiers(FollowerGroom& groom, const GroomModifiers& modifiers) {
    checkModifiers(modifiers);
    if (!modifiers.active() || groom.followerRoots.empty()) return;
    groom.followerShapes = modifyFollowerShapes(followerBaseShapes(groom), groom.followerRoots, modifiers);
}

}  // namespace hp
