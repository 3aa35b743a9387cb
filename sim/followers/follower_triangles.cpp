#include "sim/followers/follower_triangles.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

namespace hp {

namespace {

using Vec2d = Eigen::Vector2d;

struct Triangle {
    std::array<uint32_t, 3> v;
    Vec2d centre;   ///< circumcentre
    double radius2; ///< squared circumradius (infinite for a degenerate triangle)
};

double orient(const Vec2d& a, const Vec2d& b, const Vec2d& c) {
    return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

/// A counter-clockwise triangle and its circumcircle.
Triangle makeTriangle(const std::vector<Vec2d>& p, uint32_t a, uint32_t b, uint32_t c) {
    if (orient(p[a], p[b], p[c]) < 0) std::swap(b, c);
    const Vec2d u = p[b] - p[a], w = p[c] - p[a];
    const double d = 2.0 * (u.x() * w.y() - u.y() * w.x());
    Triangle t{{{a, b, c}}, p[a], std::numeric_limits<double>::infinity()};
    if (d != 0.0) {
        const Vec2d o((w.y() * u.squaredNorm() - u.y() * w.squaredNorm()) / d,
                      (u.x() * w.squaredNorm() - w.x() * u.squaredNorm()) / d);
        t.centre = p[a] + o;
        t.radius2 = o.squaredNorm();
    }
    return t;
}

/// Bowyer-Watson: insert the points in index order into a triangle that
/// encloses them all; each point removes the triangles whose circumcircle
/// holds it and fans the hole's boundary to it. O(n²) for n points, a few
/// milliseconds for the guide counts here (≤ a few thousand).
std::vector<std::array<uint32_t, 3>> delaunay(std::vector<Vec2d> p) {
    const uint32_t n = uint32_t(p.size());
    Eigen::AlignedBox2d box;
    for (const Vec2d& q : p) box.extend(q);
    const double span = std::max(box.sizes().maxCoeff(), 1e-9);
    const Vec2d mid = box.center();
    p.push_back(mid + Vec2d(-40.0 * span, -20.0 * span));
    p.push_back(mid + Vec2d(40.0 * span, -20.0 * span));
    p.push_back(mid + Vec2d(0.0, 40.0 * span));
    std::vector<Triangle> tris{makeTriangle(p, n, n + 1, n + 2)};
    std::vector<std::pair<uint32_t, uint32_t>> edges;
    std::vector<Triangle> kept;
    for (uint32_t i = 0; i < n; ++i) {
        edges.clear();
        kept.clear();
        for (const Triangle& t : tris) {
            if ((p[i] - t.centre).squaredNorm() < t.radius2) {
                for (int e = 0; e < 3; ++e) edges.emplace_back(t.v[e], t.v[(e + 1) % 3]);
            } else {
                kept.push_back(t);
            }
        }
        // The hole's boundary: edges of exactly one removed triangle.
        std::vector<std::pair<uint32_t, uint32_t>> keys(edges.size());
        for (size_t e = 0; e < edges.size(); ++e)
            keys[e] = {std::min(edges[e].first, edges[e].second), std::max(edges[e].first, edges[e].second)};
        std::vector<std::pair<uint32_t, uint32_t>> sorted = keys;
        std::sort(sorted.begin(), sorted.end());
        for (size_t e = 0; e < edges.size(); ++e) {
            const auto range = std::equal_range(sorted.begin(), sorted.end(), keys[e]);
            if (range.second - range.first == 1) kept.push_back(makeTriangle(p, edges[e].first, edges[e].second, i));
        }
        tris.swap(kept);
    }
    std::vector<std::array<uint32_t, 3>> out;
    for (const Triangle& t : tris)
        if (t.v[0] < n && t.v[1] < n && t.v[2] < n && orient(p[t.v[0]], p[t.v[1]], p[t.v[2]]) > 0) out.push_back(t.v);
    return out;
}

}  // namespace

GuideTriangulation::GuideTriangulation(std::vector<Vec3f> roots) : grid_(roots) {
    const size_t n = roots.size();
    incident_.resize(n);
    if (n < 3) return;
    // Principal axes (the planar map) and the least-squares sphere.
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Vec3f& r : roots) mean += r.cast<double>();
    mean /= double(n);
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    Eigen::Matrix4d ata = Eigen::Matrix4d::Zero();
    Eigen::Vector4d atb = Eigen::Vector4d::Zero();
    for (const Vec3f& r : roots) {
        const Eigen::Vector3d d = r.cast<double>() - mean;
        cov += d * d.transpose();
        const Eigen::Vector4d row(2.0 * d.x(), 2.0 * d.y(), 2.0 * d.z(), 1.0);
        ata += row * row.transpose();
        atb += row * d.squaredNorm();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> pca(cov);
    const double extent = std::sqrt(std::max(pca.eigenvalues()[2] / double(n), 0.0)) * 4.0;
    const Eigen::Vector4d fit = ata.ldlt().solve(atb);
    const Eigen::Vector3d c = fit.head<3>();
    const double radius = std::sqrt(std::max(fit[3] + c.squaredNorm(), 0.0));
    planar_ = !(fit.allFinite() && radius > 0.0 && radius < 100.0 * extent && pca.eigenvalues()[0] > 1e-12 * pca.eigenvalues()[2]);
    if (planar_) {
        centre_ = mean;
        axis1_ = pca.eigenvectors().col(2);
        axis2_ = pca.eigenvectors().col(1);
    } else {
        centre_ = mean + c;
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (const Vec3f& r : roots) sum += (r.cast<double>() - centre_).normalized();
        pole_ = sum.norm() > 1e-9 ? Eigen::Vector3d(sum.normalized()) : Eigen::Vector3d((roots[0].cast<double>() - centre_).normalized());
        axis1_ = pole_.unitOrthogonal();
        axis2_ = pole_.cross(axis1_);
    }
    mapped_.resize(n);
    for (size_t i = 0; i < n; ++i) mapped_[i] = map(roots[i]);
    triangles_ = delaunay(mapped_);
    for (uint32_t t = 0; t < triangles_.size(); ++t)
        for (uint32_t v : triangles_[t]) incident_[v].push_back(t);
}

Eigen::Vector2d GuideTriangulation::map(const Vec3f& p) const {
    const Eigen::Vector3d d = p.cast<double>() - centre_;
    if (planar_) return Vec2d(d.dot(axis1_), d.dot(axis2_));
    const Eigen::Vector3d u = d.norm() > 0.0 ? Eigen::Vector3d(d.normalized()) : pole_;
    const Vec2d across(u.dot(axis1_), u.dot(axis2_));
    const double theta = std::atan2(across.norm(), u.dot(pole_));
    return across.norm() > 0.0 ? Vec2d(theta * across.normalized()) : Vec2d::Zero();
}

GuideTriangulation::Location GuideTriangulation::locate(const Vec3f& p) const {
    Location loc;
    uint32_t idx[8];
    float d2[8];
    const int found = grid_.nearest(p, 8, idx, d2);
    if (found == 0) return loc;
    loc.guide = {{idx[0], idx[0], idx[0]}};
    if (triangles_.empty()) return loc;
    const Vec2d q = map(p);
    double best = -std::numeric_limits<double>::infinity();
    std::array<double, 3> weights{};
    uint32_t bestTriangle = 0;
    for (int c = 0; c < found; ++c)
        for (uint32_t t : incident_[idx[c]]) {
            const auto& v = triangles_[t];
            const Vec2d &a = mapped_[v[0]], &b = mapped_[v[1]], &cc = mapped_[v[2]];
            const double area = orient(a, b, cc);
            const std::array<double, 3> w{{orient(q, b, cc) / area, orient(a, q, cc) / area, orient(a, b, q) / area}};
            const double least = std::min({w[0], w[1], w[2]});
            if (least > best || (least == best && t < bestTriangle)) {
                best = least;
                weights = w;
                bestTriangle = t;
            }
        }
    if (best == -std::numeric_limits<double>::infinity()) return loc;  // no triangle around the nearest roots
    double sum = 0.0;
    for (double& w : weights) sum += (w = std::max(w, 0.0));
    std::array<int, 3> order{{0, 1, 2}};
    const auto& v = triangles_[bestTriangle];
    std::sort(order.begin(), order.end(), [&](int i, int j) {
        return weights[i] != weights[j] ? weights[i] > weights[j] : v[i] < v[j];
    });
    for (int k = 0; k < 3; ++k) {
        loc.guide[k] = v[order[k]];
        loc.weight[k] = float(weights[order[k]] / sum);
    }
    return loc;
}

}  // namespace hp
