#include "core/files.h"

#include "core/errors.h"

#include <cerrno>
#include <cstring>
#include <algorithm>
#include <fstream>

namespace hp {

void writeFileChecked(const std::filesystem::path& path, const void* data, size_t size) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError(path.string(), std::strerror(errno));
    out.write(static_cast<const char*>(data), std::streamsize(size));
    out.close();
    if (!out) throw IoError(path.string(), "write failed (disk full?)");
}

std::vector<char> readFileBytes(const std::filesystem::path& path, const std::string& what) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) throw AssetError(path.string(), "cannot open " + what);
    const std::streamoff size = in.tellg();
    std::vector<char> data(size_t(std::max<std::streamoff>(size, 0)));
    in.seekg(0);
    in.read(data.data(), std::streamsize(data.size()));
    if (!in) throw AssetError(path.string(), "cannot read " + what);
    return data;
}

}  // namespace hp
