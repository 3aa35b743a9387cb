// The compute pass that shades the strand vertices once a frame
// (shaders/strand_shade.comp). Why: llvmpipe runs the vertex and
// tessellation stages on its calling thread alone, a patch at a time with
// SIMD lanes the patch's few points leave mostly empty, and compute shaders
// on all its threads with full lanes; the tessellation evaluation stage then
// only interpolates the vertices' radiance (docs/benchmarks.md, "B-render
// preview").
#include "render/preview/gl_program.h"
#include "render/preview/preview_gpu.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace hp {

namespace {

/// Roots and tips of the strands `offsets` delimits, a byte a vertex, four a
/// word (the compute pass's Flags buffer): bit 0 a root, bit 1 a tip.
std::vector<uint32_t> rootAndTipFlags(const std::vector<uint32_t>& offsets) {
    const size_t vertices = offsets.empty() ? 0 : offsets.back();
    std::vector<uint32_t> flags((vertices + 3) / 4 + 1, 0u);
    for (size_t k = 0; k + 1 < offsets.size(); ++k) {
        const uint32_t first = offsets[k], last = offsets[k + 1];
        if (last == first) continue;
        flags[first / 4] |= 1u << (8 * (first % 4));
        flags[(last - 1) / 4] |= 2u << (8 * ((last - 1) % 4));
    }
    return flags;
}

}  // namespace

void ShadedPoints::shade(const StrandBuffers& strands, const GlProgram& program) {
    const size_t vertexCount = strands.offsets.empty() ? 0 : strands.offsets.back();
    if (vertexCount > capacity || !buffer) {
        destroy();
        capacity = std::max<size_t>(vertexCount + vertexCount / 2, 64);  // room to grow, as PersistentBuffer
        glCreateBuffers(1, &buffer);
        glNamedBufferStorage(buffer, GLsizeiptr(capacity * 4 * sizeof(float)), nullptr, 0);
        glCreateTextures(GL_TEXTURE_BUFFER, 1, &texture);
        glTextureBuffer(texture, GL_RGBA32F, buffer);
        glCreateBuffers(1, &flags);
    }
    if (vertexCount > 0) {
        // Only this pass reads them, so they are built here, not in every frame's upload.
        const std::vector<uint32_t> words = rootAndTipFlags(strands.offsets);
        glNamedBufferData(flags, GLsizeiptr(words.size() * sizeof(uint32_t)), words.data(), GL_DYNAMIC_DRAW);
        program.use();
        glProgramUniform1ui(program.id(), program.uniform("uVertices"), GLuint(vertexCount));
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, strands.vertices.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, flags);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, buffer);
        dispatchRows(vertexCount);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);  // the tessellation stage reads it as a buffer texture
    }
    glBindTextureUnit(kUnit, texture);
}

void ShadedPoints::destroy() {
    if (texture) glDeleteTextures(1, &texture);
    if (buffer) glDeleteBuffers(1, &buffer);
    if (flags) glDeleteBuffers(1, &flags);
    texture = buffer = flags = 0;
    capacity = 0;
}

}  // namespace hp
