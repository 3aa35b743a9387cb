#include "render/preview/shader_library.h"

#include "core/errors.h"

#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

namespace hp {

namespace {

std::string rawSource(const std::string& name) {
    if (const char* dir = std::getenv("HAIRPIPE_SHADER_DIR"); dir && *dir) {
        const std::string path = std::string(dir) + "/" + name;
        std::ifstream in(path);
        if (!in) throw Error(cat("shader ", path, " not found (HAIRPIPE_SHADER_DIR is set to ", dir, ")"));
        std::ostringstream text;
        text << in.rdbuf();
        return text.str();
    }
    for (const EmbeddedShader& s : embeddedShaders())
        if (name == s.name) return s.source;
    throw Error(cat("shader '", name, "' is not among the shaders built into hairpipe"));
}

void expand(const std::string& name, std::set<std::string>& seen, std::string& out) {
    if (!seen.insert(name).second) return;
    std::istringstream in(rawSource(name));
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
        ++number;
        const size_t hash = line.find_first_not_of(" \t");
        if (hash != std::string::npos && line.compare(hash, 8, "#include") == 0) {
            const size_t a = line.find('"'), b = line.rfind('"');
            if (a == std::string::npos || b <= a) throw Error(cat("shader ", name, ":", number, ": bad #include"));
            expand(line.substr(a + 1, b - a - 1), seen, out);
            out += cat("#line ", number + 1, "\n");  // compiler logs keep this file's line numbers
            continue;
        }
        out += line;
        out += '\n';
    }
}

}  // namespace

std::string shaderSource(const std::string& name) {
    std::set<std::string> seen;
    std::string out;
    expand(name, seen, out);
    return out;
}

}  // namespace hp
