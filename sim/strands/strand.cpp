#include "sim/strands/strand.h"

#include "core/errors.h"

#include <cmath>

namespace hp {

void StrandFrame::clear() {
    guideCount = 0;
    offsets.assign(1, 0);
    positions.clear();
    velocities.clear();
    radii.clear();
    ids.clear();
}

void StrandFrame::reserve(size_t strands, size_t verticesPerStrand) {
    offsets.reserve(strands + 1);
    ids.reserve(strands);
    positions.reserve(strands * verticesPerStrand);
    radii.reserve(strands * verticesPerStrand);
    velocities.reserve(strands * verticesPerStrand);
}

void StrandFrame::addStrand(uint32_t id, const Vec3f* points, const float* radius, size_t count,
                            const Vec3f* velocity) {
    // Velocities are all-or-nothing: once one strand has them, every strand does.
    const bool withVelocity = velocity != nullptr || !velocities.empty();
    if (withVelocity && velocities.size() != positions.size()) velocities.resize(positions.size(), Vec3f::Zero());
    positions.insert(positions.end(), points, points + count);
    radii.insert(radii.end(), radius, radius + count);
    if (withVelocity) {
        if (velocity) velocities.insert(velocities.end(), velocity, velocity + count);
        else velocities.resize(positions.size(), Vec3f::Zero());
    }
    ids.push_back(id);
    offsets.push_back(static_cast<uint32_t>(positions.size()));
}

void StrandFrame::validate() const {
    if (offsets.empty() || offsets.front() != 0) throw Error("strand frame: offsets must start at 0");
    if (offsets.back() != positions.size())
        throw Error(cat("strand frame: offsets end at ", offsets.back(), " but there are ", positions.size(),
                        " vertices"));
    for (size_t s = 0; s + 1 < offsets.size(); ++s)
        if (offsets[s + 1] < offsets[s]) throw Error(cat("strand frame: offsets decrease at strand ", s));
    if (radii.size() != positions.size()) throw Error("strand frame: radii and positions differ in size");
    if (!velocities.empty() && velocities.size() != positions.size())
        throw Error("strand frame: velocities and positions differ in size");
    if (ids.size() != strandCount()) throw Error("strand frame: one id per strand expected");
    if (guideCount > strandCount()) throw Error("strand frame: more guides than strands");
    for (size_t v = 0; v < positions.size(); ++v)
        if (!positions[v].allFinite() || !std::isfinite(radii[v]))
            throw Error(cat("strand frame ", frame, ": non-finite vertex ", v));
}

}  // namespace hp
