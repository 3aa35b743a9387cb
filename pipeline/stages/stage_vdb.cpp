// The "vdb" frame stage: voxelizes the frame's strands (render/volume/voxelizer.h)
// and writes one OpenVDB file per frame (render/volume/vdb_writer.h).
#include "pipeline/stages/stages.h"

#include "core/log.h"
#include "pipeline/batch/output.h"
#include "pipeline/batch/path_template.h"
#include "render/volume/vdb_writer.h"
#include "render/volume/voxelizer.h"

#include <tbb/global_control.h>

#include <chrono>
#include <exception>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace fs = std::filesystem;

namespace hp {

namespace {

double secondsSince(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

class VdbStage final : public FrameStage {
  public:
    VdbStage(const Scene& scene, const ShotSettings& shot) : shot_(shot) {
        voxelSize_ = scene.number("vdb.voxel_size");
        output_ = scene.text("vdb.output");
        if (!hasFrameToken(output_))
            scene.fail("vdb.output", "needs a frame token (#### or %04d), or every frame would overwrite one file");
        if (fs::path(output_).filename().empty()) scene.fail("vdb.output", "must name a file, not a folder");
        voxelize_.filter = scene.text("vdb.filter") == "box" ? VoxelFilter::Box : VoxelFilter::Trilinear;
        voxelize_.velocity = scene.flag("vdb.velocity");
        voxelize_.maxMemoryGiB = scene.number("vdb.max_memory");
        write_.compression = scene.text("vdb.compression") == "none" ? VdbCompression::None : VdbCompression::Blosc;
        write_.halfFloat = scene.flag("vdb.half_float");
        write_.densityScale = scene.number("vdb.density_scale");
        write_.velocity = voxelize_.velocity;
        const std::string& name = scene.text("name");
        sceneName_ = name.empty() ? fs::path(scene.name()).stem().string() : name;
    }

    std::string name() const override { return "vdb"; }
    /// Reads only the strands; voxelizing and writing run beside the next
    /// frame's preview, and the write beside the next frame's voxelizing.
    bool overlaps() const override { return true; }

    std::vector<fs::path> outputs(int frame) const override {
        return {shot_.outputDir / expandFrame(output_, frame)};
    }

    void run(const FrameData& data) override {
        if (!data.strands)
            throw FrameError(cat("the shot has no strands at frame ", data.frame,
                                 " (no hair stage produced any), nothing to voxelize; set vdb.enabled: false "
                                 "or give the scene hair"));
        const StrandFrame& strands = *data.strands;
        const auto t0 = std::chrono::steady_clock::now();
        DensityGrid grid = voxelize(strands, GridTransform::uniform(voxelSize_), voxelize_);
        const size_t activeVoxels = grid.activeVoxelCount();
        const double voxelizeSeconds = secondsSince(t0);

        VdbFrameInfo info;
        info.frame = data.frame;
        info.time = data.time;
        info.fps = shot_.fps;
        info.scene = sceneName_;
        info.strandCount = strands.strandCount();
        info.hairVolume = hairVolume(strands);
        info.filter = voxelize_.filter == VoxelFilter::Box ? "box" : "trilinear";
        const fs::path file = outputs(data.frame).front();
        auto write = [this, file, info, activeVoxels, voxelizeSeconds](DensityGrid& frameGrid) {
            const auto t1 = std::chrono::steady_clock::now();
            // The grid is consumed while written (its memory freed as the file's grows).
            writeAtomically(file, [&](const fs::path& tmp) { writeDensityVdb(tmp, std::move(frameGrid), info, write_); });
            logVerbose("frame ", info.frame, " vdb: ", info.strandCount, " strands -> ", activeVoxels,
                       " active voxels (voxelize ", voxelizeSeconds, " s, write ", secondsSince(t1), " s) -> ",
                       file.string());
        };
        // With the overlap lane, the file is written on a thread of its own
        // while the next frame voxelizes (collectFailures reports a failed
        // write for its frame); otherwise, and on one thread, in turn.
        const bool beside = shot_.overlap &&
                            tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism) > 1;
        waitForWrite();  // at most one file in flight: two grids in memory
        if (!beside) {
            write(grid);
            return;
        }
        writer_ = std::thread([this, write, frame = data.frame, owned = std::move(grid)]() mutable {
            try {
                write(owned);
            } catch (const std::exception& e) {  // hp::Error, or std::bad_alloc from a thread nobody else watches
                const std::lock_guard<std::mutex> lock(mutex_);
                failures_.push_back(cat("frame ", frame, " vdb: ", e.what()));
            }
        });
    }

    std::vector<std::string> collectFailures(bool wait) override {
        if (wait) waitForWrite();
        const std::lock_guard<std::mutex> lock(mutex_);
        return std::exchange(failures_, {});
    }

    ~VdbStage() override { waitForWrite(); }

  private:
    void waitForWrite() {
        if (writer_.joinable()) writer_.join();
    }

    ShotSettings shot_;
    double voxelSize_ = 0.001;
    std::string output_;
    std::string sceneName_;
    VoxelizeSettings voxelize_;
    VdbWriteSettings write_;
    std::thread writer_;  ///< the previous frame's write, while it runs
    std::mutex mutex_;
    std::vector<std::string> failures_;  ///< of writes on writer_, not yet collected
};

}  // namespace

StagePtr makeVdbStage(const Scene& scene, const ShotSettings& shot) {
    if (!scene.flag("vdb.enabled")) return nullptr;
    return std::make_unique<VdbStage>(scene, shot);
}

}  // namespace hp
