#include "core/errors.h"

namespace hp {

std::string SourceLocation::str() const {
    if (line <= 0) return file;
    if (column <= 0) return cat(file, ":", line);
    return cat(file, ":", line, ":", column);
}

static std::string sceneMessage(const SourceLocation& where, const std::string& key,
                                const std::string& message) {
    std::string out = where.valid() ? where.str() + ": " : std::string();
    if (!key.empty()) out += "'" + key + "': ";
    return out + message;
}

SceneError::SceneError(const SourceLocation& where, const std::string& key, const std::string& message)
    : Error(sceneMessage(where, key, message)), where_(where), key_(key), detail_(message) {}

AssetError::AssetError(const std::string& file, const std::string& problem)
    : Error(file + ": " + problem), file_(file) {}

IoError::IoError(const std::string& file, const std::string& problem)
    : Error("cannot write " + file + ": " + problem), file_(file), problem_(problem) {}

}  // namespace hp
