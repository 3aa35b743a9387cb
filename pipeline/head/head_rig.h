// An imported head asset in plain data: node hierarchy, meshes with skins
// and morph targets, animation clips. pipeline/head/head_import.cpp fills it from
// assimp; posing it needs no assimp (so benchmarks and tests can build rigs
// directly).
//
// Conventions: transforms map column vectors (p' = M p); times are seconds
// (converted from the file's ticks at import); `placement` takes the asset's
// units and axes to hairpipe's world (metres, Y up) — see head_import.h.
#pragma once

#include "sim/strands/head.h"

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace hp {

using Affine3f = Eigen::Affine3f;

/// Key frames of one property, times ascending (seconds).
template <typename T>
struct KeyTrack {
    std::vector<double> times;
    std::vector<T> values;
};

struct RigNode {
    std::string name;
    int parent = -1;  ///< index in HeadRig::nodes; parents come before children
    Affine3f local = Affine3f::Identity();  ///< rest transform relative to the parent
};

/// A node's animated translation, rotation and scale (T · R · S). An empty
/// track keeps the node's rest value.
struct NodeTrack {
    int node = -1;
    KeyTrack<Vec3f> translation;
    KeyTrack<Eigen::Quaternionf> rotation;
    KeyTrack<Vec3f> scale;
};

/// Animated morph weights of every mesh the node instances.
struct MorphTrack {
    int node = -1;
    std::vector<double> times;
    std::vector<std::vector<float>> weights;  ///< per key, one weight per target
};

struct RigClip {
    std::string name;
    double duration = 0.0;  ///< seconds
    double keyRate = 0.0;   ///< keys per second of the densest track (what the clip was sampled at)
    std::vector<NodeTrack> tracks;
    std::vector<MorphTrack> morphs;
};

/// One mesh instance (an assimp mesh placed by a node).
struct RigMesh {
    std::string name;
    int instance = 0;       ///< index among the file's mesh instances (what head.meshes counts)
    int node = -1;          ///< the node that places it (unskinned meshes move with it)
    uint32_t material = 0;  ///< index in HeadRig::materials
    std::vector<Vec3f> positions, normals;  ///< bind pose, mesh space
    std::vector<Vec2f> uvs;                 ///< empty when the mesh has none
    std::vector<Eigen::Vector4f> colors;    ///< RGBA per vertex; empty when none
    std::vector<Tri> triangles;

    /// Skin: bone b is node boneNodes[b] with boneOffsets[b] mapping mesh
    /// space to that bone's space at bind time. Vertex v's influences are
    /// [influenceStart[v], influenceStart[v+1]) of influenceBone/Weight,
    /// weights normalised to sum 1; a vertex without influences follows `node`.
    std::vector<int> boneNodes;
    std::vector<Affine3f> boneOffsets;
    std::vector<uint32_t> influenceStart;
    std::vector<uint32_t> influenceBone;
    std::vector<float> influenceWeight;

    /// Morph targets as deltas from the bind pose (normal deltas may be empty).
    std::vector<std::string> morphNames;
    std::vector<std::vector<Vec3f>> morphPositions;
    std::vector<std::vector<Vec3f>> morphNormals;
    std::vector<float> morphDefaults;  ///< weights when no clip drives them

    bool skinned() const { return !boneNodes.empty(); }
};

struct HeadRig {
    std::string file;  ///< for messages
    std::vector<RigNode> nodes;
    std::vector<RigMesh> meshes;
    std::vector<std::string> materials;
    std::vector<RigClip> clips;
    /// Asset space -> world: unit scale, up-axis conversion, static placement.
    Affine3f placement = Affine3f::Identity();
    /// Metres per file unit the file itself declares (FBX GlobalSettings
    /// UnitScaleFactor, centimetres per unit, / 100); 0: it declares none.
    double fileUnitScale = 0.0;
    /// Metres per file unit applied (head.unit_scale, or the file's own
    /// when the scene does not set it).
    double unitScale = 1.0;
    /// The up axis the file declares ('x', 'y', 'z'; FBX GlobalSettings
    /// UpAxis with a positive sign), 0: none; and the one applied.
    char fileUpAxis = 0, upAxis = 'y';

    size_t vertexCount() const;
    size_t triangleCount() const;
    size_t boneCount() const;   ///< distinct bone nodes over all skins
    size_t morphCount() const;  ///< morph targets over all meshes

    /// World transform (placement included) of every node at `seconds` into
    /// clip `clip` (-1: the rest pose). Keys are interpolated linearly
    /// (rotations by slerp) and held before the first and after the last.
    std::vector<Affine3f> nodeTransforms(int clip, double seconds) const;

    /// The meshes concatenated (in `meshes` order): triangles, uvs (zero
    /// where a mesh has none) and bind-pose world positions and normals.
    TriangleMesh restMesh() const;

    /// Poses the meshes at `seconds` into clip `clip` (-1: rest): morph
    /// targets, then linear blend skinning with every influence (or the
    /// node's rigid transform), then placement. Writes `out.positions` and
    /// `out.normals` (resized as needed); the topology is restMesh()'s.
    /// Vertices are processed in parallel; the result does not depend on
    /// the thread count.
    void pose(int clip, double seconds, TriangleMesh& out) const;

    /// Per triangle of restMesh(): the material index.
    std::vector<uint32_t> triangleMaterials() const;
    /// Per vertex of restMesh(): RGBA colour (white where a mesh has none).
    std::vector<Eigen::Vector4f> vertexColors() const;
    bool hasUvs() const;
    bool hasColors() const;

    /// Multi-line description for `hairpipe info` (meshes, triangles, bones,
    /// morphs, clips with duration and key rate).
    std::string summary() const;
};

}  // namespace hp
