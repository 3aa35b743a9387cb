// The thin strands' line pieces made by compute passes (shaders/
// strand_pieces.comp) and drawn as plain lines, in place of the camera's
// tessellated line pass (internal to render/preview/*.cpp). Why: llvmpipe
// runs the tessellation stages on its calling thread alone, a patch at a
// time, ~2 s of a 100k-strand frame (docs/benchmarks.md "the strand pass on
// llvmpipe"); compute shaders run on all its threads. The pieces are
// strand.tesc's and strand.tese's: the same counts, points and shading.
#pragma once

#include "render/preview/gl_program.h"
#include "render/preview/preview_gpu.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace hp {

/// PreviewSettings::piecesInCompute for a renderer (GL_RENDERER): -1 is
/// compute on llvmpipe and softpipe.
bool linePiecesInCompute(int setting, const std::string& renderer);

struct LinePieces {
    unsigned shape = 0, firsts = 0, vertices = 0, indices = 0, vao = 0;
    size_t shapeCapacity = 0, firstCapacity = 0, vertexCapacity = 0, indexCapacity = 0;
    size_t indexCount = 0, pointCount = 0, patchCount = 0;
    unsigned strandPoints = 0, strandPatches = 0;  ///< the strand buffers counted (not owned)
    std::vector<uint32_t> shapes, firstPairs;  ///< the counts read back, the prefix sums sent

    GlProgram count, emit, lines;

    /// Compiles the programs for the hair programs' `defines` (PATCH_SIZE
    /// and the shading's) and `shading` (hair.frag's), or drops them (`on` false).
    void compile(bool on, const std::vector<std::string>& defines, const std::vector<std::string>& shading);
    bool compiled() const { return emit.id() != 0; }
    /// Counts the pieces of the patches of `strands` (in its current order)
    /// with the camera's uniforms bound and sums them on the CPU.
    void countPieces(const StrandBuffers& strands);
    /// Then emits and shades them (the camera's uniforms and textures bound).
    void emitPieces();
    /// Draws them as GL_LINES (strand_pieces.vert, hair.frag).
    void draw() const;
    void destroy();
};

}  // namespace hp
