#include "pipeline/stages/usd_export.h"

#include "core/errors.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <functional>
#include <memory>

namespace hp {

namespace {

using File = std::unique_ptr<FILE, int (*)(FILE*)>;

void vec3Array(FILE* f, const std::vector<Vec3f>& v) {
    std::fputc('[', f);
    for (size_t i = 0; i < v.size(); ++i)
        std::fprintf(f, "%s(%.9g, %.9g, %.9g)", i ? ", " : "", v[i].x(), v[i].y(), v[i].z());
    std::fputc(']', f);
}

template <typename T>
void scalarArray(FILE* f, const std::vector<T>& v, const char* format, double scale = 1.0) {
    std::fputc('[', f);
    for (size_t i = 0; i < v.size(); ++i) {
        if (i) std::fputs(", ", f);
        std::fprintf(f, format, double(v[i]) * scale);
    }
    std::fputc(']', f);
}

}  // namespace

namespace {

/// The writer behind both overloads: `frame(i)` returns frame i of `count`,
/// valid until the next call, so a caller may load frames one at a time.
/// Frames are visited once per time-sampled attribute (points, velocities,
/// widths), in order.
void writeCurves(const std::filesystem::path& path, size_t count,
                 const std::function<const StrandFrame&(size_t)>& frame, const UsdExportSettings& s) {
    if (count == 0) throw Error("USD export: no frames");
    // The first frame fixes the topology; copies of the little we need later.
    const StrandFrame& f0 = frame(0);
    f0.validate();
    const std::vector<uint32_t> offsets = f0.offsets;
    const std::vector<uint32_t> ids = f0.ids;
    const uint32_t guideCount = f0.guideCount;
    const int firstFrame = f0.frame;
    const bool velocities = !f0.velocities.empty();
    std::vector<int> counts(f0.strandCount());
    for (size_t i = 0; i < counts.size(); ++i) counts[i] = int(f0.vertexCount(i));
    const int lastFrame = count > 1 ? frame(count - 1).frame : firstFrame;

    File f(std::fopen(path.c_str(), "w"), &std::fclose);
    if (!f) throw IoError(path.string(), std::strerror(errno));
    FILE* out = f.get();
    std::fprintf(out,
                 "#usda 1.0\n(\n    defaultPrim = \"%s\"\n    metersPerUnit = 1\n    upAxis = \"Y\"\n"
                 "    timeCodesPerSecond = %g\n    startTimeCode = %d\n    endTimeCode = %d\n"
                 "    doc = \"hairpipe strands\"\n)\n\n",
                 s.primPath.substr(1).c_str(), s.fps, firstFrame, lastFrame);
    std::fprintf(out, "def BasisCurves \"%s\" (\n    kind = \"component\"\n)\n{\n", s.primPath.substr(1).c_str());
    std::fputs("    uniform token type = \"linear\"\n    uniform token wrap = \"nonperiodic\"\n", out);
    std::fputs("    int[] curveVertexCounts = ", out);
    scalarArray(out, counts, "%.0f");
    // One pass over the frames per attribute; the first pass checks them.
    auto samples = [&](const char* declaration, auto&& write, bool check) {
        std::fprintf(out, "\n    %s.timeSamples = {\n", declaration);
        for (size_t i = 0; i < count; ++i) {
            const StrandFrame& fr = frame(i);
            if (check) {
                fr.validate();
                if (fr.offsets != offsets)
                    throw Error(cat("USD export: frame ", fr.frame, " has different strands than frame ", firstFrame));
                if (fr.velocities.empty() == velocities)
                    throw Error(cat("USD export: frame ", fr.frame, (velocities ? " lacks" : " has"),
                                    " velocities, unlike frame ", firstFrame));
            }
            std::fprintf(out, "        %d: ", fr.frame);
            write(fr);
            std::fputs(",\n", out);
        }
        std::fputs("    }", out);
    };
    samples("point3f[] points", [&](const StrandFrame& fr) { vec3Array(out, fr.positions); }, true);
    if (velocities) samples("vector3f[] velocities", [&](const StrandFrame& fr) { vec3Array(out, fr.velocities); }, false);
    samples("float[] widths", [&](const StrandFrame& fr) { scalarArray(out, fr.radii, "%.9g", 2.0); }, false);
    std::fputs("\n    uniform token widths:interpolation = \"vertex\"\n", out);
    std::fputs("    int[] primvars:hairpipe:strandId = ", out);
    scalarArray(out, ids, "%.0f");
    std::fputs("\n    uniform token primvars:hairpipe:strandId:interpolation = \"uniform\"\n", out);
    std::fprintf(out, "    int primvars:hairpipe:guideCount = %u\n}\n", guideCount);
    if (std::ferror(out) || std::fflush(out) != 0) throw IoError(path.string(), "write failed (disk full?)");
    if (std::fclose(f.release()) != 0) throw IoError(path.string(), "write failed (disk full?)");
}

}  // namespace

void writeUsdCurves(const std::filesystem::path& path, const std::vector<const StrandFrame*>& frames,
                    const UsdExportSettings& s) {
    writeCurves(path, frames.size(), [&](size_t i) -> const StrandFrame& { return *frames[i]; }, s);
}

void writeUsdCurves(const std::filesystem::path& path, const std::vector<int>& frames,
                    const std::function<StrandFrame(int)>& load, const UsdExportSettings& s) {
    StrandFrame current;
    size_t loaded = size_t(-1);
    writeCurves(path, frames.size(),
                [&](size_t i) -> const StrandFrame& {
                    if (i != loaded) current = load(frames[i]), loaded = i;
                    return current;
                },
                s);
}

void writeUsdCurves(const std::filesystem::path& path, const StrandFrame& frame, const UsdExportSettings& s) {
    writeUsdCurves(path, std::vector<const StrandFrame*>{&frame}, s);
}

}  // namespace hp
