// Geometry uploads of the preview: strands and head into persistently mapped
// buffers, index lists rebuilt only when the topology changes.
#include "render/preview/preview_gpu.h"

#include "core/errors.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace hp {

PersistentBuffer::~PersistentBuffer() {
    if (id_) glDeleteBuffers(1, &id_);
}

bool PersistentBuffer::reserve(size_t bytes) {
    if (bytes <= capacity_ && id_) return false;
    if (id_) glDeleteBuffers(1, &id_);
    // Grow by half again so a slowly growing strand count does not reallocate every frame.
    capacity_ = std::max<size_t>(std::max(bytes, capacity_ + capacity_ / 2), 256);
    const GLbitfield flags = GL_MAP_WRITE_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
    glCreateBuffers(1, &id_);
    glNamedBufferStorage(id_, GLsizeiptr(capacity_), nullptr, flags);
    mapped_ = glMapNamedBufferRange(id_, 0, GLsizeiptr(capacity_), flags);
    if (!mapped_) throw FrameError(cat("preview: cannot map a ", capacity_, "-byte GL buffer (out of memory?)"));
    return true;
}

// ---- strands ---------------------------------------------------------------

void StrandBuffers::create() {
    glCreateVertexArrays(1, &vao);
    glEnableVertexArrayAttrib(vao, 0);
    glVertexArrayAttribFormat(vao, 0, 4, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, 0, 0);
    glCreateBuffers(1, &indices);
    GLint limit = 32;
    glGetIntegerv(GL_MAX_PATCH_VERTICES, &limit);
    maxPatchVertices = std::clamp(limit, 4, 32);  // 32: the TCS's array size
}

void StrandBuffers::destroy() {
    if (vao) glDeleteVertexArrays(1, &vao);
    if (indices) glDeleteBuffers(1, &indices);
    vao = indices = 0;
}

void StrandBuffers::upload(const StrandFrame& s, int maxSegments) {
    const size_t n = s.vertexCount();
    if (vertices.reserve(n * 4 * sizeof(float))) {
        glVertexArrayVertexBuffer(vao, 0, vertices.id(), 0, 4 * sizeof(float));
    }
    float* out = static_cast<float*>(vertices.data());
    const bool radii = s.radii.size() == n;
    for (size_t i = 0; i < n; ++i) {
        out[4 * i + 0] = s.positions[i].x();
        out[4 * i + 1] = s.positions[i].y();
        out[4 * i + 2] = s.positions[i].z();
        out[4 * i + 3] = radii ? s.radii[i] : 0.00004f;
    }
    if (s.offsets == offsets && maxSegments == chunkSegments && indexCount > 0) return;
    // One patch per strand (or per chunk of a strand longer than a patch
    // holds, or than maxSegments): the driver's per-patch cost dominates on
    // software rasterizers, so patches are as long as GL allows unless they
    // are sorted. A patch holds the vertex before its first segment, the
    // segments' vertices and the one after; at a root or tip the missing
    // neighbour repeats the end vertex (the TES mirrors it) and unused slots
    // repeat the last entry, from which the TCS reads the segment count.
    size_t longest = 2;
    for (size_t k = 0; k < s.strandCount(); ++k) longest = std::max<size_t>(longest, s.vertexCount(k));
    if (maxSegments > 0) longest = std::min<size_t>(longest, size_t(maxSegments) + 1);
    patchSize = int(std::min<size_t>(size_t(maxPatchVertices), longest + 2));
    const uint32_t perPatch = uint32_t(patchSize - 3);  // segments one patch can hold
    list.clear();
    counts.clear();
    list.reserve(s.vertexCount() * 2);
    segments = 0;
    for (size_t k = 0; k < s.strandCount(); ++k) {
        const uint32_t first = s.offsets[k], count = s.vertexCount(k);
        for (uint32_t start = 0; start + 1 < count; start += perPatch) {
            const uint32_t m = std::min(perPatch, count - 1 - start);
            list.push_back(first + (start > 0 ? start - 1 : 0));
            for (uint32_t i = 0; i <= m; ++i) list.push_back(first + start + i);
            const uint32_t after = first + std::min(start + m + 1, count - 1);
            for (uint32_t i = m + 2; i < uint32_t(patchSize); ++i) list.push_back(after);
            counts.push_back(m);
            segments += m;
        }
    }
    glNamedBufferData(indices, GLsizeiptr(std::max<size_t>(list.size(), 1) * sizeof(uint32_t)),
                      list.empty() ? nullptr : list.data(), GL_DYNAMIC_DRAW);
    glVertexArrayElementBuffer(vao, indices);
    indexCount = list.size();
    offsets = s.offsets;
    chunkSegments = maxSegments;
}

void StrandBuffers::sortBackToFront(const StrandFrame& s, const Vec3f& eye, const Vec3f& forward) {
    const size_t patches = counts.size();
    if (patches == 0) return;
    const size_t ps = size_t(patchSize);
    // Depth of each patch: the midpoint of its first and last vertex.
    std::vector<std::pair<float, uint32_t>> keys(patches);
    for (size_t p = 0; p < patches; ++p) {
        const uint32_t a = list[p * ps + 1], b = list[p * ps + 1 + counts[p]];
        const Vec3f mid = 0.5f * (s.positions[a] + s.positions[b]);
        keys[p] = {(mid - eye).dot(forward), uint32_t(p)};
    }
    // Farthest first; ties keep strand order, so the result is deterministic.
    std::sort(keys.begin(), keys.end(), [](const auto& x, const auto& y) {
        return x.first > y.first || (x.first == y.first && x.second < y.second);
    });
    sortedList.resize(list.size());
    for (size_t i = 0; i < patches; ++i) {
        const uint32_t p = keys[i].second;
        std::copy_n(list.begin() + std::ptrdiff_t(p * ps), ps, sortedList.begin() + std::ptrdiff_t(i * ps));
    }
    glNamedBufferSubData(indices, 0, GLsizeiptr(sortedList.size() * sizeof(uint32_t)), sortedList.data());
}

size_t lightPieceVertexBound(const StrandBuffers& b, const StrandFrame& s, const LightGrid& grid, int resolution,
                             int level, float pixels, int minSegmentsPerPiece) {
    // strand.tesc measures a patch's length between its vertices 1 ..
    // segments + 1 in raster pixels of the light pass (grid coordinates times
    // the resolution) and cuts it into clamp(ceil(L / pixels), 1, most)
    // pieces with most = segments level, split over ceil(pieces / 64)
    // isolines of ceil(pieces / lines) pieces each: at most pieces + lines.
    const size_t ps = size_t(b.patchSize);
    size_t vertices = 0;
    for (size_t p = 0; p < b.counts.size(); ++p) {
        const uint32_t segs = b.counts[p];
        const double most = double(segs) * double(std::max(level, 1));
        double pieces = most;
        if (pixels > 0.f) {
            double length = 0.0;
            Vec3f previous = grid.toGrid(s.positions[b.list[p * ps + 1]]);
            for (uint32_t i = 2; i <= segs + 1; ++i) {
                const Vec3f g = grid.toGrid(s.positions[b.list[p * ps + i]]);
                length += double((g - previous).head<2>().norm()) * resolution;
                previous = g;
            }
            // 1% and one piece for the GPU's float rounding of L.
            pieces = std::min(most, std::max(1.0, length * 1.01 / double(pixels) + 2.0));
        }
        // strand.tesc's MIN_SEGMENTS_PER_PIECE floor (without it the capture
        // overflowed and the other lights lost the last strands' pieces).
        if (minSegmentsPerPiece > 0)
            pieces = std::max(pieces, std::min(std::ceil(double(segs) / double(minSegmentsPerPiece)), most));
        pieces = std::ceil(pieces);
        vertices += size_t(2.0 * (pieces + std::ceil(pieces / 64.0)));
    }
    return vertices;
}

// In front of the camera and at most `lineWidth` pixels wide everywhere: strand.tesc's THICK_PASS culls every patch (its `widest`
/// is the same 2 r f / w over the same vertices; the 1e-3 margin covers
/// float rounding). Skipping the pass saves the vertex and tessellation
/// control shaders of every patch, a few percent of a frame on llvmpipe.
bool mayHaveThickStrands(const StrandFrame& s, const Mat4f& viewProj, float focalPixels, float lineWidth) {
    if (lineWidth <= 0.f) return true;  // no line path: the ribbon pass draws every strand
    const bool radii = s.radii.size() == s.positions.size();
    const Eigen::RowVector4f wRow = viewProj.row(3);
    for (size_t i = 0; i < s.positions.size(); ++i) {
        const float w = wRow * s.positions[i].homogeneous();
        if (w <= 1e-5f) return true;  // at or behind the eye: the shader's clamp makes it wide
        const float radius = radii ? s.radii[i] : 0.00004f;  // StrandBuffers::upload's default
        if (2.f * radius * focalPixels / w > lineWidth * (1.f - 1e-3f)) return true;
    }
    return false;
}

// ---- head ------------------------------------------------------------------

void HeadBuffers::create() {
    glCreateVertexArrays(1, &vao);
    for (GLuint a = 0; a < 2; ++a) {
        glEnableVertexArrayAttrib(vao, a);
        glVertexArrayAttribFormat(vao, a, 3, GL_FLOAT, GL_FALSE, a * 3 * sizeof(float));
        glVertexArrayAttribBinding(vao, a, 0);
    }
    glCreateBuffers(1, &indices);
    glCreateBuffers(1, &furIndices);
    glCreateBuffers(1, &furTypes);
    glNamedBufferData(furTypes, 16, nullptr, GL_STATIC_DRAW);
}

void HeadBuffers::destroy() {
    if (vao) glDeleteVertexArrays(1, &vao);
    GLuint buffers[] = {indices, furIndices, furTypes};
    glDeleteBuffers(3, buffers);
    if (hairTypes) glDeleteTextures(1, &hairTypes);
    vao = indices = furIndices = furTypes = hairTypes = 0;
}

namespace {

bool sameTypes(const std::vector<HairType>& a, const std::vector<HairType>& b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const HairType& x, const HairType& y) {
        return x.color == y.color && x.segments == y.segments && x.segmentLength == y.segmentLength &&
               x.forceWeight == y.forceWeight && x.rootRadius == y.rootRadius && x.tipRadius == y.tipRadius;
    });
}

}  // namespace

void HeadBuffers::upload(const TriangleMesh& mesh, const std::vector<uint8_t>& triangleTypes,
                         const std::vector<HairType>& hairTypeList) {
    const size_t n = mesh.positions.size();
    if (vertices.reserve(n * 6 * sizeof(float))) glVertexArrayVertexBuffer(vao, 0, vertices.id(), 0, 6 * sizeof(float));
    std::vector<Vec3f> computed;
    const std::vector<Vec3f>* normals = &mesh.normals;
    if (mesh.normals.size() != n) {
        TriangleMesh copy;
        copy.positions = mesh.positions;
        copy.triangles = mesh.triangles;
        copy.computeNormals();
        computed = std::move(copy.normals);
        normals = &computed;
    }
    float* out = static_cast<float*>(vertices.data());
    for (size_t i = 0; i < n; ++i) {
        std::memcpy(out + 6 * i, mesh.positions[i].data(), 3 * sizeof(float));
        std::memcpy(out + 6 * i + 3, (*normals)[i].data(), 3 * sizeof(float));
    }

    std::vector<uint32_t> flat(mesh.triangles.size() * 3);
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
        for (int c = 0; c < 3; ++c) flat[3 * t + c] = mesh.triangles[t][c];
    const bool topologyChanged = flat != triangles;
    if (topologyChanged) {
        glNamedBufferData(indices, GLsizeiptr(std::max<size_t>(flat.size(), 1) * sizeof(uint32_t)),
                          flat.empty() ? nullptr : flat.data(), GL_STATIC_DRAW);
        indexCount = flat.size();
        triangles = flat;
    }
    if (topologyChanged || triangleTypes != types) {
        // Only the region's triangles are drawn for generated hair; the SSBO
        // gives each of them (gl_PrimitiveID) its hair type.
        std::vector<uint32_t> list, typeList;
        for (size_t t = 0; t < triangleTypes.size() && t < mesh.triangles.size(); ++t) {
            if (!triangleTypes[t]) continue;
            for (int c = 0; c < 3; ++c) list.push_back(mesh.triangles[t][c]);
            typeList.push_back(triangleTypes[t]);
        }
        glNamedBufferData(furIndices, GLsizeiptr(std::max<size_t>(list.size(), 1) * sizeof(uint32_t)),
                          list.empty() ? nullptr : list.data(), GL_STATIC_DRAW);
        glNamedBufferData(furTypes, GLsizeiptr(std::max<size_t>(typeList.size(), 4) * sizeof(uint32_t)),
                          nullptr, GL_STATIC_DRAW);
        if (!typeList.empty())
            glNamedBufferSubData(furTypes, 0, GLsizeiptr(typeList.size() * sizeof(uint32_t)), typeList.data());
        furIndexCount = list.size();
        types = triangleTypes;
    }
    if (!hairTypes || !sameTypes(hairTypeList, hairTypeRows)) {
        // Hair types are read from a texture (as Dehlin and Styngberg 2017 do): one column per type.
        const int columns = std::max<int>(1, int(hairTypeList.size()));
        std::vector<float> texels(size_t(columns) * 2 * 4, 0.f);
        for (size_t i = 0; i < hairTypeList.size(); ++i) {
            const HairType& h = hairTypeList[i];
            const float row0[4] = {h.color.x(), h.color.y(), h.color.z(), float(h.segments)};
            const float row1[4] = {h.segmentLength, h.forceWeight, h.rootRadius, h.tipRadius};
            std::memcpy(&texels[i * 4], row0, sizeof(row0));
            std::memcpy(&texels[(size_t(columns) + i) * 4], row1, sizeof(row1));
        }
        if (hairTypes) glDeleteTextures(1, &hairTypes);
        glCreateTextures(GL_TEXTURE_2D, 1, &hairTypes);
        glTextureStorage2D(hairTypes, 1, GL_RGBA32F, columns, 2);
        glTextureSubImage2D(hairTypes, 0, 0, 0, columns, 2, GL_RGBA, GL_FLOAT, texels.data());
        glTextureParameteri(hairTypes, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(hairTypes, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        hairTypeRows = hairTypeList;
    }
}

}  // namespace hp
