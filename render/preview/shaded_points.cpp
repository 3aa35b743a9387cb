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

namespace hp {

void ShadedPoints::shade(const StrandBuffers& strands, size_t vertexCount, const GlProgram& program) {
    if (vertexCount > capacity || !buffer) {
        destroy();
        capacity = std::max<size_t>(vertexCount + vertexCount / 2, 64);  // room to grow, as PersistentBuffer
        glCreateBuffers(1, &buffer);
        glNamedBufferStorage(buffer, GLsizeiptr(capacity * 4 * sizeof(float)), nullptr, 0);
        glCreateTextures(GL_TEXTURE_BUFFER, 1, &texture);
        glTextureBuffer(texture, GL_RGBA32F, buffer);
    }
    if (vertexCount > 0) {
        program.use();
        glProgramUniform1ui(program.id(), program.uniform("uVertices"), GLuint(vertexCount));
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, strands.vertices.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, strands.vertexFlags);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, buffer);
        const size_t invocations = vertexCount;
        // Rows of at most 65535 groups (GL's least guaranteed count per dimension).
        const size_t groups = (invocations + 63) / 64, row = std::min<size_t>(groups, 65535);
        glDispatchCompute(GLuint(row), GLuint((groups + row - 1) / row), 1);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);  // the tessellation stage reads it as a buffer texture
    }
    glBindTextureUnit(kUnit, texture);
}

void ShadedPoints::destroy() {
    if (texture) glDeleteTextures(1, &texture);
    if (buffer) glDeleteBuffers(1, &buffer);
    texture = buffer = 0;
    capacity = 0;
}

}  // namespace hp
