// Scalp selection: which triangles of the rest mesh grow hair.
#pragma once

#include "pipeline/head/head_rig.h"

#include <filesystem>
#include <string>
#include <vector>

namespace hp {

enum class ScalpMethod {
    All,          ///< every triangle
    Material,     ///< triangles whose material is one of `materials`
    VertexColor,  ///< mean of the corners' colour channel ≥ threshold
    Texture,      ///< mean of a mask image (sampled through the uvs) ≥ threshold
    Region,       ///< a spherical cap: the centroid's direction from `center` within `angle` of `axis`
};

struct ScalpSettings {
    ScalpMethod method = ScalpMethod::All;
    std::vector<std::string> materials;
    int channel = 0;         ///< 0..3 = R, G, B, A (vertex colour and texture)
    float threshold = 0.5f;  ///< vertex colour and texture
    std::filesystem::path mask;
    Vec3f center = Vec3f::Zero();  ///< region, world metres
    Vec3f axis = Vec3f::UnitY();
    float angleDegrees = 90.f;
};

/// @brief The scalp used when the scene names none (head.scalp.method:
/// auto): the materials whose name contains "scalp" or "hair" (any case) if
/// the file has one, else a cap over the top and back of the head: a sphere
/// fitted to the upper part of the mesh (the cranium, found from the up axis
/// +Y and the bounds), its pole tilted 24° toward the back (-Z, glTF's
/// behind), 72° wide, as the default scene's partial sphere. Face, chin and
/// neck lie outside it. `why` receives a sentence saying what was chosen.
ScalpSettings defaultScalp(const HeadRig& rig, const TriangleMesh& rest, std::string& why);

/// @brief Per-triangle scalp mask (1 = scalp) of `rest` (the rig's rest
/// mesh, whose triangles follow HeadRig::meshes). The texture mask is read
/// through OpenImageIO (AssetError naming the file); uv (0, 0) is the
/// image's bottom-left corner (assimp's convention, which flips glTF's V),
/// sampled bilinearly with wrap-around at the centroid and three points
/// towards the corners. Throws Error when the data a method needs is
/// missing (no vertex colours, no uvs, unknown material) or nothing is selected.
std::vector<uint8_t> selectScalp(const HeadRig& rig, const TriangleMesh& rest, const ScalpSettings& settings);

}  // namespace hp
