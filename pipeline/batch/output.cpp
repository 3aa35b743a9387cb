#include "pipeline/batch/output.h"

#include "core/errors.h"
#include "core/files.h"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>
#include <string>
#include <unistd.h>

namespace fs = std::filesystem;

namespace hp {

namespace {

/// This machine's host name up to the first dot ('@' never occurs in it).
const std::string& hostName() {
    static const std::string name = [] {
        char buf[256] = {};
        if (::gethostname(buf, sizeof buf - 1) != 0) return std::string("unknown");
        std::string n(buf);
        n = n.substr(0, n.find('.'));
        for (char& c : n)
            if (c == '@' || c == '/') c = '_';
        return n.empty() ? std::string("unknown") : n;
    }();
    return name;
}

/// Whether `pid` is a live process on this machine. kill(pid, 0) fails with
/// ESRCH only when no such process exists, but it succeeds for a zombie too:
/// a killed writer's entry lingers until its parent (or init) reaps it, and
/// its temporaries are as stale as a vanished writer's.
bool processAlive(pid_t pid) {
    if (::kill(pid, 0) != 0 && errno == ESRCH) return false;
    std::ifstream stat(cat("/proc/", pid, "/stat"));
    std::string line;
    if (!std::getline(stat, line)) return true;  // no /proc: trust kill()
    // "pid (comm) state ...": comm may hold spaces and parentheses.
    const size_t close = line.rfind(')');
    if (close == std::string::npos || close + 2 >= line.size()) return true;
    const char state = line[close + 2];
    return state != 'Z' && state != 'X';
}

}  // namespace

fs::path temporaryPath(const fs::path& final) {
    static std::atomic<unsigned> counter{0};
    return final.parent_path() / cat(kTemporaryPrefix, ::getpid(), "-", counter.fetch_add(1), "@", hostName(), "@",
                                      final.filename().string());
}

bool isTemporary(const fs::path& path) { return path.filename().string().rfind(kTemporaryPrefix, 0) == 0; }

std::vector<fs::path> findTemporaries(const std::set<fs::path>& folders) {
    std::vector<fs::path> found;
    for (const fs::path& folder : folders) {
        std::error_code ec;
        for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec))
            if (isTemporary(it->path())) found.push_back(it->path());
    }
    return found;
}

size_t removeStaleTemporaries(const std::set<fs::path>& folders) {
    size_t removed = 0;
    for (const fs::path& tmp : findTemporaries(folders)) {
        // ".hairpipe-tmp-<pid>-<n>@<host>@<name>"; anything else is left alone.
        const std::string name = tmp.filename().string().substr(std::strlen(kTemporaryPrefix));
        const size_t at1 = name.find('@');
        const size_t at2 = at1 == std::string::npos ? at1 : name.find('@', at1 + 1);
        if (at2 == std::string::npos || name.substr(at1 + 1, at2 - at1 - 1) != hostName()) continue;
        char* end = nullptr;
        const long pid = std::strtol(name.c_str(), &end, 10);
        if (pid <= 0 || *end != '-') continue;
        if (pid == long(::getpid()) || processAlive(pid_t(pid))) continue;
        std::error_code ec;
        if (fs::remove(tmp, ec)) ++removed;
    }
    return removed;
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
    } catch (const IoError& e) {
        fs::remove(tmp, ec);
        // The user knows the final name, never the temporary one.
        if (e.file() == tmp.string()) throw IoError(final.string(), e.problem());
        throw;
    } catch (...) {
        fs::remove(tmp, ec);
        throw;
    }
}

void writeTextAtomically(const fs::path& final, const std::string& text, bool executable) {
    writeAtomically(final, [&](const fs::path& tmp) {
        writeFileChecked(tmp, text.data(), text.size());
        if (executable)
            fs::permissions(tmp, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                            fs::perm_options::add);
    });
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
    const fs::path probe = temporaryPath(dir / "write-probe");  // a temporary's name: stale-file cleanup knows it
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
