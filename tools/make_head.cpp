// make_head: writes the project's default animated head (pipeline/head/default_head.h)
// as a binary glTF through assimp's exporter. scenes/assets/head.glb is its
// output with the default options; tests check the committed file still
// matches.
//
//   make_head OUT.glb [--rings N] [--sectors N] [--key-rate HZ]
//   make_head OUT.glb --body             the shoulders under that head, with its
//                                        neck and clips (scenes/assets/body.glb)
//   make_head OUT.glb --sphere RADIUS    a static UV sphere, Gomes 2024's and
//                                        the benchmarks' head (scenes/assets/sphere.glb)
//   make_head OUT.glb --fold             the folding head: a sphere and a neck
//                                        cylinder overlapping in one skinned mesh,
//                                        clips fold_tip and fold_jump
//                                        (pipeline/head/fold_head.h, scenes/assets/fold.glb)
#include "core/errors.h"
#include "pipeline/head/default_head.h"
#include "pipeline/head/fold_head.h"
#include "pipeline/batch/output.h"
#include "sim/strands/head.h"

#include <assimp/Exporter.hpp>
#include <assimp/material.h>
#include <assimp/scene.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>

using namespace hp;

namespace {

/// A static sphere rig: one node, one mesh with the "scalp" material, no clip.
HeadRig sphereRig(float radius) {
    HeadRig rig;
    rig.nodes.push_back(RigNode{"Sphere", -1, Affine3f::Identity()});
    const TriangleMesh m = makeSphereMesh(Vec3f::Zero(), radius, 48, 96);
    RigMesh mesh;
    mesh.name = "sphere";
    mesh.node = 0;
    mesh.material = 0;
    mesh.positions = m.positions;
    mesh.normals = m.normals;
    mesh.uvs = m.uvs;
    mesh.triangles = m.triangles;
    mesh.colors.assign(m.positions.size(), Eigen::Vector4f(1.f, 1.f, 1.f, 1.f));  // all scalp
    rig.meshes.push_back(std::move(mesh));
    rig.materials = {"scalp"};
    return rig;
}

aiMatrix4x4 toAssimp(const Affine3f& a) {
    aiMatrix4x4 m;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m[r][c] = a.matrix()(r, c);
    return m;
}

aiNode* buildNodes(const HeadRig& rig, int index) {
    const RigNode& n = rig.nodes[size_t(index)];
    aiNode* node = new aiNode(n.name);
    node->mTransformation = toAssimp(n.local);
    std::vector<unsigned> meshes;
    for (size_t m = 0; m < rig.meshes.size(); ++m)
        if (rig.meshes[m].node == index) meshes.push_back(unsigned(m));
    if (!meshes.empty()) {
        node->mNumMeshes = unsigned(meshes.size());
        node->mMeshes = new unsigned[meshes.size()];
        std::copy(meshes.begin(), meshes.end(), node->mMeshes);
    }
    std::vector<aiNode*> children;
    for (size_t c = 0; c < rig.nodes.size(); ++c)
        if (rig.nodes[c].parent == index) children.push_back(buildNodes(rig, int(c)));
    if (!children.empty()) node->addChildren(unsigned(children.size()), children.data());
    return node;
}

aiMesh* buildMesh(const HeadRig& rig, const RigMesh& r) {
    aiMesh* m = new aiMesh();
    m->mName = r.name;
    m->mMaterialIndex = r.material;
    m->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    const unsigned n = unsigned(r.positions.size());
    m->mNumVertices = n;
    m->mVertices = new aiVector3D[n];
    m->mNormals = new aiVector3D[n];
    m->mTextureCoords[0] = new aiVector3D[n];
    m->mNumUVComponents[0] = 2;
    m->mColors[0] = new aiColor4D[n];
    for (unsigned v = 0; v < n; ++v) {
        m->mVertices[v] = aiVector3D(r.positions[v].x(), r.positions[v].y(), r.positions[v].z());
        m->mNormals[v] = aiVector3D(r.normals[v].x(), r.normals[v].y(), r.normals[v].z());
        m->mTextureCoords[0][v] = aiVector3D(r.uvs[v].x(), r.uvs[v].y(), 0.f);
        m->mColors[0][v] = aiColor4D(r.colors[v][0], r.colors[v][1], r.colors[v][2], r.colors[v][3]);
    }
    m->mNumFaces = unsigned(r.triangles.size());
    m->mFaces = new aiFace[m->mNumFaces];
    for (unsigned f = 0; f < m->mNumFaces; ++f) {
        m->mFaces[f].mNumIndices = 3;
        m->mFaces[f].mIndices = new unsigned[3]{r.triangles[f][0], r.triangles[f][1], r.triangles[f][2]};
    }
    m->mNumBones = unsigned(r.boneNodes.size());
    m->mBones = new aiBone*[m->mNumBones];
    for (unsigned b = 0; b < m->mNumBones; ++b) {
        aiBone* bone = new aiBone();
        bone->mName = rig.nodes[size_t(r.boneNodes[b])].name;
        bone->mOffsetMatrix = toAssimp(r.boneOffsets[b]);
        std::vector<aiVertexWeight> weights;
        for (unsigned v = 0; v < n; ++v)
            for (uint32_t i = r.influenceStart[v]; i < r.influenceStart[v + 1]; ++i)
                if (r.influenceBone[i] == b) weights.emplace_back(v, r.influenceWeight[i]);
        bone->mNumWeights = unsigned(weights.size());
        bone->mWeights = new aiVertexWeight[weights.size()];
        std::copy(weights.begin(), weights.end(), bone->mWeights);
        m->mBones[b] = bone;
    }
    return m;
}

aiAnimation* buildClip(const HeadRig& rig, const RigClip& c) {
    // Ticks are milliseconds, as assimp's glTF importer reports them.
    const double tps = 1000.0;
    aiAnimation* a = new aiAnimation();
    a->mName = c.name;
    a->mTicksPerSecond = tps;
    a->mDuration = c.duration * tps;
    a->mNumChannels = unsigned(c.tracks.size());
    a->mChannels = new aiNodeAnim*[a->mNumChannels];
    for (unsigned i = 0; i < a->mNumChannels; ++i) {
        const NodeTrack& t = c.tracks[i];
        aiNodeAnim* ch = new aiNodeAnim();
        ch->mNodeName = rig.nodes[size_t(t.node)].name;
        auto vectorKeys = [&](const KeyTrack<Vec3f>& k, unsigned& count, aiVectorKey*& keys) {
            count = unsigned(k.times.size());
            keys = new aiVectorKey[count];
            for (unsigned j = 0; j < count; ++j)
                keys[j] = aiVectorKey(k.times[j] * tps, aiVector3D(k.values[j].x(), k.values[j].y(), k.values[j].z()));
        };
        vectorKeys(t.translation, ch->mNumPositionKeys, ch->mPositionKeys);
        vectorKeys(t.scale, ch->mNumScalingKeys, ch->mScalingKeys);
        ch->mNumRotationKeys = unsigned(t.rotation.times.size());
        ch->mRotationKeys = new aiQuatKey[ch->mNumRotationKeys];
        for (unsigned j = 0; j < ch->mNumRotationKeys; ++j) {
            const Eigen::Quaternionf& q = t.rotation.values[j];
            ch->mRotationKeys[j] = aiQuatKey(t.rotation.times[j] * tps, aiQuaternion(q.w(), q.x(), q.y(), q.z()));
        }
        a->mChannels[i] = ch;
    }
    return a;
}

aiMaterial* buildMaterial(const std::string& name, const aiColor4D& color) {
    aiMaterial* m = new aiMaterial();
    const aiString n(name);
    m->AddProperty(&n, AI_MATKEY_NAME);
    m->AddProperty(&color, 1, AI_MATKEY_BASE_COLOR);
    m->AddProperty(&color, 1, AI_MATKEY_COLOR_DIFFUSE);
    return m;
}

/// assimp's glTF exporter leaves stretches of the binary chunk that no
/// buffer view covers, holding whatever its allocator returned; zeroing them
/// makes the file a pure function of the rig (the test compares bytes).
void zeroUnusedGlbBytes(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::vector<char> data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    in.close();
    auto u32 = [&](size_t at) {
        uint32_t v = 0;
        std::memcpy(&v, data.data() + at, 4);
        return size_t(v);
    };
    if (data.size() < 28 || std::memcmp(data.data(), "glTF", 4) != 0) throw IoError(file.string(), "not a GLB file");
    const size_t jsonLength = u32(12);
    const size_t bin = 20 + jsonLength + 8;  // first byte of the BIN chunk's data
    if (bin > data.size()) throw IoError(file.string(), "truncated GLB file");
    const YAML::Node json = YAML::Load(std::string(data.data() + 20, jsonLength));  // JSON is YAML
    std::vector<char> used(data.size() - bin, 0);
    for (const YAML::Node& view : json["bufferViews"]) {
        const size_t offset = view["byteOffset"] ? view["byteOffset"].as<size_t>() : 0;
        const size_t length = view["byteLength"].as<size_t>();
        std::fill(used.begin() + long(std::min(offset, used.size())), used.begin() + long(std::min(offset + length, used.size())), 1);
    }
    for (size_t i = 0; i < used.size(); ++i)
        if (!used[i]) data[bin + i] = 0;
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(data.data(), std::streamsize(data.size()));
    if (!out) throw IoError(file.string(), "cannot rewrite the file");
}

const char* const kUsage = "usage: make_head OUT.glb [--body | --fold] [--rings N] [--sectors N] [--key-rate HZ] | OUT.glb --sphere RADIUS";

int intOption(const std::string& name, const char* value) {
    char* end = nullptr;
    const long n = value ? std::strtol(value, &end, 10) : 0;
    if (!value || *end || n < 3 || n > 4096) throw UsageError(cat("make_head: ", name, " expects an integer in [3, 4096]"));
    return int(n);
}

}  // namespace

int main(int argc, char** argv) {
    try {
        DefaultHeadOptions options;
        std::string out;
        double sphere = 0;
        bool body = false, fold = false;
        for (int i = 1; i < argc; ++i) {
            const std::string a = argv[i];
            if (a == "--rings") options.rings = intOption(a, i + 1 < argc ? argv[++i] : nullptr);
            else if (a == "--sectors") options.sectors = intOption(a, i + 1 < argc ? argv[++i] : nullptr);
            else if (a == "--key-rate") options.keyRate = intOption(a, i + 1 < argc ? argv[++i] : nullptr);
            else if (a == "--sphere" && i + 1 < argc) sphere = std::atof(argv[++i]);
            else if (a == "--body") body = true;
            else if (a == "--fold") fold = true;
            else if (a == "-h" || a == "--help" || (!a.empty() && a[0] == '-') || !out.empty())
                throw UsageError(kUsage);
            else out = a;
        }
        if (out.empty()) throw UsageError(kUsage);

        if (sphere < 0 || (sphere == 0 && std::find(argv, argv + argc, std::string("--sphere")) != argv + argc))
            throw UsageError("make_head: --sphere needs a positive radius in metres");
        if (fold && (body || sphere > 0)) throw UsageError(kUsage);
        const HeadRig rig = sphere > 0 ? sphereRig(float(sphere))
                            : body     ? makeDefaultBody(options)
                            : fold     ? makeFoldHead({})
                                       : makeDefaultHead(options);
        aiScene scene;
        scene.mRootNode = buildNodes(rig, 0);
        scene.mNumMeshes = unsigned(rig.meshes.size());
        scene.mMeshes = new aiMesh*[scene.mNumMeshes];
        for (unsigned m = 0; m < scene.mNumMeshes; ++m) scene.mMeshes[m] = buildMesh(rig, rig.meshes[m]);
        scene.mNumMaterials = 2;
        scene.mMaterials = new aiMaterial*[2]{buildMaterial("scalp", aiColor4D(0.25f, 0.16f, 0.1f, 1.f)),
                                              buildMaterial("skin", aiColor4D(0.75f, 0.6f, 0.5f, 1.f))};
        scene.mNumAnimations = unsigned(rig.clips.size());
        scene.mAnimations = scene.mNumAnimations ? new aiAnimation*[scene.mNumAnimations] : nullptr;
        for (unsigned c = 0; c < scene.mNumAnimations; ++c) scene.mAnimations[c] = buildClip(rig, rig.clips[c]);

        writeAtomically(out, [&](const std::filesystem::path& tmp) {
            Assimp::Exporter exporter;
            if (exporter.Export(&scene, "glb2", tmp.string()) != aiReturn_SUCCESS)
                throw IoError(out, cat("assimp export failed: ", exporter.GetErrorString()));
            zeroUnusedGlbBytes(tmp);
        });
        std::cout << "make_head: wrote " << out << " (" << rig.triangleCount() << " triangles, "
                  << rig.vertexCount() << " vertices";
        if (!rig.clips.empty()) std::cout << ", clip " << rig.clips[0].name << " " << rig.clips[0].duration << " s";
        std::cout << ")\n";
        return 0;
    } catch (const UsageError& e) {
        std::cerr << e.what() << "\n";
        return 1;
    } catch (const Error& e) {
        std::cerr << "make_head: " << e.what() << "\n";
        return 2;
    }
}
