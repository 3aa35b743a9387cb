// libFuzzer target: head import through assimp (pipeline/head/head_import.h) and
// posing the imported rig. The bytes are written to a file whose extension
// follows the content (glTF binary magic -> .glb, '{' -> .gltf, "solid" ->
// .stl, '<' -> .dae, else .obj), because importHead reads files, like the
// pipeline. Any input must import or throw hairpipe's AssetError /
// RigSelectionError; crashes, sanitizer reports and other exceptions are bugs
// (in hairpipe, or in assimp — docs/hardening.md lists which).
#include "tools/fuzz/fuzz_target.h"

#include "core/errors.h"
#include "pipeline/head/head_import.h"

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

const char* assetExtensionFor(const uint8_t* data, size_t size) {
    if (size >= 4 && std::memcmp(data, "glTF", 4) == 0) return ".glb";
    size_t i = 0;
    while (i < size && (data[i] == ' ' || data[i] == '\n' || data[i] == '\r' || data[i] == '\t')) ++i;
    if (i < size && data[i] == '{') return ".gltf";
    if (i < size && data[i] == '<') return ".dae";
    if (size - i >= 5 && std::memcmp(data + i, "solid", 5) == 0) return ".stl";
    return ".obj";
}

}  // namespace

HP_FUZZ_TARGET(asset)(const uint8_t* data, size_t size) {
    if (size > (1u << 20)) return -1;
    static const std::filesystem::path dir = [] {
        auto d = std::filesystem::temp_directory_path() / ("hairpipe-fuzz-asset-" + std::to_string(getpid()));
        std::filesystem::create_directories(d);
        return d;
    }();
    const std::filesystem::path file = dir / (std::string("input") + assetExtensionFor(data, size));
    {
        std::ofstream out(file, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
    }
    try {
        hp::HeadImportSettings settings;
        settings.file = file;
        const hp::HeadRig rig = hp::importHead(settings);
        hp::TriangleMesh mesh = rig.restMesh();
        const int clip = rig.clips.empty() ? -1 : 0;
        rig.pose(clip, 0.5, mesh);
        (void)rig.summary();
    } catch (const hp::Error&) {
    }
    std::filesystem::remove(file);
    return 0;
}
