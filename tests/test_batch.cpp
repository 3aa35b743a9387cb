// Batching a shot: resume after SIGKILL (simulation and render), corrupt cache
// frames, frame subsets from the cache, --jobs, chunks without the report,
// whole-shot USD export, stale temporaries.
#include "batch_support.h"
#include "core/errors.h"
#include "pipeline/batch/output.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <numeric>
#include <sstream>

using namespace hp;
using namespace hp::test;
namespace fs = std::filesystem;

namespace {

std::string frameFile(const std::string& pattern, int frame) {
    char buf[256];
    std::snprintf(buf, sizeof buf, pattern.c_str(), frame);
    return buf;
}

/// `hairpipe ARGS` exits 0; its exit code and output when it does not.
::testing::AssertionResult hairpipeSucceeds(const std::string& args) {
    const ProcessResult r = runHairpipe(args);
    if (r.exitCode == 0) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "hairpipe " << args << " exited " << r.exitCode << ":\n" << r.output;
}

/// Starts `hairpipe ARGS` in `dir` (its output to dir/killed.log), waits up
/// to 120 s for `written` to appear, then kills it with SIGKILL; its wait
/// status in `*status` when given.
::testing::AssertionResult killedOnceWritten(const std::vector<std::string>& args, const TempDir& dir,
                                             const fs::path& written, int* status = nullptr) {
    Background process(args, dir.path(), dir / "killed.log");
    if (process.pid() <= 0) return ::testing::AssertionFailure() << "hairpipe did not start";
    if (!waitUntil([&] { return fs::exists(written); }, 120))
        return ::testing::AssertionFailure() << written << " never appeared:\n" << readFile(dir / "killed.log");
    process.kill(SIGKILL);
    const int ended = process.wait();
    if (status) *status = ended;
    return ::testing::AssertionSuccess();
}

/// Processes whose command line mentions `needle` (children of a killed run).
std::vector<std::string> processesMentioning(const std::string& needle) {
    std::vector<std::string> found;
    for (const auto& e : fs::directory_iterator("/proc")) {
        const std::string cmdline = readFile(e.path() / "cmdline");
        if (cmdline.find(needle) != std::string::npos && e.path().filename() != std::to_string(::getpid()))
            found.push_back(e.path().filename().string() + ": " + replaceAll(cmdline, std::string(1, '\0'), " "));
    }
    return found;
}

/// The structure of a BasisCurves prim in a .usda file, as a USD reader
/// sees it: curve vertex counts, and per attribute its time samples with the
/// number of elements each holds.
struct UsdCurves {
    std::vector<int> vertexCounts;
    std::map<std::string, std::map<int, size_t>> samples;  ///< "points" -> time -> element count
    size_t strandIds = 0;
    std::string widthsInterpolation, idsInterpolation;
};

/// Elements of a USD array literal "[...]": tuples "(x, y, z)" or scalars.
size_t arrayElements(const std::string& literal) {
    const size_t equals = literal.find('=');  // past the type's "[]" in "int[] name = [...]"
    const size_t open = literal.find('[', equals == std::string::npos ? 0 : equals), close = literal.rfind(']');
    if (open == std::string::npos || close == std::string::npos || close <= open + 1) return 0;
    const std::string body = literal.substr(open + 1, close - open - 1);
    if (body.find('(') != std::string::npos) return size_t(std::count(body.begin(), body.end(), '('));
    return size_t(std::count(body.begin(), body.end(), ',')) + 1;
}

std::string quotedValue(const std::string& line) {
    const size_t a = line.find('"'), b = line.rfind('"');
    return a == std::string::npos || b <= a ? "" : line.substr(a + 1, b - a - 1);
}

UsdCurves parseUsdCurves(const std::string& text) {
    UsdCurves c;
    std::istringstream in(text);
    std::string line, sampled;
    while (std::getline(in, line)) {
        if (!sampled.empty()) {
            if (line.find('}') != std::string::npos && line.find('[') == std::string::npos) {
                sampled.clear();
            } else {
                const size_t colon = line.find(':');
                c.samples[sampled][std::atoi(line.substr(0, colon).c_str())] = arrayElements(line.substr(colon + 1));
            }
        } else if (line.find("int[] curveVertexCounts = [") != std::string::npos) {
            std::string body = line.substr(line.find("= [") + 3);
            for (char& ch : body) ch = ch == ',' || ch == ']' ? ' ' : ch;
            std::istringstream counts(body);
            for (int n; counts >> n;) c.vertexCounts.push_back(n);
        } else if (const size_t at = line.find(".timeSamples = {"); at != std::string::npos) {
            sampled = line.substr(line.rfind(' ', at) + 1, at - line.rfind(' ', at) - 1);
        } else if (line.find("int[] primvars:hairpipe:strandId = [") != std::string::npos) {
            c.strandIds = arrayElements(line);
        } else if (line.find("widths:interpolation") != std::string::npos) {
            c.widthsInterpolation = quotedValue(line);
        } else if (line.find("primvars:hairpipe:strandId:interpolation") != std::string::npos) {
            c.idsInterpolation = quotedValue(line);
        }
    }
    return c;
}

/// Asserts `usda` is one BasisCurves prim with `curves` curves whose points,
/// velocities and (per-vertex) widths hold one element per curve vertex at
/// each of `times`.
void expectBasisCurves(const std::string& usda, size_t curves, const std::vector<int>& times, const std::string& what) {
    SCOPED_TRACE(what);
    EXPECT_EQ(usda.rfind("#usda 1.0", 0), 0u);
    EXPECT_EQ(std::count(usda.begin(), usda.end(), '{') - std::count(usda.begin(), usda.end(), '}'), 0);
    EXPECT_NE(usda.find("def BasisCurves \"hair\""), std::string::npos);
    const UsdCurves c = parseUsdCurves(usda);
    ASSERT_EQ(c.vertexCounts.size(), curves);
    const size_t vertices = size_t(std::accumulate(c.vertexCounts.begin(), c.vertexCounts.end(), 0));
    EXPECT_GT(vertices, 2 * curves) << "curves of at least 3 vertices";
    for (const char* attribute : {"points", "velocities", "widths"}) {
        ASSERT_TRUE(c.samples.count(attribute)) << attribute << " has no time samples";
        const std::map<int, size_t>& s = c.samples.at(attribute);
        std::vector<int> sampleTimes;
        for (const auto& [time, count] : s) {
            sampleTimes.push_back(time);
            EXPECT_EQ(count, vertices) << attribute << " at time " << time;
        }
        EXPECT_EQ(sampleTimes, times) << attribute;
    }
    EXPECT_EQ(c.widthsInterpolation, "vertex");
    EXPECT_EQ(c.strandIds, curves);
    EXPECT_EQ(c.idsInterpolation, "uniform");
}

}  // namespace

TEST(Batch, StaleTemporariesOfDeadWritersAreRemoved) {
    TempDir dir;
    // A finished child's pid is a process that no longer exists.
    pid_t dead = ::fork();
    if (dead == 0) ::_exit(0);
    ::waitpid(dead, nullptr, 0);
    const std::string mine = temporaryPath(dir / "frame.0001.exr").filename().string();  // ".hairpipe-tmp-<pid>-<n>@<host>@frame..."
    const std::string rest = mine.substr(mine.find('-', std::strlen(kTemporaryPrefix)));  // "-<n>@<host>@frame.0001.exr"
    const std::string host = rest.substr(rest.find('@') + 1, rest.rfind('@') - rest.find('@') - 1);
    writeFile(dir / (std::string(kTemporaryPrefix) + std::to_string(dead) + rest), "stale");
    writeFile(dir / mine, "being written");  // this process: alive
    writeFile(dir / (std::string(kTemporaryPrefix) + std::to_string(dead) + "-0@other-" + host + "@f.exr"), "other host");
    writeFile(dir / (std::string(kTemporaryPrefix) + "999-0-old-format.exr"), "unknown origin");
    writeFile(dir / "frame.0002.exr", "an output");
    EXPECT_EQ(findTemporaries({dir.path()}).size(), 4u);
    EXPECT_EQ(removeStaleTemporaries({dir.path(), dir / "missing"}), 1u);
    EXPECT_FALSE(fs::exists(dir / (std::string(kTemporaryPrefix) + std::to_string(dead) + rest)));
    EXPECT_TRUE(fs::exists(dir / mine));
    EXPECT_TRUE(fs::exists(dir / "frame.0002.exr"));
    EXPECT_EQ(findTemporaries({dir.path()}).size(), 3u);

    // A killed writer not yet reaped (a zombie) still answers kill(pid, 0);
    // its temporaries are stale all the same.
    pid_t zombie = ::fork();
    if (zombie == 0) ::_exit(0);
    for (int i = 0; i < 1000; ++i) {  // until it has exited (not reaped: waitid with WNOWAIT)
        siginfo_t info{};
        if (::waitid(P_PID, id_t(zombie), &info, WEXITED | WNOWAIT) == 0) break;
    }
    const fs::path ofZombie = dir / (std::string(kTemporaryPrefix) + std::to_string(zombie) + rest);
    writeFile(ofZombie, "killed mid-write");
    EXPECT_EQ(removeStaleTemporaries({dir.path()}), 1u);
    EXPECT_FALSE(fs::exists(ofZombie));
    ::waitpid(zombie, nullptr, 0);
}

TEST(Batch, SimKilledMidShotResumesFromItsCheckpointIdentically) {
    TempDir dir;
    const fs::path scene = writeSmallScene(dir.path(), "1-24");
    ASSERT_TRUE(hairpipeSucceeds("sim -q " + q(scene) + " --out " + q(dir / "a")));

    int status = 0;
    ASSERT_TRUE(killedOnceWritten({"sim", scene.string(), "--out", (dir / "b").string()}, dir,
                                  dir / "b/cache/strands.0006.hpc", &status));
    EXPECT_TRUE(WIFSIGNALED(status));
    ASSERT_FALSE(fs::exists(dir / "b/cache/strands.0024.hpc")) << "the simulation ended before it was killed";
    const ProcessResult resumed = runHairpipe("sim " + q(scene) + " --out " + q(dir / "b"));
    ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
    EXPECT_NE(resumed.output.find("resumed from the checkpoint of frame"), std::string::npos) << resumed.output;
    // Strand caches, checkpoints and USD files byte for byte.
    expectSameOutputs(dir / "a", dir / "b");
}

TEST(Batch, RenderKilledMidShotCompletesIdenticallyWithoutPartialFiles) {
    TempDir dir;
    const fs::path scene = writeSmallScene(dir.path());
    ASSERT_TRUE(hairpipeSucceeds("sim -q " + q(scene) + " --out " + q(dir / "a")));
    ASSERT_TRUE(hairpipeSucceeds("render -q " + q(scene) + " --out " + q(dir / "a")));

    const fs::path b = dir / "b";
    ASSERT_TRUE(hairpipeSucceeds("sim -q " + q(scene) + " --out " + q(b)));
    int status = 0;
    ASSERT_TRUE(killedOnceWritten({"render", scene.string(), "--out", b.string()}, dir, b / "preview/preview.0002.png",
                                  &status));
    EXPECT_TRUE(WIFSIGNALED(status));
    ASSERT_FALSE(fs::exists(b / "preview/preview.0006.png")) << "the render ended before it was killed";
    const ProcessResult resumed = runHairpipe("render " + q(scene) + " --out " + q(b));
    ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
    EXPECT_EQ(resumed.output.find(" 0 stage outputs already present"), std::string::npos)
        << "the rerun should have skipped what the killed render finished:\n" << resumed.output;
    EXPECT_EQ(resumed.output.find("simulation:"), std::string::npos) << "frames come from the cache:\n" << resumed.output;
    // Cache, previews and references equal the uninterrupted render's.
    expectSameOutputs(dir / "a", b);
}

TEST(Batch, FullDiskFailsFramesWithoutPartialFilesAndARerunCompletes) {
    // A file-size limit with SIGXFSZ ignored: every write past it fails with
    // EFBIG, as a full disk does with ENOSPC. Limits grow run by run (in the
    // shell's ulimit blocks; all below one VDB frame, so every run fails), so
    // each run gets further and must leave only finished files behind.
    TempDir dir;
    const fs::path scene = writeSmallScene(dir.path());
    ASSERT_TRUE(hairpipeSucceeds("run -q " + q(scene) + " --out " + q(dir / "a")));
    const fs::path b = dir / "b";
    for (int blocks : {8, 32, 128, 256}) {
        SCOPED_TRACE(cat("ulimit -f ", blocks));
        const ProcessResult r = runShell(cat("cd ", q(dir.path()), " && trap '' XFSZ && ulimit -f ", blocks, " && '",
                                             HAIRPIPE_EXE, "' run -q ", q(scene), " --out ", q(b), " 2>&1"));
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_NE(r.output.find("write failed (disk full?)"), std::string::npos) << r.output;
        // Messages name the file the user asked for, never the temporary.
        for (size_t at = r.output.find("cannot write "); at != std::string::npos;
             at = r.output.find("cannot write ", at + 1)) {
            const std::string path = r.output.substr(at + 13, r.output.find(": ", at) - at - 13);
            EXPECT_EQ(fs::path(path).filename().string().rfind(kTemporaryPrefix, 0), std::string::npos) << path;
        }
        expectOnlyFinishedOutputs(dir / "a", b);
    }
    ASSERT_TRUE(hairpipeSucceeds("run -q " + q(scene) + " --out " + q(b)));
    expectSameOutputs(dir / "a", b);
}

TEST(Batch, JobsRunKilledTakesItsChildrenAlongAndResumesIdentically) {
    TempDir dir;
    const fs::path scene = writeSmallScene(dir.path());
    ASSERT_TRUE(hairpipeSucceeds("run -q " + q(scene) + " --out " + q(dir / "a")));

    const fs::path b = dir / "b";
    ASSERT_TRUE(killedOnceWritten({"run", scene.string(), "--out", b.string(), "--jobs", "2", "--chunk", "3"}, dir,
                                  b / "preview/preview.0002.png"));
    // The chunks were children of the killed process: they end with it.
    EXPECT_TRUE(waitUntil([&] { return processesMentioning(b.string()).empty(); }, 10))
        << "still running:\n" << ::testing::PrintToString(processesMentioning(b.string()));
    ASSERT_TRUE(hairpipeSucceeds("run " + q(scene) + " --out " + q(b) + " --jobs 2 --chunk 3"));
    expectSameOutputs(dir / "a", b);
}

TEST(Batch, CorruptCacheFrameFailsThatFrameNamingTheFile) {
    TempDir dir;
    const fs::path scene = writeSmallScene(dir.path(), "1-5");
    const fs::path out = dir / "out";
    ASSERT_TRUE(hairpipeSucceeds("sim -q " + q(scene) + " --out " + q(out)));
    const fs::path bad = out / "cache/strands.0003.hpc";
    std::string bytes = readFile(bad);
    bytes[bytes.size() / 2] ^= 0x01;
    writeFile(bad, bytes);

    for (const std::string jobs : {"", " --jobs 2 --chunk 1"}) {
        const ProcessResult r = runHairpipe("render -q " + q(scene) + " --out " + q(out) + " --frames 2-4" + jobs);
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_NE(r.output.find(bad.string()), std::string::npos) << "the message must name the file:\n" << r.output;
        EXPECT_NE(r.output.find("checksum"), std::string::npos) << r.output;
        EXPECT_NE(r.output.find("frame 3"), std::string::npos) << r.output;
        EXPECT_TRUE(fs::exists(out / "preview/preview.0002.png")) << jobs;
        EXPECT_TRUE(fs::exists(out / "preview/preview.0004.png")) << jobs;
        EXPECT_FALSE(fs::exists(out / "preview/preview.0003.png")) << jobs;
        fs::remove_all(out / "preview");
    }
}

TEST(Batch, FrameSubsetRenderedFromTheCacheEqualsTheFullRun) {
    TempDir dir;
    const fs::path scene = writeSmallScene(dir.path());
    ASSERT_TRUE(hairpipeSucceeds("run -q " + q(scene) + " --out " + q(dir / "a")));
    // Another folder (another machine) with only the cache.
    fs::create_directories(dir / "b");
    fs::copy(dir / "a/cache", dir / "b/cache", fs::copy_options::recursive);
    const ProcessResult r = runHairpipe("render " + q(scene) + " --out " + q(dir / "b") + " --frames 2,5");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(r.output.find("simulation:"), std::string::npos) << "frames must come from the cache:\n" << r.output;
    std::vector<std::string> rendered;
    for (const char* folder : {"preview", "reference"})
        for (const auto& e : fs::directory_iterator(dir / "b" / folder)) rendered.push_back(e.path().filename().string());
    std::sort(rendered.begin(), rendered.end());
    // References are on frames 1, 5, 9, ... only.
    EXPECT_EQ(rendered, (std::vector<std::string>{"preview.0002.exr", "preview.0002.png", "preview.0005.exr",
                                                  "preview.0005.png", "reference.0005.exr", "reference.0005.png"}));
    for (const std::string& f : rendered) {
        const std::string folder = f.substr(0, f.find('.'));
        if (f.size() > 4 && f.substr(f.size() - 4) == ".png") {
            EXPECT_TRUE(readFile(dir / "a" / folder / f) == readFile(dir / "b" / folder / f)) << f;
        } else {
            const Image ia = readImage((dir / "a" / folder / f).string()), ib = readImage((dir / "b" / folder / f).string());
            ASSERT_EQ(ia.pixels.size(), ib.pixels.size()) << f;
            EXPECT_EQ(0, std::memcmp(ia.pixels.data(), ib.pixels.data(), ia.pixels.size() * sizeof(float))) << f;
        }
    }
}

/// The small scene with camera follow framing the cached hair (the default
/// scene's camera) instead of its fixed camera.
fs::path writeFollowScene(const fs::path& dir, const std::string& frames) {
    const fs::path scene = writeSmallScene(dir, frames);
    std::string yaml = readFile(scene);
    const std::string fixed = "position: [0.42, 0.08, 0.62], target: [0, -0.04, -0.02], ";
    const size_t at = yaml.find(fixed);
    EXPECT_NE(at, std::string::npos) << "the small scene's camera moved; update this test";
    yaml.replace(at, fixed.size(), "mode: follow, hair: cache, ");
    writeFile(scene, yaml);
    return scene;
}

/// Strand cache frames written under `out`, sorted.
std::vector<std::string> cacheFrames(const fs::path& out) {
    std::vector<std::string> files;
    if (!fs::is_directory(out / "cache")) return files;
    for (const auto& e : fs::directory_iterator(out / "cache"))
        if (e.path().extension() == ".hpc") files.push_back(e.path().filename().string());
    std::sort(files.begin(), files.end());
    return files;
}

TEST(Batch, FollowCameraSimulatesOnlyTheFramesAskedAndFramesThemAlike) {
    TempDir dir;
    const fs::path scene = writeFollowScene(dir.path(), "1-12");
    // sim of frames 1-5 writes those 5 cache frames, not the clip's 12.
    ASSERT_TRUE(hairpipeSucceeds("sim -q " + q(scene) + " --out " + q(dir / "s") + " --frames 1-5"));
    EXPECT_EQ(cacheFrames(dir / "s"), (std::vector<std::string>{"strands.0001.hpc", "strands.0002.hpc", "strands.0003.hpc",
                                                                "strands.0004.hpc", "strands.0005.hpc"}));
    // A preview of frame 3 alone simulates (and caches) only frame 3 ...
    const std::string stages = " --stages sim,preview";
    ASSERT_TRUE(hairpipeSucceeds("run -q " + q(scene) + " --out " + q(dir / "one") + " --frames 3" + stages));
    EXPECT_EQ(cacheFrames(dir / "one"), (std::vector<std::string>{"strands.0003.hpc"}));
    // ... and gets the same camera, strands and pixels as frames 1-5 do.
    ASSERT_TRUE(hairpipeSucceeds("run -q " + q(scene) + " --out " + q(dir / "five") + " --frames 1-5" + stages));
    EXPECT_EQ(cacheFrames(dir / "five").size(), 5u);
    for (const char* f : {"cache/strands.0003.hpc", "preview/preview.0003.png"})
        EXPECT_TRUE(readFile(dir / "one" / f) == readFile(dir / "five" / f)) << f << " differs";
    expectSameFile(dir / "one", dir / "five", "preview/preview.0003.exr");
    // render --force of frame 4 re-simulates frame 4 only, and the camera
    // still reads that frame's hair (the picture matches the 1-5 run).
    ASSERT_TRUE(hairpipeSucceeds("render -q --preview " + q(scene) + " --out " + q(dir / "one") + " --frames 4 --force"));
    EXPECT_EQ(cacheFrames(dir / "one"), (std::vector<std::string>{"strands.0003.hpc", "strands.0004.hpc"}));
    EXPECT_TRUE(readFile(dir / "one/preview/preview.0004.png") == readFile(dir / "five/preview/preview.0004.png"));
}

TEST(Batch, JobsOutputsEqualOneProcessAndTheReportCoversEveryFrame) {
    TempDir dir;
    const fs::path scene = writeSmallScene(dir.path());
    ASSERT_TRUE(hairpipeSucceeds("run -q " + q(scene) + " --out " + q(dir / "a")));
    const ProcessResult r = runHairpipe("run " + q(scene) + " --out " + q(dir / "b") + " --jobs 2 --chunk 3");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("2 chunks"), std::string::npos) << r.output;
    expectSameOutputs(dir / "a", dir / "b");
    // The report is written once, by the parent, over the compare frames 1, 5.
    const std::string csv = readFile(dir / "b/compare/metrics.csv");
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3) << csv;
    for (int f : {1, 5}) EXPECT_NE(csv.find(frameFile("\n%d,", f)), std::string::npos) << csv;
}

TEST(Batch, OverlappedStagesWriteWhatTheSerialRunWrites) {
    // The VDB and compare of frame N run on the overlap lane beside frame
    // N+1's source and preview (pipeline/stages/overlap_lane.h): scheduling
    // only, so every file is the one the serial run writes.
    TempDir dir;
    const fs::path scene = writeSmallScene(dir.path());
    ASSERT_TRUE(hairpipeSucceeds("run -q --no-overlap " + q(scene) + " --out " + q(dir / "serial")));
    const ProcessResult r = runHairpipe("run -v " + q(scene) + " --out " + q(dir / "overlap"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    expectSameOutputs(dir / "serial", dir / "overlap");
    for (int f = 1; f <= 6; ++f) EXPECT_NE(r.output.find(frameFile("frame %d vdb: ", f)), std::string::npos) << r.output;
}

TEST(Batch, ChunkWithoutReportLeavesTheReportToTheLastStep) {
    TempDir dir;
    const fs::path scene = writeSmallScene(dir.path(), "1-6");
    const fs::path out = dir / "out";
    ASSERT_TRUE(hairpipeSucceeds("sim -q " + q(scene) + " --out " + q(out)));
    ASSERT_TRUE(hairpipeSucceeds("run -q " + q(scene) + " --out " + q(out) +
                                 " --frames 1-5 --stages preview,reference,compare --cache-only --no-report"));
    EXPECT_TRUE(fs::exists(out / "compare/metrics.0005.json"));
    EXPECT_FALSE(fs::exists(out / "compare/report.html"));
    EXPECT_FALSE(fs::exists(out / "vdb")) << "--stages limits the run";
    const ProcessResult report = runHairpipe("run -q " + q(scene) + " --out " + q(out) + " --stages compare");
    ASSERT_EQ(report.exitCode, 0) << report.output;
    EXPECT_TRUE(fs::exists(out / "compare/report.html"));

    // --cache-only: a frame without its cache fails instead of simulating.
    fs::remove(out / "cache/strands.0006.hpc");
    const ProcessResult missing =
        runHairpipe("run -q " + q(scene) + " --out " + q(out) + " --frames 6 --stages preview --cache-only");
    EXPECT_EQ(missing.exitCode, 2) << missing.output;
    EXPECT_NE(missing.output.find("strands.0006.hpc is missing"), std::string::npos) << missing.output;
}

TEST(Batch, ExportUsdWritesTheShotAsTimeSamplesFromTheCache) {
    TempDir dir;
    const fs::path scene = writeSmallScene(dir.path(), "1-3");
    const fs::path out = dir / "out";
    const ProcessResult none = runHairpipe("export-usd " + q(scene) + " --out " + q(out));
    EXPECT_EQ(none.exitCode, 1);
    EXPECT_NE(none.output.find("strands.0001.hpc"), std::string::npos) << none.output;
    ASSERT_TRUE(hairpipeSucceeds("sim -q " + q(scene) + " --out " + q(out)));
    ASSERT_TRUE(hairpipeSucceeds("export-usd " + q(scene) + " --out " + q(out)));
    const std::string shot = readFile(out / "usd/hair.usda");
    EXPECT_EQ(shot.rfind("#usda 1.0", 0), 0u);
    EXPECT_NE(shot.find("def BasisCurves \"hair\""), std::string::npos);
    EXPECT_NE(shot.find("startTimeCode = 1\n"), std::string::npos);
    EXPECT_NE(shot.find("endTimeCode = 3\n"), std::string::npos);
    // Each frame's sample equals that frame's own file (same writer, same cache).
    for (int f = 1; f <= 3; ++f) {
        const std::string single = readFile(out / frameFile("usd/hair.%04d.usda", f));
        const std::string key = frameFile("        %d: [(", f);
        const size_t at = single.find(key);
        ASSERT_NE(at, std::string::npos) << single.substr(0, 400);
        const std::string line = single.substr(at, single.find('\n', at) - at);
        EXPECT_NE(shot.find(line), std::string::npos) << "frame " << f;
    }
    for (const char* attr : {"point3f[] points.timeSamples", "vector3f[] velocities.timeSamples",
                             "float[] widths.timeSamples"})
        EXPECT_NE(shot.find(attr), std::string::npos) << attr;
    // As a USD reader sees it: 16 guides + 300 followers, a sample per frame.
    expectBasisCurves(shot, 316, {1, 2, 3}, "usd/hair.usda");
    for (int f = 1; f <= 3; ++f) expectBasisCurves(readFile(out / frameFile("usd/hair.%04d.usda", f)), 316, {f}, "frame");
}

TEST(Batch, BatchOptionsAreChecked) {
    TempDir dir;
    const fs::path scene = writeSmallScene(dir.path(), "1-2");
    const ProcessResult stages = runHairpipe("run " + q(scene) + " --stages preview,bogus");
    EXPECT_EQ(stages.exitCode, 1);
    EXPECT_NE(stages.output.find("unknown stage 'bogus' (stages: sim, preview, reference, vdb, compare)"),
              std::string::npos)
        << stages.output;
    const ProcessResult jobs = runHairpipe("render " + q(scene) + " --jobs 0");
    EXPECT_EQ(jobs.exitCode, 1);
    EXPECT_NE(jobs.output.find("--jobs expects an integer"), std::string::npos) << jobs.output;
    const ProcessResult simJobs = runHairpipe("sim " + q(scene) + " --jobs 2");
    EXPECT_EQ(simJobs.exitCode, 1) << "the simulation is sequential";
}
