// @brief Writing a whole file whose failure cannot go unnoticed.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace hp {

/// Writes `size` bytes to `path` (created or truncated). Throws IoError
/// naming `path`: with the system's reason when it cannot be created, and
/// "write failed (disk full?)" when the bytes do not all reach the file. The
/// stream is checked after close(), because buffered bytes reach the disk
/// only at the flush, so a full disk often shows there and nowhere else.
void writeFileChecked(const std::filesystem::path& path, const void* data, size_t size);

/// Reads a whole file. Throws AssetError naming `path`: "cannot open <what>"
/// or "cannot read <what>".
std::vector<char> readFileBytes(const std::filesystem::path& path, const std::string& what);

}  // namespace hp
