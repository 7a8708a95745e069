# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# The tier of every GoogleTest test, as a CTest label (ctest -L unit, -L accuracy, ...):
#   unit         fast checks of one module's contract; what a developer runs on every edit
#   integration  several modules or programs together: the CLI, the samples, tracing, rooms, Python
#   accuracy     statistics and accuracy against exact answers, real files or Monte Carlo error; slow
#   robustness   bad, hostile or absurd input, limits, killed writes and failing system calls
# Each list is a GoogleTest filter (patterns joined by ':', '*' and '?' as wildcards, matched against
# "Suite.Test"; an instantiated suite is "Prefix/Suite"). A test takes the first tier of robustness,
# accuracy, integration whose list it matches; every other test is unit. The program does the matching
# (--gtest_filter), so a new test lands in a tier by its name, and unit is the default.

string(CONCAT LUMX_TIER_ROBUSTNESS
  "BadInput*.*:GltfBadInput.*:RaysetBadInput.*:Tm33BadInput.*:Robustness.*:BsdfRobustness.*:JsonPolicy.*"
  ":Gldf.HostileArchives*:Gldf.CorruptedArchives*:SyscallFaults.*")

string(CONCAT LUMX_TIER_ACCURACY
  "*Accuracy.*:HonestError.*:Emitters/HonestErrorSuite.*:Emitters/ShippedSetSuite.*:AplErrorMeasured.*"
  ":Bsdf/BsdfChi2.*:BsdfConsistency.SampleAgreesWithPdfAndEval:BakeExactIrradiance.*"
  ":RandomStreams.InterleavedFirstDrawsOfConsecutiveStreamsAreUniformAndIndependent"
  ":RandomStreams.TheStatisticsRejectFlawedStreams:RandomStreams.StreamsNeverRepeatEachOther"
  ":Tm33.EveryRealIesAndLdtFileRoundTrips:AplFarField.RealPhotometryRoundTripsThroughAnApl"
  ":SphereMapHarmonics.ShrunkEstimate*:FitReference.*:SphereMapKernel.NoiseFreeSpotsShowWhatTexelMapsCanDo"
  ":AplBuilder.ClustersByLineOnlyWhenTheLinesMeet:AplBuilder.ConvergencePlacementFindsAnEnclosedEmitter"
  ":CliBuild.StoresAndPrintsHeldOutTablesTheLibraryReproduces"
  ":AplErrorLevels.LevelZeroFarAwayIsNearTheNoiseFloorWithTheBuilderRule:PinholeBoxStudy.*")

string(CONCAT LUMX_TIER_INTEGRATION
  "Cli*.*:Sample*.*:Bake*.*:RenderRoom.*:RenderAppearance.*:Gldf.*:LightModelSeam.*Room*")

# lumx_tier_filters(<prefix>): sets <prefix>_robustness, _accuracy, _integration and _unit to disjoint
# GoogleTest filters, in the order above.
function(lumx_tier_filters prefix)
  set(${prefix}_robustness "${LUMX_TIER_ROBUSTNESS}" PARENT_SCOPE)
  set(${prefix}_accuracy "${LUMX_TIER_ACCURACY}-${LUMX_TIER_ROBUSTNESS}" PARENT_SCOPE)
  set(${prefix}_integration "${LUMX_TIER_INTEGRATION}-${LUMX_TIER_ROBUSTNESS}:${LUMX_TIER_ACCURACY}" PARENT_SCOPE)
  set(${prefix}_unit "*-${LUMX_TIER_ROBUSTNESS}:${LUMX_TIER_ACCURACY}:${LUMX_TIER_INTEGRATION}" PARENT_SCOPE)
endfunction()
set(LUMX_TIERS robustness accuracy integration unit)
