#include "test_support.h"

#include <array>
#include <atomic>
#include <cstdio>
#include <random>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace hp::test {

TempDir::TempDir() {
    static std::atomic<int> counter{0};
    std::random_device rd;
    path_ = fs::temp_directory_path() /
            ("hairpipe-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-" +
             std::to_string(rd() % 100000));
    fs::create_directories(path_);
}

TempDir::~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
}

void writeFile(const fs::path& path, const std::string& text) {
    if (path.has_parent_path()) fs::create_directories(path.parent_path());
    std::ofstream out(path, std::ios::binary);
    out << text;
}

std::string readFile(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

fs::path sharedAsset(const std::string& name) {
    const fs::path p = fs::path(HAIRPIPE_SHARED_ASSETS) / name;
    return fs::exists(p) ? p : fs::path();
}

std::string assetsMissingMessage(const std::string& name) {
    return "shared test asset '" + name + "' not found in " + std::string(HAIRPIPE_SHARED_ASSETS) +
           " (../shared/assets exists only in the development workspace and CI; skipping)";
}

ProcessResult runShell(const std::string& command) {
    ProcessResult r;
    FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
    if (!pipe) return r;
    std::array<char, 4096> buf;
    size_t n;
    while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) r.output.append(buf.data(), n);
    const int status = ::pclose(pipe);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

ProcessResult runHairpipe(const std::string& args, const fs::path& cwd) {
    std::string command;
    if (!cwd.empty()) command = "cd '" + cwd.string() + "' && ";
    return runShell(command + "'" + HAIRPIPE_EXE + "' " + args);
}

fs::path sourcePath(const std::string& relative) { return fs::path(HAIRPIPE_SOURCE_DIR) / relative; }

}  // namespace hp::test
