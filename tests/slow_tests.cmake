# Included by CTest after the discovered GoogleTest cases (tests/CMakeLists.txt
# adds it to TEST_INCLUDE_FILES): labels the cases that are compute-bound and
# take a second or more in Release as "slow", so the sanitizer pass
# (tools/sanitize/run: `ctest -LE slow`, several times slower per test) skips
# them. They still run in every normal `ctest`. Entries are
# "<executable>:<Suite.Case>"; the executable stays a label too.
set(_hp_slow_tests
  test_convergence:Convergence.ErrorFallsAsOneOverRootN       # a 4096-spp image and four more
  test_convergence:Convergence.TwoSeedsAtTheThresholdAgreeWithinIt  # four adaptive renders to ~700 spp
  test_path_splitting:PathSplitting.ImageMeanMatchesThePlainEstimator  # 80 physical renders (4 policies x 20 seeds)
  test_hair_bsdf:HairBsdf.WhiteFurnaceByQuadratureLosesAtMostOnePercent  # 16 materials by quadrature
  test_preview_physical:PreviewPhysical.FittedPreviewPredictsThePhysicalRender  # a 128-spp physical render
  test_hair_bsdf:HairBsdf.WhiteFurnaceConservesEnergy          # 10^6 BSDF samples
  test_hair_bsdf:HairBsdf.SampledWhiteFurnaceConservesEnergy
  test_compare:CompareReport.IsSelfContainedAndRendersInHeadlessChromium  # Chromium start-up
  test_preview:Preview.VoxelShadowsDarkenStrandBehindSlab      # llvmpipe raster
  test_preview_cpu_voxels:PreviewCpuVoxels.GridMatchesTheGpuLightPasses  # four renderers' programs, rig shadowed
  test_preview_cpu_voxels:PreviewCpuVoxels.SameBitsOnOneAndTwoThreads  # 40,000 strands voxelized 7 times
  test_preview_cpu_voxels:PreviewCpuVoxels.OtherModesMatchTheGpu  # eight renderers' programs
  test_preview_shadows:PreviewShadows.SecondLightThroughHairIsBeerLambert  # four renders with shadows
  test_preview_shadows:PreviewShadows.ShadowingTheFillDarkensTheHair  # five renders under the rig
  test_preview_shadows:PreviewShadows.CapAndOrderOfShadowedLights  # three renderers' programs
  test_preview_shadows:PreviewShadows.EachViewIsShadedWithItsOwnLights  # seventeen renders
  test_preview_skin:PreviewSkin.SkinThroughTheHairMatchesThePhysicalSlab  # two 64-spp physical renders
  test_preview_skin:PreviewSkin.ScalpBounceIsTheSkinsLightThroughTheHair  # three renders with shadows
  test_preview_compute:PreviewCompute.ComputeShadedVerticesMatchStageShadedOnes  # twenty-four renders
  test_preview_line_pieces:PreviewLinePieces.ComputePiecesMatchTheTessellationStages  # sixteen renders
  test_preview_stage:PreviewStage.ViewerRendersUnderXvfb       # Xvfb start-up
  test_guides:Guides.StableOverTenThousandStepsWithATeleport   # 10^4 solver steps
  test_vdb:VdbFile.BytesAreIdenticalForOneAndTwoThreadsAndRepeatedWrites
  test_voxelizer:Voxelizer.ConservesHairVolumeOfAHeadOfHairToFloatRounding  # 20,000 strands at 1 mm
  test_shot_simulation:ShotSimulation.DefaultClipKeepsLengthsRootsAndClearance
  test_shot_simulation:ShotSimulation.CheckpointRestoreContinuesBitForBit
  test_hair_volume:Volume.BallOfStrandsDroppedOnSphereStaysLessDense   # two 3 s drops of 48 strands
  test_shot_simulation:ShotSimulation.HairHangsUnderGravityAndSwingsWithTheHead  # three shots, 120 frames
  test_shot_simulation:ShotSimulation.DefaultShotCrownHairDoesNotStandMidShakeOrTurned  # the whole default shot, 84 frames
  test_sim_guards:SimGuards.LongViolentRunStaysBoundedAndFinite  # 10^4+ steps
  test_rod:Rod.HeavyElasticaTipMatchesShootingToTheChainsDiscretisation  # 12 runs of 6 s settling
  test_resources:Resources.ResidentMemoryDoesNotGrowOverThirtyFrames  # 30 frames
  test_groom:Units.FbxInCentimetresIsReadInMetresAndInfoSaysSo  # two hairpipe runs
  test_groom:Settle.ConvergesLiesOnTheHeadHoldsStillAndIsReusedByteForByte  # three settles
  test_groom:GroomImport.ExportedUsdaImportsBackAsTheCachedFrame  # sim + export-usd runs
  test_render_parity:RenderParity.ThreePointRigAndSkinMatch    # 5 reference renders
  test_scene_cut:SceneCut.NoVertexInsideAnyColliderOnTheCutFrameAndAfter  # 60 solver steps, two formulations
  test_scene_cut:SceneCut.InfoListsTheCutsOfTheClip             # three head imports
  test_cli:Cli.EveryBundledSceneRendersWithTheDefaultLook       # seven scenes simulated and previewed
  test_scene_cut:SceneCut.StressClipCutFrameHasNoVertexInsideAnyCollider  # exact collider per step
  test_collision_world:CollisionWorld.HairOnAShoulderBoxStaysOnIt  # 300 solver steps
  test_collision_world:CollisionWorld.PropColliderFromASecondFile  # head import + grid
  test_collision_world:CollisionWorld.NonConvexPropKeepsItsHollowWhereAHullFillsIt  # 2 x 50 solver steps
  test_stress_clip:StressClip.NoStretchNorVertexDeeperThanAMillimetreAfterAnyFrameOnOneAndTwoThreads  # two 62-frame shots
  test_camera:CameraAuto.ProjectHeadAndHairStayInFrame         # 2 x 84 frames projected
  test_camera:CameraAuto.FoxStaysInFrame
  test_camera:CameraAuto.StressClipIsReframedAtItsSceneCut
  test_camera:CameraAuto.RenderedBorderHasNoCoverage            # 3 Embree frames
  test_camera:CameraAuto.RunSimulatesTheClipFirstAndChunksFrameAlike  # 3 hairpipe runs
  test_mesh_parts:MeshParts.FollowersIgnoreThePartsTheirRootsLieInside  # followers pinned deep inside a sphere
  test_fold_head:FoldHead.TipClipKeepsLengthsAndClearanceOnOneAndTwoThreads  # 2 x 29 frames, winding numbers on each
  test_fold_head:FoldHead.JumpClipIsOneCutKeepsLengthsAndClearanceOnOneAndTwoThreads  # 2 x 37 frames
)
foreach(_entry IN LISTS _hp_slow_tests)
  string(REPLACE ":" ";" _parts "${_entry}")
  list(GET _parts 0 _exe)
  list(GET _parts 1 _test)
  set_tests_properties(${_test} PROPERTIES LABELS "${_exe};slow")
endforeach()
