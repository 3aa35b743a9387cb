// Helpers of the batch and farm tests (test_batch.cpp, test_farm.cpp): a
// small shot with every stage, hairpipe started as a process that can be
// killed, and a comparison of two output folders that must be identical.
#pragma once

#include "render/image/image_io.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <functional>
#include <spawn.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

extern char** environ;

namespace hp::test {

/// A shot small enough to run in a few seconds with every stage on: 16
/// guides, 300 followers, 96x64 images, references and comparisons on
/// frames 1, 5, 9, ...; per-frame USD; frames 1-6 unless told.
inline std::filesystem::path writeSmallScene(const std::filesystem::path& dir, const std::string& frames = "1-6") {
    const std::filesystem::path scene = dir / "small.yaml";
    writeFile(scene, "name: small\n"
                     "frames: " + frames + "\n"
                     "seed: 3\n"
                     "head:\n"
                     "  file: " + sourcePath("scenes/assets/head.glb").string() + "\n"
                     "  clip: nod_shake_turn\n"
                     "  scalp: {method: region, center: [0, 0, -0.01], axis: [0, 1, -0.45], angle: 72}\n"
                     "hair:\n"
                     "  guides: {count: 16, length: 0.15, segments: 8}\n"
                     "  followers: {count: 300}\n"
                     "cache:\n"
                     "  usd: usd/hair.####.usda\n"
                     "render:\n"
                     "  camera: {position: [0.42, 0.08, 0.62], target: [0, -0.04, -0.02], fov: 38, width: 96, height: 64}\n"
                     "preview:\n"
                     "  enabled: true\n"
                     "  msaa: 2\n"
                     "  shadow: {resolution: 32, map_size: 128}\n"
                     "reference: {enabled: true, samples: 2, frames: 1-100x4}\n"
                     "vdb: {enabled: true, voxel_size: 0.004, velocity: true}\n"
                     "compare: {enabled: true, frames: 1-100x4}\n");
    return scene;
}

/// Quotes for the shell command runHairpipe builds.
inline std::string q(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

/// hairpipe running in the background, output to a log file.
class Background {
  public:
    Background(const std::vector<std::string>& args, const std::filesystem::path& cwd, const std::filesystem::path& log) {
        std::vector<std::string> argv = {HAIRPIPE_EXE};
        argv.insert(argv.end(), args.begin(), args.end());
        std::vector<char*> p;
        for (std::string& a : argv) p.push_back(a.data());
        p.push_back(nullptr);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        posix_spawn_file_actions_adddup2(&actions, 1, 2);
        const std::filesystem::path old = std::filesystem::current_path();
        std::filesystem::current_path(cwd);
        if (posix_spawn(&pid_, HAIRPIPE_EXE, &actions, nullptr, p.data(), environ) != 0) pid_ = -1;
        std::filesystem::current_path(old);
        posix_spawn_file_actions_destroy(&actions);
    }
    ~Background() {
        if (pid_ > 0) kill(SIGKILL), wait();
    }
    pid_t pid() const { return pid_; }
    void kill(int signal) const { ::kill(pid_, signal); }
    /// Waits for the end; the raw wait status.
    int wait() {
        int status = 0;
        if (pid_ > 0) ::waitpid(pid_, &status, 0);
        pid_ = -1;
        return status;
    }
    bool running() const { return pid_ > 0 && ::waitpid(pid_, nullptr, WNOHANG) == 0; }

  private:
    pid_t pid_ = -1;
};

/// Polls `done` every millisecond for up to `seconds`.
inline bool waitUntil(const std::function<bool()>& done, double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
        if (done()) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return done();
}

/// Files under `dir`, relative, sorted; the farm folder (logs, scripts) and
/// the simulation's statistics (they hold timings) are not outputs to compare.
inline std::vector<std::string> outputFiles(const std::filesystem::path& dir) {
    std::vector<std::string> files;
    for (const auto& e : std::filesystem::recursive_directory_iterator(dir)) {
        if (!e.is_regular_file()) continue;
        const std::string rel = std::filesystem::relative(e.path(), dir).string();
        if (rel.rfind("farm/", 0) == 0 || rel.find("/stats.") != std::string::npos) continue;
        files.push_back(rel);
    }
    std::sort(files.begin(), files.end());
    return files;
}

inline std::string replaceAll(std::string s, const std::string& from, const std::string& to) {
    for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size())) s.replace(at, from.size(), to);
    return s;
}

/// Compare tables and the report: rewritten whole by every run that compares.
inline bool isCompareTable(const std::string& f) {
    return f.rfind("compare/", 0) == 0 && std::filesystem::path(f).extension() != ".png" &&
           std::filesystem::path(f).extension() != ".exr";
}

/// Asserts output file `f` (relative) is the same in `a` and `b`: EXRs with
/// identical channels and pixels (their headers carry the write time),
/// compare tables identical once the output folder named in them is
/// swapped, anything else byte for byte.
inline void expectSameFile(const std::filesystem::path& a, const std::filesystem::path& b, const std::string& f) {
    const std::string ext = std::filesystem::path(f).extension().string();
    if (ext == ".exr") {
        const Image ia = readImage((a / f).string()), ib = readImage((b / f).string());
        EXPECT_EQ(ia.channels, ib.channels) << f;
        ASSERT_EQ(ia.pixels.size(), ib.pixels.size()) << f;
        EXPECT_EQ(0, std::memcmp(ia.pixels.data(), ib.pixels.data(), ia.pixels.size() * sizeof(float)))
            << f << ": pixels differ";
    } else if (isCompareTable(f)) {
        EXPECT_EQ(replaceAll(readFile(a / f), a.string(), b.string()), readFile(b / f)) << f;
    } else {
        EXPECT_TRUE(readFile(a / f) == readFile(b / f)) << f << ": bytes differ";
    }
}

/// Output files of `dir` whose names start with the temporary prefix.
inline std::vector<std::string> temporaries(const std::filesystem::path& dir) {
    std::vector<std::string> out;
    for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
        if (e.path().filename().string().rfind(".hairpipe-tmp-", 0) == 0) out.push_back(e.path().string());
    return out;
}

inline void expectNoTemporaries(const std::filesystem::path& dir) {
    for (const std::string& f : temporaries(dir)) ADD_FAILURE() << "temporary file left: " << f;
}

/// Asserts `b` holds the same outputs as `a` (expectSameFile for each) and
/// no temporaries.
inline void expectSameOutputs(const std::filesystem::path& a, const std::filesystem::path& b) {
    const std::vector<std::string> fa = outputFiles(a), fb = outputFiles(b);
    EXPECT_EQ(fa, fb) << "different sets of output files";
    expectNoTemporaries(b);
    for (const std::string& f : fa)
        if (std::find(fb.begin(), fb.end(), f) != fb.end()) expectSameFile(a, b, f);
}

/// Asserts every frame output `b` has is one `a` has too, and the same: a
/// run that failed part way left only finished files. Compare tables are
/// skipped (they list the failures).
inline void expectOnlyFinishedOutputs(const std::filesystem::path& a, const std::filesystem::path& b) {
    const std::vector<std::string> fa = outputFiles(a), fb = outputFiles(b);
    expectNoTemporaries(b);
    for (const std::string& f : fb) {
        if (isCompareTable(f)) continue;
        if (std::find(fa.begin(), fa.end(), f) == fa.end()) ADD_FAILURE() << "unexpected output " << f;
        else expectSameFile(a, b, f);
    }
}

}  // namespace hp::test
