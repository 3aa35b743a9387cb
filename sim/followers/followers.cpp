// Building a Followers object: checks, neighbour selection, twist alignment
// and the tables update() fills (follower_update.cpp does the per-step part).
#include "sim/followers/followers.h"

#include "core/errors.h"
#include "sim/followers/follower_kernels.h"
#include "sim/followers/follower_neighbours.h"
#include "sim/followers/follower_state.h"
#include "sim/followers/follower_triangles.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

namespace hp {

void RestShapes::add(const Vec3f* p, size_t n) {
    points.insert(points.end(), p, p + n);
    offsets.push_back(uint32_t(points.size()));
}

RestShapes RestShapes::straight(size_t count, int vertices, float length) {
    RestShapes s;
    const int n = std::max(vertices, 2);
    s.points.reserve(count * size_t(n));
    s.offsets.reserve(count + 1);
    for (size_t i = 0; i < count; ++i) {
        for (int k = 0; k < n; ++k) s.points.emplace_back(0.f, length * float(k) / float(n - 1), 0.f);
        s.offsets.push_back(uint32_t(s.points.size()));
    }
    return s;
}

Eigen::Matrix3d restRootFrame(const SurfaceFrame& f, const char* what, size_t i) {
    using Vec3d = Eigen::Vector3d;
    Vec3d n = f.normal.cast<double>(), t = f.tangent.cast<double>();
    if (!n.allFinite() || !t.allFinite() || !f.position.allFinite() || n.norm() < 1e-6)
        throw Error(cat("followers: ", what, " ", i, " has a non-finite or zero root frame"));
    n.normalize();
    t -= n * n.dot(t);
    if (t.norm() < 1e-6) throw Error(cat("followers: ", what, " ", i, " has a tangent parallel to its normal"));
    t.normalize();
    Eigen::Matrix3d m;
    m << t, n, t.cross(n);
    return m;
}

namespace {

using Mat3d = Eigen::Matrix3d;
using Vec3d = Eigen::Vector3d;

/// Rotation taking coordinates in frame A to coordinates in frame B after
/// carrying A over to B's normal by the minimal rotation: B⁻¹ swing(n_A → n_B) A.
/// Both normals are the local y axis, so it is a turn about y; returns its
/// angle φ with R_y(φ) = [[cos φ, 0, sin φ], [0, 1, 0], [-sin φ, 0, cos φ]].
double twistAngle(const Mat3d& a, const Mat3d& b) {
    const Mat3d m = b.transpose() * follower::swing(Vec3d(a.col(1)), Vec3d(b.col(1))).toRotationMatrix() * a;
    return std::atan2(m(0, 2) - m(2, 0), m(0, 0) + m(2, 2));
}

Vec3d rotateY(double phi, const Vec3d& v) {
    const double c = std::cos(phi), s = std::sin(phi);
    return Vec3d(c * v.x() + s * v.z(), v.y(), -s * v.x() + c * v.z());
}

uint32_t padTo8(uint32_t n) { return (n + 7u) & ~7u; }

void checkShape(const RestShapes& shapes, size_t i, const char* what) {
    const uint32_t n = shapes.offsets[i + 1] - shapes.offsets[i];
    if (n < 2 || n > kMaxFollowerVertices)
        throw Error(cat("followers: ", what, " ", i, " has ", n, " vertices (2 to ", kMaxFollowerVertices,
                        " supported)"));
    for (uint32_t k = shapes.offsets[i]; k + 1 < shapes.offsets[i + 1]; ++k) {
        if (!shapes.points[k].allFinite() || !shapes.points[k + 1].allFinite())
            throw Error(cat("followers: ", what, " ", i, " has a non-finite rest vertex"));
        if ((shapes.points[k + 1] - shapes.points[k]).norm() <= 0.f)
            throw Error(cat("followers: ", what, " ", i, " has a zero-length rest segment ", k - shapes.offsets[i]));
    }
}

template <typename T>
T perFollower(const std::vector<T>& values, size_t i) { return values.size() == 1 ? values[0] : values[i]; }

/// Cuts each class's followers, in index order, into packets of 8; fills
/// the lanes' fields and own rest segments. Unused lanes of a class's last
/// packet repeat its last follower.
void buildPackets(Followers::Impl& im, const std::vector<size_t>& ownStart, const std::vector<Vec3f>& ownSegments) {
    constexpr int L = FollowerPacket::kLanes;
    const bool own = !ownSegments.empty();
    size_t ownTotal = 0;
    for (uint32_t cls = 0; cls < im.classes.size(); ++cls) {
        std::vector<uint32_t> members;
        for (uint32_t f = 0; f < im.followers; ++f)
            if (im.classOf[f] == cls) members.push_back(f);
        const uint32_t P = im.classes[cls].pad;
        for (size_t i = 0; i < members.size(); i += L) {
            const size_t n = std::min(members.size() - i, size_t(L));
            FollowerPacket pk;
            pk.count = uint32_t(n);
            pk.cls = cls;
            pk.own = uint32_t(ownTotal);
            for (int k = 0; k < L; ++k) {
                const uint32_t f = members[i + std::min(size_t(k), n - 1)];
                pk.follower[k] = f;
                pk.guide1[k] = im.neighbours[f].guide1;
                pk.pair[k] = im.pairOf[f];
                pk.vertexOffset[k] = im.vertexOffset[f];
                pk.alignC[k] = im.alignC[f];
                pk.alignS[k] = im.alignS[f];
                pk.scale[k] = own ? 1.f : im.segmentLength[f];
                pk.weight[k] = im.weight[f];
                pk.hash[k] = follower::followerHash(im.settings.seed, f);
            }
            if (own) {
                im.ownRest.resize(ownTotal + P);
                for (int k = 0; k < L; ++k)
                    for (uint32_t j = 0; j < P; ++j) {
                        const Vec3f& r = ownSegments[ownStart[pk.follower[k]] + j];
                        OwnRestSlot& slot = im.ownRest[ownTotal + j];
                        slot.x[k] = r.x();
                        slot.y[k] = r.y();
                        slot.z[k] = r.z();
                    }
                ownTotal += P;
                if (ownTotal > 0xffffffffu) throw Error("followers: too many follower rest vertices");
            }
            im.packets.push_back(pk);
        }
    }
}

/// Barycentric followers without own rest shapes: segment y's direction is
/// the blend of the three corners' rest directions, each turned into the
/// follower's frame by its rest twist,
///   d_y = normalize(Σ_i b_i R_y(φ_i) r_i(y)),   x_{y+1} = x_y + (length / S) d_y,
/// so the rest shape varies continuously over the triangulation like the motion.
RestShapes blendedRestShapes(const FollowerGroom& groom, const std::vector<Mat3d>& guideFrames,
                             const Followers::Impl& im, const std::vector<GuideTriangulation::Location>& corners) {
    RestShapes out;
    for (size_t f = 0; f < corners.size(); ++f) {
        const uint32_t n = perFollower(groom.followerVertices, f);
        const float length = perFollower(groom.followerLengths, f);
        if (n < 2 || n > kMaxFollowerVertices)
            throw Error(cat("followers: follower ", f, " has ", n, " vertices (2 to ", kMaxFollowerVertices, " supported)"));
        if (!(length > 0.f) || !std::isfinite(length))
            throw Error(cat("followers: follower ", f, " has length ", length, " (must be > 0)"));
        const Mat3d frame = restRootFrame(groom.followerRoots[f], "follower", f);
        double phi[3];
        for (int i = 0; i < 3; ++i) phi[i] = twistAngle(guideFrames[corners[f].guide[i]], frame);
        Vec3f p = Vec3f::Zero();
        out.points.push_back(p);
        for (uint32_t y = 0; y + 1 < n; ++y) {
            Vec3d d = Vec3d::Zero(), first = Vec3d::Zero();
            for (int i = 0; i < 3; ++i) {
                const uint32_t g = corners[f].guide[i], a = im.guideSegmentOffsets[g];
                const uint32_t gs = im.guideSegmentOffsets[g + 1] - a;
                const Vec3d r = rotateY(phi[i], im.guideRestDirs[a + FollowerClass::guideSegment(y, n - 1, gs)].cast<double>());
                if (i == 0) first = r;
                d += double(corners[f].weight[i]) * r;
            }
            d = d.norm() > 1e-9 ? Vec3d(d.normalized()) : first;
            p += (double(length) / double(n - 1) * d).cast<float>();
            out.points.push_back(p);
        }
        out.offsets.push_back(uint32_t(out.points.size()));
    }
    return out;
}

}  // namespace

RestShapes followerBaseShapes(const FollowerGroom& groom) {
    if (groom.followerShapes.count() > 0) return groom.followerShapes;
    const size_t G = groom.guideRoots.size(), F = groom.followerRoots.size();
    RestShapes out;
    if (F == 0) return out;
    if (G == 0 || groom.guideShapes.count() != G) throw Error("followers: base shapes need one rest shape per guide");
    std::vector<Vec3f> guideRootPositions(G);
    for (size_t g = 0; g < G; ++g) guideRootPositions[g] = groom.guideRoots[g].position;
    const PointGrid grid(std::move(guideRootPositions));
    for (size_t f = 0; f < F; ++f) {
        uint32_t g1 = 0;
        float d2 = 0.f;
        grid.nearest(groom.followerRoots[f].position, 1, &g1, &d2);
        const uint32_t n = perFollower(groom.followerVertices, f);
        if (n < 2) throw Error(cat("followers: follower ", f, " has ", n, " vertices (2 or more needed)"));
        const float segment = perFollower(groom.followerLengths, f) / float(n - 1);
        // The kernel's effective frame is R_f R_y(φ): a rest direction r of
        // guide 1 is R_y(φ) r in the follower's own root frame.
        const double phi = twistAngle(restRootFrame(groom.guideRoots[g1], "guide", g1),
                                      restRootFrame(groom.followerRoots[f], "follower", f));
        const uint32_t a = groom.guideShapes.offsets[g1], gs = groom.guideShapes.offsets[g1 + 1] - a - 1;
        Vec3f p = Vec3f::Zero();
        out.points.push_back(p);
        for (uint32_t y = 0; y + 1 < n; ++y) {
            const uint32_t k = a + FollowerClass::guideSegment(y, n - 1, gs);
            const Vec3d d = (groom.guideShapes.points[k + 1] - groom.guideShapes.points[k]).cast<double>().normalized();
            p += (double(segment) * rotateY(phi, d)).cast<float>();
            out.points.push_back(p);
        }
        out.offsets.push_back(uint32_t(out.points.size()));
    }
    return out;
}

Followers::Followers(const FollowerGroom& groom, const FollowerSettings& settings) : impl_(std::make_unique<Impl>()) {
    Impl& im = *impl_;
    im.settings = settings;
    const size_t G = groom.guideRoots.size(), F = groom.followerRoots.size();
    im.guides = G;
    im.followers = F;
    const bool given = groom.followerShapes.count() > 0;  // own rest shapes from the groom
    const bool tri = settings.mode == FollowerMode::Barycentric;
    const bool own = given || tri;  // barycentric followers always read their own rest shapes

    // --- Checks: every message names the strand and what is wrong.
    if (groom.guideShapes.count() != G)
        throw Error(cat("followers: ", G, " guide roots but ", groom.guideShapes.count(), " guide rest shapes"));
    if (F > 0 && G == 0) throw Error("followers: followers need at least one guide");
    if (given && groom.followerShapes.count() != F)
        throw Error(cat("followers: ", F, " follower roots but ", groom.followerShapes.count(), " follower rest shapes"));
    if (!given) {
        if (groom.followerVertices.size() != 1 && groom.followerVertices.size() != F)
            throw Error("followers: followerVertices needs one value or one per follower");
        if (groom.followerLengths.size() != 1 && groom.followerLengths.size() != F)
            throw Error("followers: followerLengths needs one value or one per follower");
    }
    if (!groom.followerIds.empty() && groom.followerIds.size() != F)
        throw Error(cat("followers: ", groom.followerIds.size(), " follower ids for ", F, " followers"));
    if (!(settings.fixedOffset >= 0.f && settings.fixedOffset <= 1.f) ||
        !(settings.maxVelocity >= 0.f && settings.maxVelocity <= 1e3f))
        throw Error("followers: fixed offset must be in [0, 1] and max velocity in [0, 1000] m/s");
    if (!(settings.rootRadius >= 0.f) || !(settings.tipRadius >= 0.f))
        throw Error("followers: radii must be non-negative");
    for (size_t g = 0; g < G; ++g) checkShape(groom.guideShapes, g, "guide");
    if (given)
        for (size_t f = 0; f < F; ++f) checkShape(groom.followerShapes, f, "follower");

    // --- Guides at rest: unit directions and inverse transported frames P_y⁻¹.
    std::vector<Mat3d> guideFrames(G);
    for (size_t g = 0; g < G; ++g) {
        guideFrames[g] = restRootFrame(groom.guideRoots[g], "guide", g);
        const uint32_t a = groom.guideShapes.offsets[g], b = groom.guideShapes.offsets[g + 1];
        follower::Quat frame;
        Vec3f previous = Vec3f::UnitY();
        for (uint32_t k = a; k + 1 < b; ++k) {
            const Vec3f d = (groom.guideShapes.points[k + 1] - groom.guideShapes.points[k]).normalized();
            frame = follower::transportStep(frame, previous, d);
            previous = d;
            im.restInverse.push_back(follower::conjugate(frame));
            im.guideRestDirs.push_back(d);
        }
        im.guideSegmentOffsets.push_back(uint32_t(im.restInverse.size()));
    }

    // --- Barycentric mode: the guide-root triangle over each follower and,
    // without the groom's own shapes, rest shapes blended from its corners.
    std::vector<GuideTriangulation::Location> corners;
    RestShapes blended;
    if (tri) {
        std::vector<Vec3f> rootPositions(G);
        for (size_t g = 0; g < G; ++g) rootPositions[g] = groom.guideRoots[g].position;
        const GuideTriangulation triangulation(std::move(rootPositions));
        corners.resize(F);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, F, 512), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t f = r.begin(); f != r.end(); ++f) corners[f] = triangulation.locate(groom.followerRoots[f].position);
        });
        if (!given) blended = blendedRestShapes(groom, guideFrames, im, corners);
    }
    const RestShapes& shapes = given ? groom.followerShapes : blended;

    // --- Segment-count classes.
    auto followerSegments = [&](size_t f) -> uint32_t {
        return own ? shapes.offsets[f + 1] - shapes.offsets[f] - 1
                   : perFollower(groom.followerVertices, f) - 1;
    };
    im.classOf.resize(F);
    for (size_t f = 0; f < F; ++f) {
        const uint32_t s = followerSegments(f);
        if (s < 1 || s + 1 > kMaxFollowerVertices)
            throw Error(cat("followers: follower ", f, " has ", s + 1, " vertices (2 to ", kMaxFollowerVertices,
                            " supported)"));
        auto it = std::find_if(im.classes.begin(), im.classes.end(), [&](const FollowerClass& c) { return c.segments == s; });
        if (it == im.classes.end()) {
            if (im.classes.size() == 255) throw Error("followers: more than 255 distinct follower vertex counts");
            FollowerClass c;
            c.segments = s;
            c.pad = padTo8(s + 1);  // slot 0 is the root (FollowerClass)
            im.classes.push_back(std::move(c));
            it = im.classes.end() - 1;
        }
        im.classOf[f] = uint8_t(it - im.classes.begin());
    }
    for (FollowerClass& c : im.classes) {
        const uint32_t P = c.pad;
        c.hot.assign(G, P);
        c.cold.assign(G, P);
        for (size_t g = 0; g < G; ++g) {
            // Identity rotations and zero rest directions at the root slot and
            // in the padding: those slots add nothing to the positions.
            float* w = c.hot.row(g, HotRow::RotationW);
            float *rx = c.hot.row(g, HotRow::RestX), *ry = c.hot.row(g, HotRow::RestY), *rz = c.hot.row(g, HotRow::RestZ);
            const uint32_t gs = im.guideSegmentOffsets[g + 1] - im.guideSegmentOffsets[g];
            for (uint32_t j = 0; j < P; ++j) {
                w[j] = 1.f;
                if (j < 1 || j > c.segments) continue;
                const Vec3f r = im.guideRestDirs[im.guideSegmentOffsets[g] + FollowerClass::guideSegment(j - 1, c.segments, gs)];
                rx[j] = r.x();
                ry[j] = r.y();
                rz[j] = r.z();
            }
        }
        c.weightedCurve.assign(P, 0.f);
        for (uint32_t j = 1; j <= c.segments; ++j)
            c.weightedCurve[j] = settings.fixedOffset * follower::fixedOffsetCurve(float(j - 1), float(c.segments));
        c.radii.resize(c.segments + 1);
        for (uint32_t v = 0; v <= c.segments; ++v)
            c.radii[v] = taperedRadius(settings.rootRadius, settings.tipRadius, float(v) / float(c.segments));
    }

    // --- Neighbours (grid search, in parallel; each follower independent).
    std::vector<Vec3f> guideRootPositions(G);
    for (size_t g = 0; g < G; ++g) guideRootPositions[g] = groom.guideRoots[g].position;
    const PointGrid grid(std::move(guideRootPositions));
    const bool byShape = settings.neighbours == NeighbourRule::ShapeSimilarity;
    const int k = byShape ? std::clamp(settings.shapeCandidates, 2, 64) : 2;

    im.neighbours.resize(F);
    im.weight.resize(F);
    im.alignC.resize(F);
    im.alignS.resize(F);
    im.segmentLength.assign(F, 0.f);
    im.vertexOffset.resize(F + 1);
    im.vertexOffset[0] = 0;
    for (size_t f = 0; f < F; ++f) im.vertexOffset[f + 1] = im.vertexOffset[f] + followerSegments(f) + 1;
    // Own rest segments per follower (P slots from ownStart[f]), moved into
    // the packets' lane layout (OwnRestSlot) once those are formed.
    std::vector<size_t> ownStart(own ? F + 1 : 0);
    std::vector<Vec3f> ownSegments;
    if (own) {
        for (size_t f = 0; f < F; ++f) ownStart[f + 1] = ownStart[f] + size_t(im.classes[im.classOf[f]].pad);
        ownSegments.assign(ownStart[F], Vec3f::Zero());
    }

    // Mean squared difference of unit rest directions, `b` carried into `a`'s
    // frame; `aDirs(y)` gives a's direction of its segment y of `segs`.
    auto shapeDistance = [&](auto aDirs, uint32_t segs, const Mat3d& aFrame, size_t b) {
        const double phi = twistAngle(guideFrames[b], aFrame);
        const uint32_t bs = im.guideSegmentOffsets[b + 1] - im.guideSegmentOffsets[b];
        double sum = 0.0;
        for (uint32_t y = 0; y < segs; ++y) {
            const Vec3d rb = rotateY(phi, im.guideRestDirs[im.guideSegmentOffsets[b] + FollowerClass::guideSegment(y, segs, bs)].cast<double>());
            sum += (aDirs(y) - rb).squaredNorm();
        }
        return sum / double(segs);
    };
    constexpr double kSameShape = 1e-4;  // below this (≈0.6° rms) shapes count as equal; the nearer root wins

    // Frames and lengths are checked serially first, so the first bad follower is the one reported.
    std::vector<Mat3d> followerFrames(F);
    for (size_t f = 0; f < F; ++f) {
        followerFrames[f] = restRootFrame(groom.followerRoots[f], "follower", f);
        if (!own) {
            const float length = perFollower(groom.followerLengths, f);
            if (!(length > 0.f) || !std::isfinite(length))
                throw Error(cat("followers: follower ", f, " has length ", length, " (must be > 0)"));
        }
    }
    tbb::parallel_for(tbb::blocked_range<size_t>(0, F, 512), [&](const tbb::blocked_range<size_t>& range) {
        uint32_t idx[64];
        float d2[64];
        for (size_t f = range.begin(); f != range.end(); ++f) {
            const Mat3d& Rf = followerFrames[f];
            const int found = tri ? 0 : grid.nearest(groom.followerRoots[f].position, k, idx, d2);
            uint32_t g1 = tri ? corners[f].guide[0] : idx[0];
            uint32_t g2 = tri ? corners[f].guide[1] : found > 1 ? idx[1] : idx[0];
            const uint32_t segs = followerSegments(f);
            if (byShape && found > 2) {
                // Own rest shape: rank candidates by similarity to it. Without:
                // keep the nearest, pick the second most like the first.
                struct Cand { double shape; float d2; uint32_t i; };
                Cand cands[64];
                int n = 0;
                for (int j = own ? 0 : 1; j < found; ++j) {
                    double s;
                    if (own) {
                        const uint32_t a = shapes.offsets[f];
                        auto dirs = [&](uint32_t y) {
                            return Vec3d((shapes.points[a + y + 1] - shapes.points[a + y]).cast<double>().normalized());
                        };
                        s = shapeDistance(dirs, segs, Rf, idx[j]);
                    } else {
                        const uint32_t gs = im.guideSegmentOffsets[g1 + 1] - im.guideSegmentOffsets[g1];
                        auto dirs = [&](uint32_t y) {
                            return Vec3d(im.guideRestDirs[im.guideSegmentOffsets[g1] + FollowerClass::guideSegment(y, gs, gs)].cast<double>());
                        };
                        s = shapeDistance(dirs, gs, guideFrames[g1], idx[j]);
                    }
                    cands[n++] = {s < kSameShape ? 0.0 : s, d2[j], idx[j]};
                }
                std::stable_sort(cands, cands + n, [](const Cand& a, const Cand& b) {
                    if (a.shape != b.shape) return a.shape < b.shape;
                    if (a.d2 != b.d2) return a.d2 < b.d2;
                    return a.i < b.i;
                });
                if (own) { g1 = cands[0].i; g2 = cands[1].i; }
                else g2 = cands[0].i;
            }
            FollowerNeighbours& nb = im.neighbours[f];
            nb.guide1 = g1;
            nb.guide2 = g2;
            if (tri) {
                nb.guide3 = corners[f].guide[2];
                for (int i = 0; i < 3; ++i) nb.weight[i] = corners[f].weight[i];
            }
            nb.distance1 = std::sqrt(distance2(groom.followerRoots[f].position, groom.guideRoots[g1].position));
            nb.distance2 = std::sqrt(distance2(groom.followerRoots[f].position, groom.guideRoots[g2].position));
            im.weight[f] = follower::interpolationWeight(nb.distance1, nb.distance2);

            // Twist alignment: the follower's effective frame is guide 1's
            // frame carried to it; guide 2's rotations are turned into guide 1's frame.
            const double phiF = twistAngle(guideFrames[g1], Rf);
            im.alignC[f] = float(std::cos(phiF));
            im.alignS[f] = float(std::sin(phiF));

            if (own) {
                // Rest segments (direction × length) in the effective frame:
                // f' = R_y(φ)ᵀ f, slot y + 1 for segment y.
                Vec3f* out = ownSegments.data() + ownStart[f];
                const uint32_t a = shapes.offsets[f];
                for (uint32_t y = 0; y < segs; ++y) {
                    const Vec3d d = (shapes.points[a + y + 1] - shapes.points[a + y]).cast<double>();
                    const double len = d.norm();
                    const Vec3d r = len * rotateY(-phiF, d / len);
                    out[y + 1] = r.cast<float>();
                }
            } else {
                im.segmentLength[f] = perFollower(groom.followerLengths, f) / float(segs);
            }
        }
    });

    // --- Guide pairs: the pair tables are per (guide 1, guide 2) and class,
    // numbered in follower order (deterministic). Cluster mode reads guide 1 only.
    im.pairOf.resize(F);
    {
        std::vector<std::unordered_map<uint64_t, uint32_t>> index(im.classes.size());
        for (size_t f = 0; f < F; ++f) {
            FollowerClass& c = im.classes[im.classOf[f]];
            const uint32_t g1 = im.neighbours[f].guide1;
            // Cluster and barycentric followers read guide 1's rows only (no pair table).
            const uint32_t g2 = settings.mode == FollowerMode::Cluster || tri ? g1 : im.neighbours[f].guide2;
            const auto [it, added] = index[im.classOf[f]].emplace(uint64_t(g1) << 32 | g2, uint32_t(c.pairs.size()));
            if (added) {
                const double phiK = twistAngle(guideFrames[g2], guideFrames[g1]);
                c.pairs.push_back({g1, g2, float(std::cos(phiK)), float(std::sin(phiK))});
            }
            im.pairOf[f] = it->second;
        }
        for (FollowerClass& c : im.classes) {
            c.pairRecords.assign(c.pairs.size() * c.pad, PairRecord{});
            c.guideRecords.assign(G * c.pad, GuideRecord{});
        }
    }

    im.ids.resize(F);
    for (size_t f = 0; f < F; ++f) im.ids[f] = groom.followerIds.empty() ? uint32_t(G + f) : groom.followerIds[f];
    buildPackets(im, ownStart, ownSegments);
    if (tri) {
        // K of guides 2 and 3 into guide 1's frame, as for the pairs.
        im.triangles.resize(im.packets.size());
        for (size_t i = 0; i < im.packets.size(); ++i)
            for (int l = 0; l < FollowerPacket::kLanes; ++l) {
                const FollowerNeighbours& nb = im.neighbours[im.packets[i].follower[l]];
                TrianglePacket& t = im.triangles[i];
                t.guide2[l] = nb.guide2;
                t.guide3[l] = nb.guide3;
                t.b1[l] = nb.weight[0];
                t.b2[l] = nb.weight[1];
                t.b3[l] = nb.weight[2];
                const double phi2 = twistAngle(guideFrames[nb.guide2], guideFrames[nb.guide1]);
                const double phi3 = twistAngle(guideFrames[nb.guide3], guideFrames[nb.guide1]);
                t.k2c[l] = float(std::cos(phi2));
                t.k2s[l] = float(std::sin(phi2));
                t.k3c[l] = float(std::cos(phi3));
                t.k3s[l] = float(std::sin(phi3));
            }
    }
}

Followers::~Followers() = default;
Followers::Followers(Followers&&) noexcept = default;
Followers& Followers::operator=(Followers&&) noexcept = default;

size_t Followers::guideCount() const { return impl_->guides; }
size_t Followers::followerCount() const { return impl_->followers; }
const FollowerSettings& Followers::settings() const { return impl_->settings; }
const FollowerNeighbours& Followers::neighbours(size_t follower) const { return impl_->neighbours.at(follower); }

}  // namespace hp
