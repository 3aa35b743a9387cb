#include "sim/collision/winding_number.h"

#include "sim/collision/mesh_query.h"

#include <cmath>

namespace hp {

double solidAngle(const Vec3f& q, const Vec3f& a, const Vec3f& b, const Vec3f& c) {
    // In double: near a vertex the three lengths differ by orders of magnitude.
    const Eigen::Vector3d x = (a - q).cast<double>(), y = (b - q).cast<double>(), z = (c - q).cast<double>();
    const double lx = x.norm(), ly = y.norm(), lz = z.norm();
    return 2.0 * std::atan2(x.dot(y.cross(z)), lx * ly * lz + x.dot(y) * lz + y.dot(z) * lx + z.dot(x) * ly);
}

double windingNumber(const TriangleMesh& mesh, const Vec3f& q) {
    double w = 0.0;
    for (const Tri& t : mesh.triangles) w += solidAngle(q, mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]]);
    return w / (4.0 * M_PI);
}

double windingNumber(const TriangleMesh& mesh, const MeshQuery& query, const Vec3f& q, const Vec3f& direction) {
    if (!query.intersect(q, direction).hit()) return 0.0;
    return windingNumber(mesh, q);
}

}  // namespace hp
