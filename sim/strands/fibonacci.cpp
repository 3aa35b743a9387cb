#include "sim/strands/fibonacci.h"

#include <Eigen/Geometry>

#include <cmath>

namespace hp {

Vec3f fibonacciPoint(size_t i, size_t n) {
    const double golden = M_PI * (3.0 - std::sqrt(5.0));  // golden angle, radians
    const double y = 1.0 - (2.0 * i + 1.0) / double(n);   // cell centres: never exactly at a pole
    const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
    const double phi = golden * double(i);
    return Vec3f(float(r * std::cos(phi)), float(y), float(r * std::sin(phi)));
}

std::vector<Vec3f> fibonacciCap(size_t count, const Vec3f& axis, float minCosine) {
    std::vector<Vec3f> out;
    if (count == 0) return out;
    // Points are spaced evenly in height, so the cap holds a fraction
    // (1 - minCosine) / 2 of them: size the sphere lattice accordingly.
    const double fraction = std::max(1e-6, (1.0 - double(minCosine)) / 2.0);
    const size_t n = size_t(std::ceil(double(count) / fraction));
    const Eigen::Quaternionf toAxis = Eigen::Quaternionf::FromTwoVectors(Vec3f::UnitY(), axis.normalized());
    // Heights decrease with i, so the cap is a prefix of the lattice.
    for (size_t i = 0; i < n && out.size() < count; ++i) {
        const Vec3f p = fibonacciPoint(i, n);
        if (p.y() >= minCosine) out.push_back(toAxis * p);
    }
    return out;
}

}  // namespace hp
