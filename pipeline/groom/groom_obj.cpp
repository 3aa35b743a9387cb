// OBJ polylines through assimp: the only groom reader that includes assimp.
#include "pipeline/groom/groom_file.h"

#include "core/errors.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

namespace hp {

GroomCurves readObjCurves(const std::filesystem::path& path) {
    const std::string name = path.string();
    Assimp::Importer importer;
    // No post-processing: the segments must stay in file order (assimp's OBJ
    // importer splits an `l a b c` record into the segments (a, b), (b, c),
    // each with its own copies of the points).
    const aiScene* scene = importer.ReadFile(name, 0);
    if (!scene) throw AssetError(name, cat("cannot read it as an OBJ file: ", importer.GetErrorString()));
    GroomCurves c;
    std::vector<Vec3f> strand;
    auto flush = [&] {
        if (!strand.empty()) c.add(strand.data(), strand.size());
        strand.clear();
    };
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh* mesh = scene->mMeshes[m];
        if (!(mesh->mPrimitiveTypes & aiPrimitiveType_LINE)) continue;
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& face = mesh->mFaces[f];
            if (face.mNumIndices != 2) continue;  // points, triangles and polygons are not strands
            for (unsigned i = 0; i < face.mNumIndices; ++i) {
                if (face.mIndices[i] >= mesh->mNumVertices)
                    throw AssetError(name, cat("a line refers to vertex ", face.mIndices[i] + 1, " of ", mesh->mNumVertices));
                const aiVector3D& v = mesh->mVertices[face.mIndices[i]];
                const Vec3f p(v.x, v.y, v.z);
                // A segment continues the strand when it starts where the last one ended.
                if (i == 0 && !(strand.empty() || strand.back() == p)) flush();
                if (i > 0 || strand.empty()) strand.push_back(p);
            }
            if (c.count() + 1 > kMaxGroomStrands)
                throw AssetError(name, cat("more than ", kMaxGroomStrands, " strands"));
        }
        flush();
    }
    if (c.count() == 0) throw AssetError(name, "contains no polylines (`l` records): no strands to groom");
    return c;
}

}  // namespace hp
