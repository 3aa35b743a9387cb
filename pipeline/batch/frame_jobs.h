// Local frame parallelism (`--jobs N` of run, render and vdb).
//
// A shot splits where its data flow splits: the simulation is sequential and
// runs first, in this process, writing the strand cache; every later stage is
// independent per frame and runs in child processes (`hairpipe run --frames
// <chunk> --stages ... --cache-only --no-report`), at most N at once, each
// reading the cache. Memory is bounded by N processes each holding one frame
// (plus its renderer); outputs are identical to a one-process run because
// every child computes the same frames from the same bit-exact cache. The
// whole-run outputs (the compare report) are written once, here, over all
// frames after the children end.
#pragma once

#include "pipeline/scene/scene.h"
#include "pipeline/stages/shot.h"

#include <set>

namespace hp {

/// The scene part of a child's command line: the scene file, --out and the
/// overrides (--set, the seed), so the child sees exactly this run's scene.
std::vector<std::string> sceneArguments(const RunOptions& options, const ShotSettings& shot);

/// True when a stage of `stages` renders (preview, reference) with a camera
/// that frames the cached hair (cameraReadsStrandCache, the default camera):
/// the frames its cameras read (cameraCacheFrames) must then be simulated
/// before the first frame is rendered.
bool framesOnCachedHair(const Scene& scene, const std::vector<StagePtr>& stages);

/// @brief Runs the simulation before the frame stages: moves the sim stage
/// out of `stages` (or, when the other stages need strands and the run may
/// simulate, makes one) and runs it over the run's frames, plus, when a
/// render stage's camera auto frames the cached hair, the frames its
/// cameras read (cameraCacheFrames: none more in follow mode, the whole
/// cut-free segments in auto mode).
/// Its failures go into `report`.
void simulateFirst(const Scene& scene, const ShotSettings& shot, std::vector<StagePtr>& stages, RunReport& report);

/// Runs the shot's stages (`only`, all enabled ones if empty) with
/// options.jobs child processes as described above. Frame failures of the
/// children (their "error:" lines) and children that died are collected in
/// the report, not thrown.
RunReport runShotInJobs(const Scene& scene, const RunOptions& options, const std::set<std::string>& only);

}  // namespace hp
