// B-vdb (docs/benchmarks.md): voxelize the ~100k strands of B-render and write
// one VDB frame, at 1 mm and 0.5 mm voxels, on 2 threads and 1.
//
// Until the simulation is integrated, the strands come from
// makeSyntheticHair (sim/strands/synthetic.h): 100,000 strands × 24 vertices on the
// r = 0.1 m sphere's upper hemisphere, 0.25 m long, root radius 0.04 mm
// tapering to 0.01 mm — the B-render geometry without simulated shapes.
//
// Reports per configuration the median and spread of `runs` runs: seconds to
// voxelize, seconds to write, file size, active voxels, peak resident memory
// (reset between configurations through /proc/self/clear_refs), and the
// relative mass error |Σ density·V − hair volume| / hair volume; then the
// median CPU and wall seconds of voxelize's phases (VoxelizePhases: preparing
// the segments, binning them by tile, the tiles' walks and deposits,
// gathering the blocks).
//
// Written as the vdb stage writes by default (vdb.half_float: true,
// vdb.compression: none); --float and --compression blosc give the full-float,
// Blosc-compressed file of earlier versions. The mass error is reported for
// the grid (before writing) and for the file as read back (half floats round
// each value to ~3 significant digits).
//
// --limits: the machine's bounds for this frame instead: memcpy bandwidth on
// 1 and 2 threads, and OpenVDB's own Blosc codec (io::bloscToStream, as the
// writer calls it per leaf) on the frame's active values, in MB/s.
//
// usage: bench_vdb [--strands N] [--voxel m ...] [--threads n ...] [--runs k]
//                  [--filter box|trilinear] [--velocity] [--float] [--compression blosc|none] [--limits]
//                  [--kernel auto|sse2] (the deposit's instruction set: AVX2 where the CPU has it,
//                                  or the SSE2 reference; same grid)
//                  [--keep DIR]   (keep the written files there)
//                  [--compare FILE] (compare the first run's grid with the density of a
//                                  float VDB written before, e.g. by another build with
//                                  --float --keep: active voxels, max relative difference)
//                  [--frames N]   (instead: frames 1..N, each turned 0.5° from the last,
//                                  voxelized and written serially, then with frame k
//                                  written while frame k+1 voxelizes: seconds per frame)
//                  [--sequence F] (instead: write frames 1..F of the hair spinning with the
//                                  B-sim head, 90°/s about +Y at 24 fps, as hair.####.vdb —
//                                  the whole-sequence time, and files to check in a DCC)
#include "render/volume/vdb_writer.h"
#include "render/volume/voxelizer.h"
#include "sim/strands/synthetic.h"
#include "tools/bench/bench_support.h"

#include <Eigen/Geometry>
#include <openvdb/io/Compression.h>
#include <openvdb/openvdb.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <unistd.h>
#include <limits>
#include <unordered_map>
#include <vector>

namespace fs = std::filesystem;
using namespace hp;

namespace {

double seconds(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

/// Peak resident set (VmHWM) in MiB.
double peakMiB() {
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line))
        if (line.rfind("VmHWM:", 0) == 0) return std::atof(line.c_str() + 6) / 1024.0;
    return 0;
}

void resetPeak() { std::ofstream("/proc/self/clear_refs") << "5"; }

/// Counts what is written and keeps none of it.
struct CountingBuffer : std::streambuf {
    size_t bytes = 0;
    std::streamsize xsputn(const char*, std::streamsize n) override {
        bytes += size_t(n);
        return n;
    }
    int overflow(int c) override {
        ++bytes;
        return c;
    }
};

/// Best of 5 copies of `bytes` between two buffers on `threads` threads, in GB/s of bytes copied.
double copyBandwidth(size_t bytes, int threads) {
    std::vector<char> from(bytes, 1), to(bytes, 0);
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    double best = 1e30;
    for (int r = 0; r < 5; ++r) {
        const auto t = std::chrono::steady_clock::now();
        const size_t chunk = bytes / size_t(threads);
        tbb::parallel_for(0, threads, [&](int i) {
            std::memcpy(to.data() + size_t(i) * chunk, from.data() + size_t(i) * chunk, chunk);
        });
        best = std::min(best, seconds(t));
    }
    return double(bytes) / best * 1e-9;
}

/// --limits: memory bandwidth, and OpenVDB's Blosc codec and a buffered file
/// write on this frame's active values (one call per leaf, as the writer).
void reportLimits(const StrandFrame& frame, double h) {
    const size_t bytes = size_t(256) << 20;
    std::printf("memcpy of 256 MiB (best of 5): %.2f GB/s on 1 thread, %.2f GB/s on 2\n", copyBandwidth(bytes, 1),
                copyBandwidth(bytes, 2));
    const DensityGrid grid = voxelize(frame, GridTransform::uniform(h));
    std::vector<std::vector<float>> leaves(grid.blockCount());
    std::vector<std::vector<openvdb::math::half>> halves(grid.blockCount());
    size_t values = 0;
    for (size_t b = 0; b < grid.blockCount(); ++b) {
        for (int i = 0; i < DensityGrid::kBlockVoxels; ++i)
            if (grid.blockDensity(b)[i] > 0) leaves[b].push_back(grid.blockDensity(b)[i]);
        halves[b].assign(leaves[b].begin(), leaves[b].end());
        values += leaves[b].size();
    }
    auto codec = [&](auto& data, const char* what) {
        double best = 1e30;
        size_t out = 0;
        for (int r = 0; r < 3; ++r) {
            CountingBuffer counter;
            std::ostream os(&counter);
            const auto t = std::chrono::steady_clock::now();
            for (const auto& leaf : data)
                openvdb::io::bloscToStream(os, reinterpret_cast<const char*>(leaf.data()), sizeof(leaf[0]), leaf.size());
            best = std::min(best, seconds(t));
            out = counter.bytes;
        }
        const double in = double(values * sizeof(data[0][0]));
        std::printf("Blosc (OpenVDB io::bloscToStream, LZ4, per leaf, 1 thread) on %zu active %s values: %.0f MB/s "
                    "(%.3f s), %.1f -> %.1f MiB\n",
                    values, what, in / best * 1e-6, best, in / (1 << 20), double(out) / (1 << 20));
    };
    openvdb::initialize();
    codec(leaves, "float");
    codec(halves, "half");
    // The same values written uncompressed through a 4 MiB stream buffer, as the writer does.
    const fs::path file = fs::temp_directory_path() / ("bench_vdb_limits_" + std::to_string(::getpid()));
    double best = 1e30;
    for (int r = 0; r < 3; ++r) {
        std::vector<char> buffer(size_t(4) << 20);
        std::ofstream out;
        out.rdbuf()->pubsetbuf(buffer.data(), std::streamsize(buffer.size()));
        const auto t = std::chrono::steady_clock::now();
        out.open(file, std::ios::binary | std::ios::trunc);
        for (const auto& leaf : leaves) out.write(reinterpret_cast<const char*>(leaf.data()), std::streamsize(leaf.size() * 4));
        out.close();
        best = std::min(best, seconds(t));
    }
    fs::remove(file);
    std::printf("uncompressed write of the float values (4 MiB stream buffer, page cache): %.0f MB/s (%.3f s)\n",
                double(values * 4) / best * 1e-6, best);
}

/// --compare: how `grid` differs from the density of a float VDB file written
/// earlier (e.g. by another build with --float --keep): voxels active in one
/// and not the other, and the largest relative difference of a voxel's value.
void compareWith(const fs::path& file, const DensityGrid& grid) {
    const DensityGrid other = readDensityVdb(file).density;
    std::unordered_map<uint64_t, size_t> blocks;
    for (size_t b = 0; b < other.blockCount(); ++b)
        blocks.emplace(DensityGrid::blockKey(other.blockOrigin(b) / DensityGrid::kBlockSize), b);
    size_t onlyHere = 0, onlyThere = 0, differ = 0, same = 0;
    double maxRelative = 0;
    for (size_t b = 0; b < grid.blockCount(); ++b) {
        const auto it = blocks.find(DensityGrid::blockKey(grid.blockOrigin(b) / DensityGrid::kBlockSize));
        const float* there = it == blocks.end() ? nullptr : other.blockDensity(it->second);
        for (int i = 0; i < DensityGrid::kBlockVoxels; ++i) {
            const float a = grid.blockDensity(b)[i], o = there ? there[i] : 0.f;
            if ((a > 0) != (o > 0)) ++(a > 0 ? onlyHere : onlyThere);
            if (a > 0 && o > 0) {
                a == o ? ++same : ++differ;
                maxRelative = std::max(maxRelative, std::abs(double(a) - double(o)) / double(o));
            }
        }
        if (there) blocks.erase(it);
    }
    for (const auto& kv : blocks)
        for (int i = 0; i < DensityGrid::kBlockVoxels; ++i) onlyThere += other.blockDensity(kv.second)[i] > 0;
    std::printf("compared with %s: %zu voxels active only here, %zu only there; of the common ones %zu equal, "
                "%zu differ, max relative difference %.3g (float ulp %.3g)\n",
                file.c_str(), onlyHere, onlyThere, same, differ, maxRelative, double(std::numeric_limits<float>::epsilon()));
}

/// Frame f of a short shot: the strands turned by 0.5° per frame about +Y
/// (the B-sim head's spin, slowed), so no two frames voxelize alike.
StrandFrame turnedFrame(const StrandFrame& frame, int f) {
    const Eigen::Matrix3f turn = Eigen::AngleAxisf(0.00872665f * float(f), Vec3f::UnitY()).toRotationMatrix();
    StrandFrame moved = frame;
    for (Vec3f& p : moved.positions) p = turn * p;
    for (Vec3f& v : moved.velocities) v = turn * v;
    return moved;
}

/// --frames N: frames 1..N voxelized and written one after the other
/// (serial), then again with frame k's file written on a second thread while
/// frame k+1 voxelizes (pipelined: what a shot's frames can do, the write
/// off the critical path). Wall and process CPU seconds per frame of each,
/// `runs` times, interleaved.
void reportFrames(const StrandFrame& frame, double h, int threads, int frames, int runs, const VoxelizeSettings& vs,
                  const VdbWriteSettings& ws, const fs::path& dir, double volume) {
    std::vector<StrandFrame> shot;
    for (int f = 1; f <= frames; ++f) shot.push_back(turnedFrame(frame, f));
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    auto write = [&](int f, DensityGrid&& grid) {
        VdbFrameInfo info;
        info.frame = f;
        info.time = f / 24.0;
        info.scene = "B-vdb";
        info.strandCount = shot[size_t(f - 1)].strandCount();
        info.hairVolume = volume;
        char name[32];
        std::snprintf(name, sizeof name, "hair.%04d.vdb", f);
        writeDensityVdb(dir / name, std::move(grid), info, ws);
    };
    std::vector<double> serial, serialCpu, piped, pipedCpu;
    for (int r = 0; r < runs; ++r) {
        auto t = std::chrono::steady_clock::now();
        double c = bench::processCpuSeconds();
        for (int f = 1; f <= frames; ++f) write(f, voxelize(shot[size_t(f - 1)], GridTransform::uniform(h), vs));
        serial.push_back(seconds(t) / frames);
        serialCpu.push_back((bench::processCpuSeconds() - c) / frames);

        t = std::chrono::steady_clock::now();
        c = bench::processCpuSeconds();
        std::thread writer;
        DensityGrid writing;  // the grid the writer thread owns
        for (int f = 1; f <= frames; ++f) {
            DensityGrid grid = voxelize(shot[size_t(f - 1)], GridTransform::uniform(h), vs);
            if (writer.joinable()) writer.join();
            writing = std::move(grid);
            writer = std::thread([&, f] { write(f, std::move(writing)); });
        }
        writer.join();
        piped.push_back(seconds(t) / frames);
        pipedCpu.push_back((bench::processCpuSeconds() - c) / frames);
    }
    const bench::Stats s = bench::stats(serial), p = bench::stats(piped);
    std::printf("%d frames at %.2f mm, %d thread%s, per frame: serial (voxelize, write) %.3f s [%.3f-%.3f] (cpu %.3f s), "
                "pipelined (write beside the next voxelize) %.3f s [%.3f-%.3f] (cpu %.3f s)\n",
                frames, h * 1e3, threads, threads == 1 ? "" : "s", s.median, s.min, s.max, bench::stats(serialCpu).median,
                p.median, p.min, p.max, bench::stats(pipedCpu).median);
}

}  // namespace

int main(int argc, char** argv) {
    size_t strands = 100000;
    std::vector<double> voxels;
    std::vector<int> threads;
    int runs = 3, sequence = 0, frames = 0;
    VoxelizeSettings vs;
    VdbWriteSettings ws;
    ws.halfFloat = true;  // the scene defaults (pipeline/scene/keys/vdb.yaml)
    ws.compression = VdbCompression::None;
    bool limits = false;
    fs::path keep, compare;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "bench_vdb: %s needs a value\n", a.c_str());
                std::exit(1);
            }
            return argv[++i];
        };
        if (a == "--strands") strands = size_t(std::atol(next().c_str()));
        else if (a == "--voxel") voxels.push_back(std::atof(next().c_str()));
        else if (a == "--threads") threads.push_back(std::atoi(next().c_str()));
        else if (a == "--runs") runs = std::max(1, std::atoi(next().c_str()));
        else if (a == "--filter") vs.filter = next() == "box" ? VoxelFilter::Box : VoxelFilter::Trilinear;
        else if (a == "--velocity") vs.velocity = true;
        else if (a == "--kernel") vs.kernel = next() == "sse2" ? VoxelKernel::Sse2 : VoxelKernel::Auto;
        else if (a == "--half") ws.halfFloat = true;
        else if (a == "--float") ws.halfFloat = false;
        else if (a == "--limits") limits = true;
        else if (a == "--compression") ws.compression = next() == "none" ? VdbCompression::None : VdbCompression::Blosc;
        else if (a == "--keep") keep = next();
        else if (a == "--compare") compare = next();
        else if (a == "--frames") frames = std::max(1, std::atoi(next().c_str()));
        else if (a == "--sequence") sequence = std::max(1, std::atoi(next().c_str()));
        else {
            std::fprintf(stderr, "bench_vdb: unknown argument %s (see the comment at the top of bench_vdb.cpp)\n", a.c_str());
            return 1;
        }
    }
    if (voxels.empty()) voxels = {0.001, 0.0005};
    if (threads.empty()) threads = {2, 1};

    SyntheticHairSettings hs;
    hs.strands = strands;
    const auto t0 = std::chrono::steady_clock::now();
    StrandFrame frame = makeSyntheticHair(hs);
    if (vs.velocity) {  // a plausible velocity field: the head's spin about +Y at 90°/s
        frame.velocities.resize(frame.positions.size());
        for (size_t v = 0; v < frame.positions.size(); ++v)
            frame.velocities[v] = Vec3f(0, 1.5707963f, 0).cross(frame.positions[v]);
    }
    const double volume = hairVolume(frame);
    std::printf("B-vdb: %zu synthetic strands x %d vertices (makeSyntheticHair; no simulation yet), "
                "hair volume %.6g m^3, built in %.2f s\n",
                frame.strandCount(), hs.vertices, volume, seconds(t0));
    std::printf("filter %s, velocity %s, kernel %s, %s, %s, %d runs (median [min-max])\n",
                vs.filter == VoxelFilter::Box ? "box" : "trilinear", vs.velocity ? "on" : "off",
                vs.kernel == VoxelKernel::Sse2 ? "sse2" : "auto (avx2 where the CPU has it)",
                ws.halfFloat ? "half float" : "float",
                ws.compression == VdbCompression::Blosc ? "blosc" : "no compression", runs);

    if (limits) {
        reportLimits(frame, voxels.front());
        return 0;
    }
    const fs::path dir = keep.empty() ? fs::temp_directory_path() / ("bench_vdb_" + std::to_string(::getpid())) : keep;
    fs::create_directories(dir);
    if (frames > 0) {
        reportFrames(frame, voxels.front(), threads.front(), frames, runs, vs, ws, dir, volume);
        if (keep.empty()) fs::remove_all(dir);
        return 0;
    }
    if (sequence > 0) {
        // Frame f: the strands rotated by the head's spin at time f / 24 s.
        const double h = voxels.front();
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads.front()));
        resetPeak();
        const auto ts = std::chrono::steady_clock::now();
        const double cs = bench::processCpuSeconds();
        size_t bytes = 0;
        for (int f = 1; f <= sequence; ++f) {
            const Eigen::Matrix3f spin = Eigen::AngleAxisf(1.5707963f * float(f) / 24.f, Vec3f::UnitY()).toRotationMatrix();
            StrandFrame moved = frame;
            for (Vec3f& p : moved.positions) p = spin * p;
            for (Vec3f& v : moved.velocities) v = spin * v;
            VdbFrameInfo info;
            info.frame = f;
            info.time = f / 24.0;
            info.scene = "B-vdb";
            info.strandCount = moved.strandCount();
            info.hairVolume = volume;
            char name[32];
            std::snprintf(name, sizeof name, "hair.%04d.vdb", f);
            writeDensityVdb(dir / name, voxelize(moved, GridTransform::uniform(h), vs), info, ws);
            bytes += size_t(fs::file_size(dir / name));
        }
        std::printf("sequence of %d frames at %.2f mm, %d thread(s): %.2f s (cpu %.2f s), %.1f MiB in all, "
                    "peak RSS %.0f MiB -> %s\n",
                    sequence, h * 1e3, threads.front(), seconds(ts), bench::processCpuSeconds() - cs, double(bytes) / (1 << 20),
                    peakMiB(), dir.c_str());
        if (keep.empty()) fs::remove_all(dir);
        return 0;
    }
    for (double h : voxels) {
        for (int n : threads) {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(n));
            resetPeak();
            std::vector<double> tv, tw, cv, cw, tf, phase[4], phaseWall[4];
            VoxelizePhases phases;
            VoxelizeSettings timed = vs;
            timed.phases = &phases;
            size_t activeVoxels = 0, bytes = 0, blocks = 0;
            double massError = 0;
            const fs::path file = dir / ("hair_" + std::to_string(int(h * 1e6)) + "um.vdb");
            for (int r = 0; r < runs; ++r) {
                auto t = std::chrono::steady_clock::now();
                double c = bench::processCpuSeconds();
                DensityGrid grid = voxelize(frame, GridTransform::uniform(h), timed);
                tv.push_back(seconds(t));
                int p = 0;
                for (const auto* ph : {&phases.prepare, &phases.bin, &phases.tiles, &phases.gather})
                    phaseWall[p].push_back(ph->wall), phase[p++].push_back(ph->cpu);
                cv.push_back(bench::processCpuSeconds() - c);
                activeVoxels = grid.activeVoxelCount();
                blocks = grid.blockCount();
                massError = std::abs(grid.totalVolume() - volume) / volume;
                if (!compare.empty() && r == 0) compareWith(compare, grid);  // outside the timings
                VdbFrameInfo info;
                info.frame = 1;
                info.scene = "B-vdb";
                info.strandCount = frame.strandCount();
                info.hairVolume = volume;
                t = std::chrono::steady_clock::now();
                c = bench::processCpuSeconds();
                writeDensityVdb(file, std::move(grid), info, ws);  // consumes the grid, as the stage does
                tw.push_back(seconds(t));
                cw.push_back(bench::processCpuSeconds() - c);
                tf.push_back(tv.back() + tw.back());
                bytes = size_t(fs::file_size(file));
            }
            const double peak = peakMiB();
            // The file's own mass error (read back outside the timings).
            const double fileMassError = std::abs(readDensityVdb(file).density.totalVolume() - volume) / volume;
            const bench::Stats v = bench::stats(tv), w = bench::stats(tw), vc = bench::stats(cv), wc = bench::stats(cw),
                               f = bench::stats(tf);
            std::printf("voxel %.2f mm, %d thread%s: frame %.3f s [%.3f-%.3f] = voxelize %.3f s [%.3f-%.3f] (cpu %.3f s) + "
                        "write %.3f s [%.3f-%.3f] (cpu %.3f s), file %.1f MiB, %zu active voxels in %zu leaves, "
                        "peak RSS %.0f MiB, mass error %.2e (file %.2e)\n",
                        h * 1e3, n, n == 1 ? " " : "s", f.median, f.min, f.max, v.median, v.min, v.max, vc.median,
                        w.median, w.min, w.max, wc.median, double(bytes) / (1 << 20), activeVoxels, blocks, peak,
                        massError, fileMassError);
            std::printf("  voxelize's phases, cpu s (wall s), medians:");
            const char* names[4] = {"prepare", "bin", "tiles", "gather"};
            for (int p = 0; p < 4; ++p)
                std::printf(" %s %.3f (%.3f)", names[p], bench::stats(phase[p]).median, bench::stats(phaseWall[p]).median);
            std::printf("\n");
            std::fflush(stdout);
        }
    }
    if (keep.empty()) fs::remove_all(dir);
    return 0;
}
