#include "core/files.h"

#include "core/errors.h"

#include <cerrno>
#include <cstring>
#include <fstream>

namespace hp {

void writeFileChecked(const std::filesystem::path& path, const void* data, size_t size) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError(path.string(), std::strerror(errno));
    out.write(static_cast<const char*>(data), std::streamsize(size));
    out.close();
    if (!out) throw IoError(path.string(), "write failed (disk full?)");
}

}  // namespace hp
