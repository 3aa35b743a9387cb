// Voxelization programs specialised for the voxel settings (voxel_programs.h).
#include "render/preview/voxel_programs.h"

#include "core/errors.h"

namespace hp {

std::vector<std::string> VoxelPrograms::defines(const PreviewShadowSettings& shadow) {
    // voxelize.frag's uMode: 0 binary nearest, 1 additive nearest, 2 additive trilinear.
    const int mode = shadow.mode == VoxelMode::Binary ? 0 : (shadow.splat == VoxelSplat::Trilinear ? 2 : 1);
    return {cat("VOXEL_MODE ", mode), cat("VOXEL_CROSSINGS ", shadow.weight == VoxelWeight::Crossings ? 1 : 0)};
}

void VoxelPrograms::ensure(const PreviewShadowSettings& shadow, int strandPatchSize, int minSegmentsPerPiece) {
    const std::vector<std::string> wanted = defines(shadow);
    const bool settingsChanged = wanted != defines_ || !captured.id();
    if (settingsChanged || strandPatchSize != patchSize_ || minSegmentsPerPiece != minSegmentsPerPiece_ ||
        !strands.id()) {
        std::vector<std::string> d = wanted;
        d.push_back(cat("PATCH_SIZE ", strandPatchSize));
        d.push_back("CAPTURE");
        if (minSegmentsPerPiece > 0) d.push_back(cat("MIN_SEGMENTS_PER_PIECE ", minSegmentsPerPiece));
        strands = GlProgram("strand voxelization",
                            {{ShaderStage::Vertex, "strand.vert"},
                             {ShaderStage::TessControl, "strand.tesc"},
                             {ShaderStage::TessEvaluation, "strand.tese"},
                             {ShaderStage::Fragment, "voxelize.frag"}},
                            d);
        patchSize_ = strandPatchSize;
        minSegmentsPerPiece_ = minSegmentsPerPiece;
    }
    if (settingsChanged) {
        captured = GlProgram("captured strand voxelization",
                             {{ShaderStage::Vertex, "voxel_lines.vert"}, {ShaderStage::Fragment, "voxelize.frag"}},
                             wanted);
        std::vector<std::string> d = wanted;
        d.push_back("VOXEL_PASS");
        fur = GlProgram("generated hair voxelization",
                        {{ShaderStage::Vertex, "fur.vert"},
                         {ShaderStage::TessControl, "fur.tesc"},
                         {ShaderStage::TessEvaluation, "fur.tese"},
                         {ShaderStage::Geometry, "fur.geom"},
                         {ShaderStage::Fragment, "voxelize.frag"}},
                        d);
        defines_ = wanted;
    }
}

}  // namespace hp
