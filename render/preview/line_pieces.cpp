#include "render/preview/line_pieces.h"

#include "render/preview/gl_context.h"  // softwareRasterizer

#include <epoxy/gl.h>

#include <algorithm>

namespace hp {

namespace {

/// A buffer of at least `bytes` in `id` (grown by half again: strands move).
void ensureBuffer(unsigned& id, size_t& capacity, size_t bytes) {
    if (id && capacity >= bytes) return;
    if (id) glDeleteBuffers(1, &id);
    capacity = std::max<size_t>(bytes + bytes / 2, 256);
    glCreateBuffers(1, &id);
    glNamedBufferStorage(id, GLsizeiptr(capacity), nullptr, GL_DYNAMIC_STORAGE_BIT);
}

}  // namespace

bool linePiecesInCompute(int setting, const std::string& renderer) {
    if (setting >= 0) return setting > 0;
    return softwareRasterizer(renderer);
}

void LinePieces::compile(bool on, const std::vector<std::string>& defines, const std::vector<std::string>& shading) {
    count = GlProgram();
    emit = GlProgram();
    lines = GlProgram();
    if (!on) return;
    const std::vector<std::pair<ShaderStage, std::string>> stages = {{ShaderStage::Compute, "strand_pieces.comp"}};
    std::vector<std::string> counting = defines, emitting = defines;
    counting.push_back("COUNT");
    emitting.push_back("EMIT");
    count = GlProgram("strand pieces (count)", stages, counting);
    emit = GlProgram("strand pieces (emit)", stages, emitting);
    lines = GlProgram("strand pieces", {{ShaderStage::Vertex, "strand_pieces.vert"}, {ShaderStage::Fragment, "hair.frag"}},
                      shading);
}

void LinePieces::countPieces(const StrandBuffers& strands) {
    indexCount = pointCount = 0;
    const size_t patches = strands.patchSize > 0 ? strands.indexCount / size_t(strands.patchSize) : 0;
    patchCount = patches;
    if (!patches) return;
    ensureBuffer(shape, shapeCapacity, patches * 4);
    ensureBuffer(firsts, firstCapacity, patches * 8);
    strandPoints = strands.vertices.id();
    strandPatches = strands.indices;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, strandPoints);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, strandPatches);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, shape);
    count.use();
    glProgramUniform1ui(count.id(), count.uniform("uPatches"), GLuint(patches));
    dispatchRows(patches);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    // The sums on the CPU: a read back of 4 bytes a patch, against a GPU scan's passes.
    shapes.resize(patches);
    glGetNamedBufferSubData(shape, 0, GLsizeiptr(patches * 4), shapes.data());
    firstPairs.resize(patches * 2);
    uint32_t vertex = 0, index = 0;
    for (size_t p = 0; p < patches; ++p) {
        const uint32_t pieces = ((shapes[p] >> 8) & 255u) * (shapes[p] & 255u);
        firstPairs[2 * p] = vertex;
        firstPairs[2 * p + 1] = index;
        if (pieces) vertex += pieces + 1, index += 2 * pieces;
    }
    pointCount = vertex;
    indexCount = index;
    if (!index) return;
    glNamedBufferSubData(firsts, 0, GLsizeiptr(patches * 8), firstPairs.data());
}

void LinePieces::emitPieces() {
    if (!indexCount) return;
    ensureBuffer(vertices, vertexCapacity, pointCount * 32);
    ensureBuffer(indices, indexCapacity, indexCount * 4);
    if (!vao) {
        glCreateVertexArrays(1, &vao);
        glEnableVertexArrayAttrib(vao, 0);
        glEnableVertexArrayAttrib(vao, 1);
        glVertexArrayAttribFormat(vao, 0, 4, GL_FLOAT, GL_FALSE, 0);
        glVertexArrayAttribFormat(vao, 1, 4, GL_FLOAT, GL_FALSE, 16);
        glVertexArrayAttribBinding(vao, 0, 0);
        glVertexArrayAttribBinding(vao, 1, 0);
    }
    glVertexArrayVertexBuffer(vao, 0, vertices, 0, 32);
    glVertexArrayElementBuffer(vao, indices);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, firsts);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, vertices);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, strandPoints);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, strandPatches);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, shape);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, indices);
    emit.use();
    glProgramUniform1ui(emit.id(), emit.uniform("uPatches"), GLuint(patchCount));
    dispatchRows(patchCount);
    glMemoryBarrier(GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT | GL_ELEMENT_ARRAY_BARRIER_BIT);
}

void LinePieces::draw() const {
    if (!indexCount) return;
    lines.use();
    glBindVertexArray(vao);
    glDrawElements(GL_LINES, GLsizei(indexCount), GL_UNSIGNED_INT, nullptr);
}

void LinePieces::destroy() {
    for (unsigned* b : {&shape, &firsts, &vertices, &indices})
        if (*b) glDeleteBuffers(1, b), *b = 0;
    if (vao) glDeleteVertexArrays(1, &vao), vao = 0;
    shapeCapacity = firstCapacity = vertexCapacity = indexCapacity = 0;
    indexCount = pointCount = patchCount = 0;
}

}  // namespace hp
