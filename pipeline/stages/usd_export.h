// Strands as USD BasisCurves (.usda text), so a DCC (Houdini, Blender,
// usdview, Maya) can load the groom. Written directly as text: Debian 12 has
// no USD library.
//
// One file per frame holds a single time sample at that frame; a whole-shot
// file holds every frame as time samples of points/velocities. The curves are
// "linear" (the cached polyline vertices); widths are per vertex (2 × radius),
// strand ids go into a primvar `hairpipe:strandId` (uniform interpolation).
#pragma once

#include "sim/strands/strand.h"

#include <filesystem>
#include <functional>
#include <vector>

namespace hp {

struct UsdExportSettings {
    double fps = 24.0;
    std::string primPath = "/hair";  ///< the BasisCurves prim
};

/// Writes one frame (one time sample) to `path`.
void writeUsdCurves(const std::filesystem::path& path, const StrandFrame& frame, const UsdExportSettings& settings);

/// Writes several frames of the same strands as time samples in one file.
/// All frames must have the same strand counts (topology is not animated).
void writeUsdCurves(const std::filesystem::path& path, const std::vector<const StrandFrame*>& frames,
                    const UsdExportSettings& settings);

/// The same for a whole shot without holding it in memory: `load(frame)`
/// returns each of `frames` (e.g. from the strand cache) and is called a few
/// times per frame (once per time-sampled attribute), never holding two.
void writeUsdCurves(const std::filesystem::path& path, const std::vector<int>& frames,
                    const std::function<StrandFrame(int)>& load, const UsdExportSettings& settings);

}  // namespace hp
