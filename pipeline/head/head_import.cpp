#include "pipeline/head/head_import.h"

#include "core/log.h"

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <system_error>

namespace hp {

namespace {

namespace fs = std::filesystem;

Affine3f toAffine(const aiMatrix4x4& m) {
    Eigen::Matrix4f e;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) e(r, c) = m[r][c];
    Affine3f a;
    a.matrix() = e;
    return a;
}

Vec3f toVec(const aiVector3D& v) { return Vec3f(v.x, v.y, v.z); }

bool isIndex(const std::string& s) {
    return !s.empty() && s.size() < 10 && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
}

/// "Head" names the glTF primitives "Head-0", "Head-1", ... assimp makes of one mesh.
bool matchesMeshName(const std::string& selector, const std::string& name) {
    if (name == selector) return true;
    if (name.size() <= selector.size() + 1 || name.compare(0, selector.size(), selector) != 0 ||
        name[selector.size()] != '-')
        return false;
    return isIndex(name.substr(selector.size() + 1));
}

struct Instance {
    const aiMesh* mesh;
    int node;
};

void flatten(const aiNode* n, int parent, HeadRig& rig, const aiScene* scene, std::vector<Instance>& instances) {
    const int index = int(rig.nodes.size());
    rig.nodes.push_back({n->mName.C_Str(), parent, toAffine(n->mTransformation)});
    for (unsigned i = 0; i < n->mNumMeshes; ++i) instances.push_back({scene->mMeshes[n->mMeshes[i]], index});
    for (unsigned i = 0; i < n->mNumChildren; ++i) flatten(n->mChildren[i], index, rig, scene, instances);
}

RigMesh convertMesh(const aiMesh* a, int node, const std::map<std::string, int>& nodeIndex, const std::string& file) {
    RigMesh m;
    m.name = a->mName.C_Str();
    m.node = node;
    m.material = a->mMaterialIndex;
    const unsigned nv = a->mNumVertices;
    for (unsigned v = 0; v < nv; ++v) m.positions.push_back(toVec(a->mVertices[v]));
    if (a->HasNormals())
        for (unsigned v = 0; v < nv; ++v) m.normals.push_back(toVec(a->mNormals[v]));
    if (a->HasTextureCoords(0))
        for (unsigned v = 0; v < nv; ++v) m.uvs.emplace_back(a->mTextureCoords[0][v].x, a->mTextureCoords[0][v].y);
    if (a->HasVertexColors(0))
        for (unsigned v = 0; v < nv; ++v) {
            const aiColor4D& c = a->mColors[0][v];
            m.colors.emplace_back(c.r, c.g, c.b, c.a);
        }
    for (unsigned f = 0; f < a->mNumFaces; ++f)
        if (a->mFaces[f].mNumIndices == 3)
            m.triangles.push_back({a->mFaces[f].mIndices[0], a->mFaces[f].mIndices[1], a->mFaces[f].mIndices[2]});

    if (a->HasBones()) {
        std::vector<std::vector<std::pair<uint32_t, float>>> influences(nv);
        for (unsigned b = 0; b < a->mNumBones; ++b) {
            const aiBone* bone = a->mBones[b];
            const auto it = nodeIndex.find(bone->mName.C_Str());
            if (it == nodeIndex.end())
                throw AssetError(file, cat("bone '", bone->mName.C_Str(), "' of mesh '", m.name, "' has no node"));
            m.boneNodes.push_back(it->second);
            m.boneOffsets.push_back(toAffine(bone->mOffsetMatrix));
            for (unsigned w = 0; w < bone->mNumWeights; ++w) {
                const aiVertexWeight& vw = bone->mWeights[w];
                if (vw.mVertexId >= nv)
                    throw AssetError(file, cat("bone '", bone->mName.C_Str(), "' weights vertex ", vw.mVertexId,
                                               " of a ", nv, "-vertex mesh"));
                if (vw.mWeight > 0.f) influences[vw.mVertexId].emplace_back(b, vw.mWeight);
            }
        }
        m.influenceStart.push_back(0);
        for (auto& list : influences) {
            float sum = 0.f;
            for (const auto& [b, w] : list) sum += w;
            for (const auto& [b, w] : list) {
                m.influenceBone.push_back(b);
                m.influenceWeight.push_back(w / sum);  // weights sum to 1 (files are not always exact)
            }
            m.influenceStart.push_back(uint32_t(m.influenceBone.size()));
        }
    }

    // Morph targets: assimp stores each target's absolute positions (and
    // normals); keep deltas from the base, which blend linearly.
    for (unsigned k = 0; k < a->mNumAnimMeshes; ++k) {
        const aiAnimMesh* t = a->mAnimMeshes[k];
        if (!t->HasPositions() || t->mNumVertices != nv) continue;
        m.morphNames.push_back(t->mName.length ? t->mName.C_Str() : cat("target", k));
        m.morphDefaults.push_back(t->mWeight);
        std::vector<Vec3f> dp(nv), dn;
        for (unsigned v = 0; v < nv; ++v) dp[v] = toVec(t->mVertices[v]) - m.positions[v];
        if (t->HasNormals() && !m.normals.empty()) {
            dn.resize(nv);
            for (unsigned v = 0; v < nv; ++v) dn[v] = toVec(t->mNormals[v]) - m.normals[v];
        }
        m.morphPositions.push_back(std::move(dp));
        m.morphNormals.push_back(std::move(dn));
    }
    return m;
}

RigClip convertClip(const aiAnimation* a, const std::map<std::string, int>& nodeIndex,
                    const std::vector<Instance>& instances) {
    RigClip c;
    c.name = a->mName.C_Str();
    const double tps = a->mTicksPerSecond > 0.0 ? a->mTicksPerSecond : 25.0;  // assimp's default
    c.duration = a->mDuration / tps;
    auto rate = [&](size_t keys, double first, double last) {
        if (keys > 1 && last > first) c.keyRate = std::max(c.keyRate, double(keys - 1) / ((last - first) / tps));
    };
    for (unsigned i = 0; i < a->mNumChannels; ++i) {
        const aiNodeAnim* ch = a->mChannels[i];
        const auto it = nodeIndex.find(ch->mNodeName.C_Str());
        if (it == nodeIndex.end()) continue;  // animates a node outside the scene graph
        NodeTrack t;
        t.node = it->second;
        for (unsigned k = 0; k < ch->mNumPositionKeys; ++k) {
            t.translation.times.push_back(ch->mPositionKeys[k].mTime / tps);
            t.translation.values.push_back(toVec(ch->mPositionKeys[k].mValue));
        }
        for (unsigned k = 0; k < ch->mNumRotationKeys; ++k) {
            const aiQuaternion& q = ch->mRotationKeys[k].mValue;
            t.rotation.times.push_back(ch->mRotationKeys[k].mTime / tps);
            t.rotation.values.push_back(Eigen::Quaternionf(q.w, q.x, q.y, q.z).normalized());
        }
        for (unsigned k = 0; k < ch->mNumScalingKeys; ++k) {
            t.scale.times.push_back(ch->mScalingKeys[k].mTime / tps);
            t.scale.values.push_back(toVec(ch->mScalingKeys[k].mValue));
        }
        if (ch->mNumPositionKeys)
            rate(ch->mNumPositionKeys, ch->mPositionKeys[0].mTime, ch->mPositionKeys[ch->mNumPositionKeys - 1].mTime);
        if (ch->mNumRotationKeys)
            rate(ch->mNumRotationKeys, ch->mRotationKeys[0].mTime, ch->mRotationKeys[ch->mNumRotationKeys - 1].mTime);
        c.tracks.push_back(std::move(t));
    }
    for (unsigned i = 0; i < a->mNumMorphMeshChannels; ++i) {
        const aiMeshMorphAnim* ch = a->mMorphMeshChannels[i];
        // glTF names the channel after the node; other formats after the mesh.
        int node = -1;
        if (const auto it = nodeIndex.find(ch->mName.C_Str()); it != nodeIndex.end()) node = it->second;
        for (const Instance& in : instances)
            if (node < 0 && matchesMeshName(ch->mName.C_Str(), in.mesh->mName.C_Str())) node = in.node;
        if (node < 0 || ch->mNumKeys == 0) continue;
        MorphTrack t;
        t.node = node;
        for (unsigned k = 0; k < ch->mNumKeys; ++k) {
            const aiMeshMorphKey& key = ch->mKeys[k];
            std::vector<float> w;
            for (unsigned j = 0; j < key.mNumValuesAndWeights; ++j) {
                if (key.mValues[j] >= w.size()) w.resize(key.mValues[j] + 1, 0.f);
                w[key.mValues[j]] = float(key.mWeights[j]);
            }
            t.times.push_back(key.mTime / tps);
            t.weights.push_back(std::move(w));
        }
        rate(ch->mNumKeys, ch->mKeys[0].mTime, ch->mKeys[ch->mNumKeys - 1].mTime);
        c.morphs.push_back(std::move(t));
    }
    return c;
}

/// Metres per unit an FBX file declares: assimp's FBX importer copies
/// GlobalSettings' UnitScaleFactor (centimetres per unit) into the scene
/// metadata without applying it. 0 when absent or not a positive number.
double declaredUnitScale(const aiScene* scene) {
    if (!scene->mMetaData) return 0.0;
    double cm = 0.0;
    float cmf = 0.f;
    int32_t cmi = 0;
    if (!scene->mMetaData->Get("UnitScaleFactor", cm)) {
        if (scene->mMetaData->Get("UnitScaleFactor", cmf)) cm = cmf;
        else if (scene->mMetaData->Get("UnitScaleFactor", cmi)) cm = cmi;
    }
    return std::isfinite(cm) && cm > 0.0 ? cm / 100.0 : 0.0;
}

/// The up axis an FBX file declares (assimp copies GlobalSettings' UpAxis, 0 =
/// X, 1 = Y, 2 = Z, and UpAxisSign into the metadata); 0 when absent or
/// negative (a down axis has no up_axis equivalent).
char declaredUpAxis(const aiScene* scene) {
    int32_t axis = -1, sign = 1;
    if (!scene->mMetaData || !scene->mMetaData->Get("UpAxis", axis)) return 0;
    scene->mMetaData->Get("UpAxisSign", sign);
    if (sign < 0 || axis < 0 || axis > 2) return 0;
    return "xyz"[axis];
}

}  // namespace

Eigen::Matrix3f upAxisRotation(UpAxis up) {
    switch (up) {
        case UpAxis::Z: return Eigen::AngleAxisf(float(-M_PI / 2), Vec3f::UnitX()).toRotationMatrix();
        case UpAxis::X: return Eigen::AngleAxisf(float(M_PI / 2), Vec3f::UnitZ()).toRotationMatrix();
        default: return Eigen::Matrix3f::Identity();
    }
}

HeadRig importHead(const HeadImportSettings& settings) {
    const std::string file = settings.file.string();
    std::error_code ec;
    if (!fs::exists(settings.file, ec)) throw AssetError(file, "head file not found");
    if (!fs::is_regular_file(settings.file, ec)) throw AssetError(file, "head file is not a regular file");

    Assimp::Importer importer;
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const aiScene* scene =
        importer.ReadFile(file, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_GenSmoothNormals |
                                    aiProcess_SortByPType | aiProcess_ValidateDataStructure);
    if (!scene) {
        const std::string why = importer.GetErrorString();
        // SortByPType removed every mesh: the file has only points or lines.
        if (why.find("No meshes remaining") != std::string::npos)
            throw AssetError(file, "contains no triangle mesh (only points or lines)");
        throw AssetError(file, cat("cannot read it as a mesh file: ", why));
    }
    if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !scene->mRootNode || scene->mNumMeshes == 0)
        throw AssetError(file, "contains no triangle mesh");

    HeadRig rig;
    rig.file = file;
    std::vector<Instance> instances;
    flatten(scene->mRootNode, -1, rig, scene, instances);
    std::map<std::string, int> nodeIndex;
    for (size_t i = 0; i < rig.nodes.size(); ++i) nodeIndex.emplace(rig.nodes[i].name, int(i));
    for (unsigned i = 0; i < scene->mNumMaterials; ++i) rig.materials.push_back(scene->mMaterials[i]->GetName().C_Str());

    // Which instances to keep.
    std::vector<bool> keep(instances.size(), settings.meshes.empty());
    for (const std::string& sel : settings.meshes) {
        bool any = false;
        for (size_t i = 0; i < instances.size(); ++i) {
            const bool hit = isIndex(sel) ? std::stoul(sel) == i
                                          : matchesMeshName(sel, instances[i].mesh->mName.C_Str()) ||
                                                sel == rig.nodes[size_t(instances[i].node)].name;
            if (hit) keep[i] = any = true;
        }
        if (!any) {
            std::string list;
            for (size_t i = 0; i < instances.size(); ++i)
                list += cat(i ? ", " : "", i, ": ", instances[i].mesh->mName.C_Str(), " (node ",
                            rig.nodes[size_t(instances[i].node)].name, ")");
            throw RigSelectionError(cat("no mesh '", sel, "' in ", file, "; it has ", list));
        }
    }
    for (size_t i = 0; i < instances.size(); ++i) {
        if (!keep[i]) continue;
        RigMesh m = convertMesh(instances[i].mesh, instances[i].node, nodeIndex, file);
        m.instance = int(i);
        if (!m.triangles.empty()) rig.meshes.push_back(std::move(m));
    }
    if (rig.meshes.empty()) throw AssetError(file, "contains no triangle mesh");
    for (unsigned i = 0; i < scene->mNumAnimations; ++i)
        rig.clips.push_back(convertClip(scene->mAnimations[i], nodeIndex, instances));

    // FBX only: other importers apply their format's unit and axis themselves
    // (Collada) or have none (glTF is metres and Y up, OBJ has no units).
    std::string ext = settings.file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
    const bool fbx = ext == ".fbx";
    rig.fileUnitScale = fbx ? declaredUnitScale(scene) : 0.0;
    rig.unitScale = settings.unitScaleGiven || rig.fileUnitScale <= 0.0 ? settings.unitScale : rig.fileUnitScale;
    rig.fileUpAxis = fbx ? declaredUpAxis(scene) : 0;
    UpAxis up = settings.upAxis;
    if (!settings.upAxisGiven && rig.fileUpAxis) up = rig.fileUpAxis == 'z' ? UpAxis::Z : rig.fileUpAxis == 'x' ? UpAxis::X : UpAxis::Y;
    rig.upAxis = up == UpAxis::Z ? 'z' : up == UpAxis::X ? 'x' : 'y';
    rig.placement = settings.placement;
    rig.placement.linear() *= upAxisRotation(up) * float(rig.unitScale);
    logVerbose("head: ", file, ": ", rig.meshes.size(), " meshes, ", rig.triangleCount(), " triangles, ",
               rig.boneCount(), " bones, ", rig.morphCount(), " morph targets, ", rig.clips.size(), " clips");
    return rig;
}

int findClip(const HeadRig& rig, const std::string& selector) {
    if (selector == "none") return -1;
    if (selector.empty()) return rig.clips.empty() ? -1 : 0;
    for (size_t i = 0; i < rig.clips.size(); ++i)
        if (rig.clips[i].name == selector) return int(i);
    if (isIndex(selector) && std::stoul(selector) < rig.clips.size()) return int(std::stoul(selector));
    std::string list;
    for (size_t i = 0; i < rig.clips.size(); ++i)
        list += cat(i ? ", " : "", i, ": ", rig.clips[i].name.empty() ? "(unnamed)" : rig.clips[i].name);
    throw RigSelectionError(cat("no clip '", selector, "' in ", rig.file, "; it has ",
                                rig.clips.empty() ? std::string("no clips") : list));
}

}  // namespace hp
