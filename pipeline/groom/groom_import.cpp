#include "pipeline/groom/groom_import.h"

#include "core/log.h"
#include "pipeline/groom/groom_file.h"
#include "sim/collision/mesh_query.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <limits>

namespace hp {

namespace {

/// `n` points evenly spaced along the arc length of the polyline p[0, count).
std::vector<Vec3f> resample(const Vec3f* p, size_t count, int n) {
    std::vector<float> arc(count, 0.f);
    for (size_t i = 1; i < count; ++i) arc[i] = arc[i - 1] + (p[i] - p[i - 1]).norm();
    std::vector<Vec3f> out(static_cast<size_t>(n));
    size_t seg = 0;
    for (int k = 0; k < n; ++k) {
        const float s = arc.back() * float(k) / float(n - 1);
        while (seg + 2 < count && arc[seg + 1] < s) ++seg;
        const float span = arc[seg + 1] - arc[seg];
        const float w = span > 0.f ? std::clamp((s - arc[seg]) / span, 0.f, 1.f) : 0.f;
        out[size_t(k)] = (1.f - w) * p[seg] + w * p[seg + 1];
    }
    out.front() = p[0];
    out.back() = p[count - 1];
    return out;
}

/// Farthest-point sampling of `k` strands by (root, middle, tip): spread over
/// the scalp and over the groom's shapes. Deterministic (ties: lower index).
std::vector<uint32_t> chooseGuides(const std::vector<std::array<Vec3f, 3>>& features, size_t k) {
    const size_t n = features.size();
    Vec3f mean = Vec3f::Zero();
    for (const auto& f : features) mean += f[0];
    mean /= float(n);
    auto dist2 = [&](size_t a, size_t b) {
        float d = 0.f;
        for (int j = 0; j < 3; ++j) d += (features[a][j] - features[b][j]).squaredNorm();
        return d;
    };
    size_t first = 0;
    for (size_t i = 1; i < n; ++i)
        if ((features[i][0] - mean).squaredNorm() < (features[first][0] - mean).squaredNorm()) first = i;
    std::vector<float> nearest(n, std::numeric_limits<float>::infinity());
    std::vector<uint32_t> chosen{uint32_t(first)};
    while (chosen.size() < k) {
        const size_t last = chosen.back();
        tbb::parallel_for(size_t(0), n, [&](size_t i) { nearest[i] = std::min(nearest[i], dist2(i, last)); });
        size_t best = 0;
        for (size_t i = 1; i < n; ++i)
            if (nearest[i] > nearest[best]) best = i;
        chosen.push_back(uint32_t(best));
    }
    std::sort(chosen.begin(), chosen.end());
    return chosen;
}

}  // namespace

Eigen::Matrix3f rootAxes(const SurfaceFrame& f) {
    const Vec3f n = f.normal.normalized();
    Vec3f t = f.tangent - n * n.dot(f.tangent);
    t = t.norm() > 1e-6f ? Vec3f(t.normalized()) : Vec3f(n.unitOrthogonal());
    Eigen::Matrix3f m;
    m << t, n, t.cross(n);
    return m;
}

bool sceneHasGroomFile(const Scene& scene) { return !scene.file("hair.groom.file").empty(); }

ImportedGroom importGroom(const Scene& scene, const HeadSetup& head, int vertices) {
    const std::filesystem::path file = scene.file("hair.groom.file");
    const GroomCurves curves = readGroomFile(file);
    Affine3f toHead = scenePlacement(scene, "hair.groom");
    toHead.linear() *= upAxisRotation(sceneUpAxis(scene, "hair.groom")) * float(scene.number("hair.groom.unit_scale"));
    const float maxDistance = float(scene.number("hair.groom.max_root_distance"));

    // Bind and resample every strand (in parallel; each strand's result is its own).
    const MeshQuery scalp(head.rest, head.scalpGiven ? head.scalp : std::vector<uint8_t>{});
    const size_t n = curves.count();
    std::vector<SurfacePoint> roots(n);
    std::vector<std::vector<Vec3f>> local(n);
    std::vector<float> missed(n, -1.f);  ///< root distance of a dropped strand
    tbb::parallel_for(size_t(0), n, [&](size_t s) {
        std::vector<Vec3f> pts(curves.size(s));
        for (size_t i = 0; i < pts.size(); ++i) pts[i] = toHead * curves.points[curves.offsets[s] + i];
        const MeshPoint hit = scalp.closest(pts[0], maxDistance);
        if (!hit.found()) {
            missed[s] = scalp.closest(pts[0]).distance;
            return;
        }
        roots[s] = hit.point;
        const SurfaceFrame frame = evaluate(head.rest, hit.point);
        const Eigen::Matrix3f axes = rootAxes(frame);
        std::vector<Vec3f> strand = resample(pts.data(), pts.size(), vertices);
        // Moved rigidly so the root sits on the surface point.
        const Vec3f shift = frame.position - strand[0];
        for (Vec3f& p : strand) p = axes.transpose() * (p + shift - frame.position);
        strand[0] = Vec3f::Zero();
        local[s] = std::move(strand);
    });

    ImportedGroom g;
    g.read = n;
    std::vector<uint32_t> kept;
    for (size_t s = 0; s < n; ++s) {
        if (missed[s] < 0.f) {
            kept.push_back(uint32_t(s));
            continue;
        }
        if (g.dropped++ < 5)
            logWarning("groom: ", file.string(), ": strand ", s, " starts ", missed[s], " m from the scalp (more than "
                       "hair.groom.max_root_distance ", maxDistance, " m): dropped");
    }
    if (kept.empty())
        throw AssetError(file.string(), cat("no strand starts within hair.groom.max_root_distance (", maxDistance,
                                            " m) of the scalp: check hair.groom.unit_scale, up_axis and translate"));
    if (g.dropped > 5) logWarning("groom: ", g.dropped, " strands dropped in all (too far from the scalp)");

    const size_t guideCount = size_t(scene.integer("hair.guides.count"));
    std::vector<uint8_t> isGuide(n, 0);
    if (kept.size() <= guideCount) {
        for (uint32_t s : kept) isGuide[s] = 1;
    } else {
        std::vector<std::array<Vec3f, 3>> features(kept.size());
        for (size_t i = 0; i < kept.size(); ++i) {
            const uint32_t s = kept[i];
            const SurfaceFrame f = evaluate(head.rest, roots[s]);
            const Eigen::Matrix3f axes = rootAxes(f);
            features[i] = {f.position, f.position + axes * local[s][size_t(vertices / 2)],
                           f.position + axes * local[s].back()};
        }
        for (uint32_t i : chooseGuides(features, guideCount)) isGuide[kept[i]] = 1;
    }
    for (int pass = 0; pass < 2; ++pass)
        for (uint32_t s : kept)
            if (isGuide[s] == (pass == 0)) g.sources.push_back(s);
    for (uint32_t s : kept) {
        if (isGuide[s]) {
            g.roots.guides.push_back(roots[s]);
            g.guideShapes.add(local[s].data(), local[s].size());
        } else {
            g.roots.followers.push_back(roots[s]);
            g.followerShapes.add(local[s].data(), local[s].size());
        }
    }
    if (g.roots.followers.empty()) {
        // A sparse groom: procedural followers copy their nearest guide.
        const size_t count = size_t(scene.integer("hair.followers.count"));
        g.roots.followers = placeRoots(head.rest, head.scalp, rootSettings(scene, head, count, uint64_t(scene.integer("seed")) * 2 + 1));
    }
    logInfo("groom: ", file.string(), ": ", n, " strands read", g.dropped ? cat(", ", g.dropped, " dropped") : "",
            "; ", g.roots.guides.size(), " guides", g.followerShapes.count() ? cat(" chosen among them, ", g.roots.followers.size(),
            " followers keeping their own shape") : cat(", ", g.roots.followers.size(), " procedural followers"),
            "; resampled to ", vertices, " points");
    return g;
}

RestShapes nearestGuideShapes(const StrandFrame& guides, const std::vector<SurfaceFrame>& guideRoots,
                              const std::vector<SurfaceFrame>& followerRoots) {
    const size_t F = followerRoots.size();
    std::vector<std::vector<Vec3f>> local(F);
    tbb::parallel_for(size_t(0), F, [&](size_t f) {
        const Vec3f& p = followerRoots[f].position;
        size_t best = 0;  // lowest index among equals: deterministic
        for (size_t g = 1; g < guideRoots.size(); ++g)
            if ((guideRoots[g].position - p).squaredNorm() < (guideRoots[best].position - p).squaredNorm()) best = g;
        const Eigen::Matrix3f axes = rootAxes(followerRoots[f]);
        const Vec3f& root = guides.positions[guides.first(best)];
        for (uint32_t v = 0; v < guides.vertexCount(best); ++v)
            local[f].push_back(axes.transpose() * (guides.positions[guides.first(best) + v] - root));
    });
    RestShapes shapes;
    for (const auto& l : local) shapes.add(l.data(), l.size());
    return shapes;
}

std::vector<std::vector<Vec3f>> strandsAt(const RestShapes& shapes, const std::vector<SurfaceFrame>& roots) {
    std::vector<std::vector<Vec3f>> out(shapes.count());
    for (size_t s = 0; s < out.size(); ++s) {
        const Eigen::Matrix3f axes = rootAxes(roots[s]);
        for (uint32_t i = shapes.offsets[s]; i < shapes.offsets[s + 1]; ++i)
            out[s].push_back(roots[s].position + axes * shapes.points[i]);
    }
    return out;
}

}  // namespace hp
