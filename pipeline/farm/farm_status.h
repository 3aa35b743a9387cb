// `hairpipe farm status`: a shot's progress judged from its output folder
// alone — per stage, frames done of total and the missing ones; the farm
// plan's tasks from their status files and logs; the temporaries of running
// or killed writers; and, when Slurm answers, the plan's queued jobs. Needs
// no scheduler: the outputs are the truth, so it works the same for a local
// run, a farm run, or a run someone killed.
#pragma once

#include "pipeline/scene/scene.h"
#include "pipeline/stages/shot.h"

#include <string>

namespace hp {

struct FarmStatus {
    std::string text;       ///< the report, for a terminal
    bool complete = false;  ///< every stage-frame and the compare report written, no task failed
};

/// The status of `scene`'s shot in the output folder `options` resolve to.
FarmStatus farmStatus(const Scene& scene, const RunOptions& options);

}  // namespace hp
