#include "pipeline/output.h"

#include "core/errors.h"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <unistd.h>

namespace fs = std::filesystem;

namespace hp {

fs::path temporaryPath(const fs::path& final) {
    static std::atomic<unsigned> counter{0};
    return final.parent_path() /
           cat(kTemporaryPrefix, ::getpid(), "-", counter.fetch_add(1), "-", final.filename().string());
}

void writeAtomically(const fs::path& final, const std::function<void(const fs::path&)>& write) {
    std::error_code ec;
    if (final.has_parent_path()) {
        fs::create_directories(final.parent_path(), ec);
        if (ec) throw IoError(final.string(), "cannot create folder " + final.parent_path().string() + ": " + ec.message());
    }
    const fs::path tmp = temporaryPath(final);
    try {
        write(tmp);
        if (!fs::is_regular_file(tmp, ec)) throw IoError(final.string(), "the writer produced no file");
        fs::rename(tmp, final, ec);
        if (ec) throw IoError(final.string(), "cannot rename temporary file: " + ec.message());
    } catch (...) {
        fs::remove(tmp, ec);
        throw;
    }
}

void checkOutputDirectory(const fs::path& dir) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir)) {
        throw IoError(dir.string(), "cannot create the output folder: " +
                                        (ec ? ec.message() : std::string("a file of that name exists")));
    }
    // Permission bits alone do not tell (root ignores them; a read-only mount
    // does not show in them): write a probe file.
    const fs::path probe = dir / cat(kTemporaryPrefix, ::getpid(), "-probe");
    std::ofstream out(probe, std::ios::binary | std::ios::trunc);
    if (!out) {
        const int err = errno;
        throw IoError(dir.string(), cat("the output folder is not writable: ", std::strerror(err)));
    }
    out << 'x';
    out.close();
    const bool written = bool(out);
    fs::remove(probe, ec);
    if (!written) throw IoError(dir.string(), "the output folder is not writable (write failed; disk full?)");
}

bool allExist(const std::vector<fs::path>& paths) {
    std::error_code ec;
    for (const fs::path& p : paths)
        if (!fs::is_regular_file(p, ec) || fs::file_size(p, ec) == 0) return false;
    return true;
}

}  // namespace hp
