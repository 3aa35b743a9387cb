#include "render/preview/gl_program.h"

#include "core/errors.h"
#include "render/preview/shader_library.h"

#include <epoxy/gl.h>

#include <algorithm>

namespace hp {

namespace {

GLenum glStage(ShaderStage s) {
    switch (s) {
        case ShaderStage::Vertex: return GL_VERTEX_SHADER;
        case ShaderStage::TessControl: return GL_TESS_CONTROL_SHADER;
        case ShaderStage::TessEvaluation: return GL_TESS_EVALUATION_SHADER;
        case ShaderStage::Geometry: return GL_GEOMETRY_SHADER;
        case ShaderStage::Fragment: return GL_FRAGMENT_SHADER;
        case ShaderStage::Compute: return GL_COMPUTE_SHADER;
    }
    return GL_VERTEX_SHADER;
}

std::string shaderLog(GLuint shader) {
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::string log(size_t(std::max(length, 1)), '\0');
    glGetShaderInfoLog(shader, length, nullptr, log.data());
    return log.c_str();
}

std::string programLog(GLuint program) {
    GLint length = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
    std::string log(size_t(std::max(length, 1)), '\0');
    glGetProgramInfoLog(program, length, nullptr, log.data());
    return log.c_str();
}

}  // namespace

GlProgram::GlProgram(std::string name, const std::vector<std::pair<ShaderStage, std::string>>& files,
                     const std::vector<std::string>& defines)
    : name_(std::move(name)) {
    std::string prelude = "#version 450 core\n";
    for (const std::string& d : defines) prelude += "#define " + d + "\n";
    prelude += "#line 1\n";
    std::vector<GLuint> shaders;
    auto cleanup = [&] {
        for (GLuint s : shaders) glDeleteShader(s);
    };
    id_ = glCreateProgram();
    for (const auto& [stage, file] : files) {
        const std::string source = prelude + shaderSource(file);
        GLuint shader = glCreateShader(glStage(stage));
        shaders.push_back(shader);
        const char* text = source.c_str();
        glShaderSource(shader, 1, &text, nullptr);
        glCompileShader(shader);
        GLint ok = 0;
        glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
        if (!ok) {
            const std::string log = shaderLog(shader);
            cleanup();
            glDeleteProgram(id_);
            id_ = 0;
            throw Error(cat("preview program '", name_, "': shaders/", file, " does not compile:\n", log));
        }
        glAttachShader(id_, shader);
    }
    glLinkProgram(id_);
    cleanup();
    GLint ok = 0;
    glGetProgramiv(id_, GL_LINK_STATUS, &ok);
    if (!ok) {
        const std::string log = programLog(id_);
        glDeleteProgram(id_);
        id_ = 0;
        throw Error(cat("preview program '", name_, "' does not link:\n", log));
    }
}

GlProgram::~GlProgram() {
    if (id_) glDeleteProgram(id_);
}

GlProgram::GlProgram(GlProgram&& other) noexcept : id_(other.id_), name_(std::move(other.name_)) { other.id_ = 0; }

GlProgram& GlProgram::operator=(GlProgram&& other) noexcept {
    if (this != &other) {
        if (id_) glDeleteProgram(id_);
        id_ = other.id_;
        name_ = std::move(other.name_);
        other.id_ = 0;
    }
    return *this;
}

void GlProgram::use() const { glUseProgram(id_); }

int GlProgram::uniform(const char* name) const { return glGetUniformLocation(id_, name); }

void dispatchRows(size_t invocations) {
    const size_t groups = (invocations + 63) / 64, row = std::max<size_t>(1, std::min<size_t>(groups, 65535));
    glDispatchCompute(GLuint(row), GLuint((groups + row - 1) / row), 1);
}

}  // namespace hp
