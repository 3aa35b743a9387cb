// Head import through assimp (the only file that includes assimp's headers
// is head_import.cpp). Any format assimp reads: glTF/GLB, FBX, Collada, OBJ...
//
// The import boundary, where units and axes become hairpipe's:
// - assimp hands over the file's node hierarchy as stored (glTF is Y up by
//   specification; a file's own root node, e.g. CesiumMan's "Z_UP", is kept
//   and so already applied). assimp's post-processing triangulates, welds
//   identical vertices, drops points and lines, and generates smooth normals
//   where the file has none (Fox.glb).
// - `unitScale` multiplies asset units into metres (0.01 for centimetres).
//   Unless the scene sets it, the file's own unit is used where assimp
//   exposes one: an FBX file's GlobalSettings UnitScaleFactor (centimetres
//   per unit) in the scene metadata. glTF is metres by specification, and
//   assimp already applies a Collada file's <unit>. The same for the up
//   axis: an FBX file's UpAxis (X, Y or Z, positive sign) unless the scene
//   sets head.up_axis.
// - `upAxis` names the asset's up axis; Z up is turned to Y up by a -90°
//   rotation about X ((x, y, z) -> (x, z, -y)), X up by +90° about Z.
// - `placement` (the scene's translate/rotate) is applied last, in metres.
// Together they form HeadRig::placement; times become seconds.
#pragma once

#include "core/errors.h"
#include "pipeline/head/head_rig.h"

#include <filesystem>
#include <string>
#include <vector>

namespace hp {

enum class UpAxis { Y, Z, X };

struct HeadImportSettings {
    std::filesystem::path file;
    /// Mesh instances to keep, each a name or a 0-based index (in the order
    /// `hairpipe info` lists them); a name matches a mesh, the node placing
    /// it, or a glTF mesh split into primitives ("Head" keeps "Head-0",
    /// "Head-1", ...). Empty: every mesh.
    std::vector<std::string> meshes;
    double unitScale = 1.0;
    /// False: the scene leaves head.unit_scale unset, so a unit the file
    /// declares (FBX UnitScaleFactor) replaces `unitScale`.
    bool unitScaleGiven = true;
    UpAxis upAxis = UpAxis::Y;
    /// False: the scene leaves head.up_axis unset, so an up axis the file
    /// declares (FBX UpAxis) replaces `upAxis`.
    bool upAxisGiven = true;
    Affine3f placement = Affine3f::Identity();
};

/// A selection (mesh or clip) that names nothing in the file; the message
/// lists what the file has. The pipeline reports it at the scene key.
class RigSelectionError : public Error {
  public:
    using Error::Error;
};

/// @brief Reads the file into a HeadRig. Throws AssetError naming the file
/// when it is missing, unreadable, truncated or has no triangle mesh, and
/// RigSelectionError when `meshes` names a mesh the file lacks.
HeadRig importHead(const HeadImportSettings& settings);

/// The index of a clip by name or 0-based index; "" is the first clip (or -1
/// when there is none), "none" is -1 (the rest pose). Throws RigSelectionError.
int findClip(const HeadRig& rig, const std::string& selector);

/// Rotation taking `up` to +Y (identity for Y).
Eigen::Matrix3f upAxisRotation(UpAxis up);

}  // namespace hp
