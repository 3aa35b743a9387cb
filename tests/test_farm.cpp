// Farm submission: the local engine and a real single-node Slurm cluster
// (tools/farm/slurm-local) produce the same outputs as a plain run; farm
// status counts done and missing frames and names failed tasks.
#include "batch_support.h"

#include <gtest/gtest.h>

#include <cstdlib>

using namespace hp;
using namespace hp::test;
namespace fs = std::filesystem;

namespace {

/// The status table's row of a stage, e.g. "preview    3      4      3".
std::string stageRow(const std::string& status, const std::string& stage) {
    const size_t at = status.find("\n  " + stage + " ");
    if (at == std::string::npos) return "";
    const size_t begin = at + 3;
    return status.substr(begin, status.find('\n', begin) - begin);
}

/// Why a single-node Slurm cluster cannot be started here, or empty.
std::string slurmUnavailable() {
    if (::geteuid() != 0) return "the Slurm daemons and the munge key need root";
    for (const char* tool : {"munged", "slurmctld", "slurmd", "sbatch", "squeue", "sinfo"})
        if (runShell(std::string("command -v ") + tool).exitCode != 0)
            return std::string(tool) + " not found (install slurm-wlm and munge, see tools/setup)";
    return "";
}

/// A running single-node cluster, stopped (daemons ended) on destruction.
class LocalSlurm {
  public:
    explicit LocalSlurm(const fs::path& state) : state_(state) {
        const ProcessResult r = runShell("'" + sourcePath("tools/farm/slurm-local").string() + "' start '" + state.string() + "'");
        output_ = r.output;
        hostCannot_ = r.exitCode == 3;
        const std::string prefix = "export SLURM_CONF=";
        const size_t at = r.output.find(prefix);
        if (r.exitCode == 0 && at != std::string::npos) {
            const size_t begin = at + prefix.size();
            conf_ = r.output.substr(begin, r.output.find('\n', begin) - begin);
            ::setenv("SLURM_CONF", conf_.c_str(), 1);
        }
    }
    ~LocalSlurm() {
        runShell("'" + sourcePath("tools/farm/slurm-local").string() + "' stop '" + state_.string() + "'");
        ::unsetenv("SLURM_CONF");
    }
    bool started() const { return !conf_.empty(); }
    /// slurm-local's exit 3: the host cannot run slurmd (a cgroup plugin
    /// that does not initialise even with the plugins that need none, or a
    /// host name Slurm had to resolve and could not), with the cause in
    /// output(). slurm-local gives up within SLURM_LOCAL_WAIT (30 s).
    bool hostCannot() const { return hostCannot_; }
    const std::string& output() const { return output_; }
    std::string logs() const { return readFile(state_ / "log/slurmctld.log") + readFile(state_ / "log/slurmd.log"); }

  private:
    fs::path state_;
    std::string conf_, output_;
    bool hostCannot_ = false;
};

/// The pid in a daemon's pid file, or 0.
pid_t pidIn(const fs::path& pidFile) { return fs::exists(pidFile) ? pid_t(std::atoi(readFile(pidFile).c_str())) : 0; }

}  // namespace

TEST(Farm, LocalEngineEqualsAPlainRunAndStatusCountsFrames) {
    TempDir dir;
    const fs::path scene = writeSmallScene(dir.path(), "1-4");
    const ProcessResult plain = runHairpipe("run -q " + q(scene) + " --out " + q(dir / "a"));
    ASSERT_EQ(plain.exitCode, 0) << plain.output;
    const fs::path b = dir / "b";

    const ProcessResult before = runHairpipe("farm status " + q(scene) + " --out " + q(b));
    EXPECT_EQ(before.exitCode, 2) << before.output;
    EXPECT_EQ(stageRow(before.output, "preview"), "preview    0      4      1-4") << before.output;

    const ProcessResult submit =
        runHairpipe("farm submit --engine local " + q(scene) + " --out " + q(b) + " --chunk 2 --jobs 2");
    ASSERT_EQ(submit.exitCode, 0) << submit.output;
    EXPECT_NE(submit.output.find("array of 2 tasks of up to 2 frames"), std::string::npos) << submit.output;
    for (const char* f : {"sim.sh", "frames.sh", "report.sh", "submit-slurm.sh", "logs/frames.2.log", "status/report.exit"})
        EXPECT_TRUE(fs::exists(b / "farm" / f)) << f;
    expectSameOutputs(dir / "a", b);

    const ProcessResult done = runHairpipe("farm status " + q(scene) + " --out " + q(b));
    EXPECT_EQ(done.exitCode, 0) << done.output;
    EXPECT_EQ(stageRow(done.output, "sim"), "sim        4      4") << done.output;
    EXPECT_EQ(stageRow(done.output, "preview"), "preview    4      4") << done.output;
    EXPECT_EQ(stageRow(done.output, "reference"), "reference  1      1") << done.output;
    EXPECT_NE(done.output.find("tasks: 4 ok, 0 failed, 0 not finished"), std::string::npos) << done.output;
    EXPECT_NE(done.output.find("\ncomplete\n"), std::string::npos) << done.output;

    // A corrupt cache frame: resubmitting redoes frame 3, its chunk fails, the
    // other chunk and the report still run; status names the failure.
    const fs::path bad = b / "cache/strands.0003.hpc";
    std::string bytes = readFile(bad);
    bytes[bytes.size() / 2] ^= 0x01;
    writeFile(bad, bytes);
    fs::remove(b / "preview/preview.0003.png");
    fs::remove(b / "vdb/hair.0004.vdb");
    const ProcessResult again =
        runHairpipe("farm submit --engine local " + q(scene) + " --out " + q(b) + " --chunk 2 --jobs 2");
    EXPECT_EQ(again.exitCode, 2) << again.output;
    const ProcessResult failed = runHairpipe("farm status " + q(scene) + " --out " + q(b));
    EXPECT_EQ(failed.exitCode, 2) << failed.output;
    EXPECT_EQ(stageRow(failed.output, "preview"), "preview    3      4      3") << failed.output;
    EXPECT_EQ(stageRow(failed.output, "vdb"), "vdb        4      4")
        << "the chunk goes on past its failed frame 3:\n" << failed.output;
    EXPECT_NE(failed.output.find("chunk 2 (frames 3-4)          FAILED, exit code 2"), std::string::npos)
        << failed.output;
    EXPECT_NE(failed.output.find(bad.string()), std::string::npos) << "the error names the file:\n" << failed.output;
    EXPECT_NE(failed.output.find("tasks: 3 ok, 1 failed, 0 not finished"), std::string::npos) << failed.output;
    EXPECT_NE(failed.output.find("\nincomplete\n"), std::string::npos) << failed.output;
}

TEST(Farm, PartOfAShotSimulatesTheFramesItsCamerasRead) {
    // The default camera (follow) frames each frame from its own cached hair:
    // a farm run of frame 2 simulates up to frame 2 and no further. Camera
    // auto frames the cached hair of the frame's whole cut-free segment (here
    // the clip 1-4): its sim job must write frame 4 too, or the frame task
    // (which may only read the cache) fails on it.
    TempDir dir;
    const fs::path scene = writeSmallScene(dir.path(), "1-4");
    std::string yaml = readFile(scene);
    const std::string fixed = "position: [0.42, 0.08, 0.62], target: [0, -0.04, -0.02], ";
    ASSERT_NE(yaml.find(fixed), std::string::npos);
    writeFile(scene, yaml.erase(yaml.find(fixed), fixed.size()));
    const std::string only = " --frames 2 --chunk 1 --set vdb.enabled=false --set reference.enabled=false --set compare.enabled=false";
    const ProcessResult follow =
        runHairpipe("farm submit --engine local " + q(scene) + " --out " + q(dir / "f") + only);
    ASSERT_EQ(follow.exitCode, 0) << follow.output;
    EXPECT_TRUE(fs::exists(dir / "f/preview/preview.0002.png"));
    EXPECT_FALSE(fs::exists(dir / "f/cache/strands.0004.hpc")) << "follow reads frame 2's hair alone";
    const ProcessResult aut = runHairpipe("farm submit --engine local " + q(scene) + " --out " + q(dir / "a") + only +
                                          " --set render.camera.mode=auto");
    ASSERT_EQ(aut.exitCode, 0) << aut.output;
    EXPECT_TRUE(fs::exists(dir / "a/cache/strands.0004.hpc")) << "auto frames the whole segment: the clip is cached";
    EXPECT_TRUE(fs::exists(dir / "a/preview/preview.0002.png"));
}

TEST(Farm, StatusRejectsSubmitOptions) {
    TempDir dir;
    const fs::path scene = writeSmallScene(dir.path(), "1-2");
    const ProcessResult r = runHairpipe("farm status " + q(scene) + " --chunk 2");
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("option --chunk is for farm submit"), std::string::npos) << r.output;
    const ProcessResult engine = runHairpipe("farm submit --engine pbs " + q(scene));
    EXPECT_EQ(engine.exitCode, 1) << engine.output;
    EXPECT_NE(engine.output.find("--engine expects slurm or local, got 'pbs'"), std::string::npos) << engine.output;
}

TEST(Farm, SlurmSingleNodeClusterRunsTheShotLikeALocalRun) {
    const std::string why = slurmUnavailable();
    if (!why.empty()) GTEST_SKIP() << "Slurm cannot be started here: " << why;
    TempDir dir;
    const fs::path scene = writeSmallScene(dir.path(), "1-4");
    const ProcessResult plain = runHairpipe("run -q " + q(scene) + " --out " + q(dir / "a"));
    ASSERT_EQ(plain.exitCode, 0) << plain.output;

    const fs::path state = dir / "slurm";
    std::vector<pid_t> daemons;
    {
        LocalSlurm slurm(state);
        // A reason of the host is a skip, never a failure of the suite.
        if (slurm.hostCannot()) GTEST_SKIP() << "Slurm cannot be started here: " << slurm.output();
        ASSERT_TRUE(slurm.started()) << "tools/farm/slurm-local start failed:\n" << slurm.output() << slurm.logs();
        for (const char* pidFile : {"slurmctld.pid", "slurmd.pid", "munged.pid"}) {
            daemons.push_back(pidIn(state / pidFile));
            EXPECT_GT(daemons.back(), 0) << pidFile;
        }
        const fs::path b = dir / "b";
        const ProcessResult submit =
            runHairpipe("farm submit --engine slurm --wait " + q(scene) + " --out " + q(b) + " --chunk 2");
        ASSERT_EQ(submit.exitCode, 0) << submit.output << slurm.logs();
        EXPECT_NE(submit.output.find("submitted: sim "), std::string::npos) << submit.output;
        EXPECT_TRUE(fs::exists(b / "farm/slurm-jobs.txt"));
        expectSameOutputs(dir / "a", b);

        const ProcessResult status = runHairpipe("farm status " + q(scene) + " --out " + q(b));
        EXPECT_EQ(status.exitCode, 0) << status.output;
        EXPECT_NE(status.output.find("engine slurm"), std::string::npos) << status.output;
        EXPECT_NE(status.output.find("tasks: 4 ok, 0 failed, 0 not finished"), std::string::npos) << status.output;
    }
    // The daemons are gone with the cluster.
    for (pid_t pid : daemons) EXPECT_NE(::kill(pid, 0), 0) << "daemon " << pid << " still running";
}
