// A linked OpenGL program made of shaders/ files (internal to the preview;
// ids are plain unsigned so this header needs no GL headers).
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace hp {

enum class ShaderStage { Vertex, TessControl, TessEvaluation, Geometry, Fragment, Compute };

class GlProgram {
  public:
    GlProgram() = default;
    /// Compiles each (stage, file) with "#version 450 core" and `defines`
    /// ("NAME" or "NAME VALUE") in front, and links them. Needs a current
    /// context. Throws hp::Error with the program name, the file and the
    /// driver's log on a compile or link failure.
    GlProgram(std::string name, const std::vector<std::pair<ShaderStage, std::string>>& files,
              const std::vector<std::string>& defines = {});
    ~GlProgram();
    GlProgram(GlProgram&& other) noexcept;
    GlProgram& operator=(GlProgram&& other) noexcept;
    GlProgram(const GlProgram&) = delete;
    GlProgram& operator=(const GlProgram&) = delete;

    unsigned id() const { return id_; }
    const std::string& name() const { return name_; }
    void use() const;
    /// Location of a uniform, -1 if the linker removed it.
    int uniform(const char* name) const;

  private:
    unsigned id_ = 0;
    std::string name_;
};

/// Dispatches the bound compute program over `invocations` threads in
/// groups of 64 (the programs' local size), laid out in rows of at most
/// 65535 groups (GL's least guaranteed count per dimension): the shader
/// takes its index as gl_GlobalInvocationID.y · gl_NumWorkGroups.x · 64 + gl_GlobalInvocationID.x.
void dispatchRows(size_t invocations);

}  // namespace hp
