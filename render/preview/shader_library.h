// The preview's GLSL sources (shaders/): built into the binary, or read from
// disk for shader development.
//
// Why embedded: users run the hairpipe binary from anywhere (a render farm
// copies it around), so the sources are compiled into hp_render by a CMake
// step (cmake/EmbedFiles.cmake). Setting HAIRPIPE_SHADER_DIR=<folder> makes
// the preview read that folder instead, so a shader edit needs no rebuild.
#pragma once

#include <string>
#include <vector>

namespace hp {

struct EmbeddedShader {
    const char* name;    ///< file name in shaders/, e.g. "strand.tese"
    const char* source;
};

/// Every file of shaders/ as it was at build time (generated source file).
const std::vector<EmbeddedShader>& embeddedShaders();

/// The source of shaders/<name> with `#include "other.glsl"` lines replaced by
/// that file (recursively; each file at most once). Throws hp::Error naming
/// the file when it does not exist.
std::string shaderSource(const std::string& name);

}  // namespace hp
