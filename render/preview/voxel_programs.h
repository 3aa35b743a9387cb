// The programs that voxelize hair from a light (shaders/voxelize.frag behind
// the strand tessellation, the captured pieces and the generated hair),
// compiled for the frame's voxel mode, splat and weight (internal to the
// preview).
#pragma once

#include "render/preview/gl_program.h"
#include "render/preview/preview.h"

#include <string>
#include <vector>

namespace hp {

/// voxelize.frag takes the mode and the weight as compile-time constants:
/// llvmpipe runs both sides of a branch on a uniform under an execution
/// mask, so with uniforms every fragment paid the trilinear splat's eight
/// atomics and the crossing weight whatever the settings.
struct VoxelPrograms {
    GlProgram strands;  ///< strand.tesc/tese from the light, capturing its pieces (CAPTURE)
    GlProgram captured; ///< the captured pieces, drawn again for the other lights
    GlProgram fur;      ///< generated hair

    /// The defines of `shadow`'s mode, splat and weight ("VOXEL_MODE n",
    /// "VOXEL_CROSSINGS 0/1").
    static std::vector<std::string> defines(const PreviewShadowSettings& shadow);
    /// Compiles what `shadow`, the strand patch size and the fewest pieces
    /// per segment need (strand.tesc MIN_SEGMENTS_PER_PIECE: at least one
    /// piece per this many segments; 0 = none) unless already compiled for
    /// them. Needs a current context.
    void ensure(const PreviewShadowSettings& shadow, int strandPatchSize, int minSegmentsPerPiece);

  private:
    std::vector<std::string> defines_;
    int patchSize_ = 0, minSegmentsPerPiece_ = 0;
};

}  // namespace hp
