#include "pipeline/head/scalp.h"

#include "core/errors.h"
#include "render/image/image_io.h"
#include "sim/strands/roots.h"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace hp {

namespace {

const char* kChannelNames = "RGBA";

/// Bilinear sample of channel c at uv, wrapping around (textures repeat).
float sampleMask(const Image& img, int c, const Vec2f& uv) {
    const float x = uv.x() * float(img.width) - 0.5f;
    const float y = (1.f - uv.y()) * float(img.height) - 0.5f;  // image rows run top down
    const float fx = std::floor(x), fy = std::floor(y);
    const float ax = x - fx, ay = y - fy;
    auto wrap = [](int i, int n) { return ((i % n) + n) % n; };
    auto at = [&](int i, int j) { return img.at(wrap(i, img.width), wrap(j, img.height), c); };
    const int i = int(fx), j = int(fy);
    return (1 - ay) * ((1 - ax) * at(i, j) + ax * at(i + 1, j)) + ay * ((1 - ax) * at(i, j + 1) + ax * at(i + 1, j + 1));
}

std::string show(const Vec3f& v) { return cat("[", v.x(), ", ", v.y(), ", ", v.z(), "]"); }

std::string describe(ScalpMethod m) {
    switch (m) {
        case ScalpMethod::All: return "all";
        case ScalpMethod::Material: return "material";
        case ScalpMethod::VertexColor: return "vertex colour";
        case ScalpMethod::Texture: return "texture mask";
        default: return "region";
    }
}

}  // namespace

ScalpSettings defaultScalp(const HeadRig& rig, const TriangleMesh& rest, std::string& why) {
    ScalpSettings s;
    std::vector<uint32_t> used;  // materials some mesh uses
    for (const RigMesh& m : rig.meshes)
        if (m.material < rig.materials.size() && std::find(used.begin(), used.end(), m.material) == used.end())
            used.push_back(m.material);
    for (uint32_t m : used) {
        std::string lower = rig.materials[m];
        std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        if (lower.find("scalp") != std::string::npos || lower.find("hair") != std::string::npos)
            s.materials.push_back(rig.materials[m]);
    }
    if (!s.materials.empty()) {
        s.method = ScalpMethod::Material;
        std::string names;
        for (const std::string& n : s.materials) names += (names.empty() ? "'" : ", '") + n + "'";
        why = cat("the material ", names, " of ", rig.file);
        return s;
    }
    // The cranium: the part of the mesh within one head width of its top
    // (a neck or shoulders below do not pull the sphere down).
    Eigen::AlignedBox3f box;
    for (const Vec3f& p : rest.positions) box.extend(p);
    const Vec3f size = box.sizes();
    const float width = std::max(size.x(), size.z());
    std::vector<Vec3f> top;
    for (const Vec3f& p : rest.positions)
        if (p.y() >= box.max().y() - 0.5f * width) top.push_back(p);
    Vec3f center;
    float radius = 0.f;
    if (!fitSphere(top, center, radius) || !(radius > 0.25f * width && radius < 1.5f * width))
        center = Vec3f(box.center().x(), box.max().y() - 0.5f * width, box.center().z());
    s.method = ScalpMethod::Region;
    s.center = center;
    s.axis = Vec3f(0.f, 1.f, -0.45f).normalized();
    s.angleDegrees = 72.f;
    why = cat("a cap over the top and back of the head (region: centre ", show(center), ", axis ", show(s.axis),
              ", 72 deg; ", rig.file, " has no material named *scalp* or *hair*)");
    return s;
}

std::vector<uint8_t> selectScalp(const HeadRig& rig, const TriangleMesh& rest, const ScalpSettings& s) {
    const size_t nt = rest.triangles.size();
    std::vector<uint8_t> mask(nt, 0);
    switch (s.method) {
        case ScalpMethod::All: std::fill(mask.begin(), mask.end(), 1); break;
        case ScalpMethod::Material: {
            std::vector<uint8_t> wanted(rig.materials.size(), 0);
            for (const std::string& name : s.materials) {
                const auto it = std::find(rig.materials.begin(), rig.materials.end(), name);
                if (it == rig.materials.end()) {
                    std::string list;
                    for (const RigMesh& m : rig.meshes)
                        if (m.material < rig.materials.size() &&
                            list.find("'" + rig.materials[m.material] + "'") == std::string::npos)
                            list += (list.empty() ? "'" : ", '") + rig.materials[m.material] + "'";
                    throw Error(cat("no material '", name, "' in ", rig.file, " (its meshes use ", list, ")"));
                }
                wanted[size_t(it - rig.materials.begin())] = 1;
            }
            const std::vector<uint32_t> mats = rig.triangleMaterials();
            for (size_t t = 0; t < nt; ++t) mask[t] = mats[t] < wanted.size() && wanted[mats[t]];
            break;
        }
        case ScalpMethod::VertexColor: {
            if (!rig.hasColors()) throw Error(cat(rig.file, " has no vertex colours to select the scalp by"));
            const std::vector<Eigen::Vector4f> colors = rig.vertexColors();
            for (size_t t = 0; t < nt; ++t) {
                float sum = 0.f;
                for (uint32_t v : rest.triangles[t]) sum += colors[v][s.channel];
                mask[t] = sum / 3.f >= s.threshold;
            }
            break;
        }
        case ScalpMethod::Texture: {
            if (rest.uvs.size() != rest.positions.size() || !rig.hasUvs())
                throw Error(cat(rig.file, " has no texture coordinates to read the scalp mask through"));
            const Image img = readImage(s.mask.string());
            // A grey or single-channel mask: its only channel stands for all.
            const int c = std::min(s.channel, img.channelCount() - 1);
            if (img.width == 0 || img.height == 0 || c < 0) throw AssetError(s.mask.string(), "the mask image is empty");
            for (size_t t = 0; t < nt; ++t) {
                const Tri& tri = rest.triangles[t];
                const Vec2f centroid = (rest.uvs[tri[0]] + rest.uvs[tri[1]] + rest.uvs[tri[2]]) / 3.f;
                float sum = sampleMask(img, c, centroid);
                for (uint32_t v : tri) sum += sampleMask(img, c, 0.5f * (centroid + rest.uvs[v]));
                mask[t] = sum / 4.f >= s.threshold;
            }
            break;
        }
        case ScalpMethod::Region: {
            const Vec3f axis = s.axis.normalized();
            const float minCos = std::cos(s.angleDegrees * float(M_PI) / 180.f);
            for (size_t t = 0; t < nt; ++t) {
                const Tri& tri = rest.triangles[t];
                const Vec3f d = (rest.positions[tri[0]] + rest.positions[tri[1]] + rest.positions[tri[2]]) / 3.f - s.center;
                mask[t] = d.norm() > 0.f && d.normalized().dot(axis) >= minCos;
            }
            break;
        }
    }
    if (std::none_of(mask.begin(), mask.end(), [](uint8_t m) { return m != 0; })) {
        std::string detail;
        if (s.method == ScalpMethod::VertexColor || s.method == ScalpMethod::Texture)
            detail = cat(" (channel ", kChannelNames[s.channel], " never reaches ", s.threshold, ")");
        if (s.method == ScalpMethod::Region)
            detail = cat(" (no triangle lies within ", s.angleDegrees, " deg of the axis ", show(s.axis), " around ",
                         show(s.center), ")");
        throw Error(cat("the scalp selection (", describe(s.method), ") selects no triangle of ", rig.file, detail));
    }
    return mask;
}

}  // namespace hp
