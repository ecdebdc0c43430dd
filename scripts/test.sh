#!/usr/bin/env bash
# Strata's whole test suite: installs what is missing, builds, checks formatting, runs ctest.
#   scripts/test.sh              normal build in build/
#   scripts/test.sh --sanitize   AddressSanitizer + UndefinedBehaviorSanitizer build in build-asan/
# Extra arguments after -- go to ctest (e.g. -- -L gpu, -- -R Flood).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

build_dir=build
setup_args=()
ctest_args=()
if [ "${1:-}" = "--sanitize" ]; then
  build_dir=build-asan
  setup_args=(--asan)
  shift
  # Mesa's llvmpipe keeps some allocations until exit (JIT caches); leaks inside the driver
  # are not ours: suppressed by library, everything else still reported.
  # intercept_tls_get_addr=0: LeakSanitizer's bookkeeping of dynamic TLS (dlopen'ed libraries'
  # thread-locals: Mesa, GDAL's and OpenImageIO's plugins) read a stale block on the main thread
  # after a worker thread had exited, and its tracer died with SIGSEGV at exit in 4 of 8 runs of
  # the streamed-render tests (after they passed; 0 of 8 with this). Without the interception
  # those blocks are not scanned for pointers; Strata keeps nothing in dynamic TLS.
  export ASAN_OPTIONS=${ASAN_OPTIONS:-"detect_leaks=1:abort_on_error=1:intercept_tls_get_addr=0"}
  export LSAN_OPTIONS=${LSAN_OPTIONS:-"suppressions=$root/scripts/lsan.supp:print_suppressions=0"}
  export UBSAN_OPTIONS=${UBSAN_OPTIONS:-"print_stacktrace=1:halt_on_error=1"}
  # The longest tests (15 s or more in the normal build, several times that under the
  # sanitizers) run in the normal pass only; every code path they take is also taken by a
  # shorter test here (the rain and shear-law paths by SimRunoffCpu.KinematicPlaneConvergesWithTheCellSize
  # and SimMorphoCpu.LoadAdaptsOverTheSettlingLength; resuming by GlTest.ResumeRefuses... and the
  # CPU RunFolder tests). Under the sanitizers the three added here took 34, 72 and 90 s.
  # StrataCli.CtrlCToMpirun... measures against Open MPI's one second between SIGTERM and SIGKILL,
  # which a sanitized rank's stop may exceed; its report-first order is every run's.
  # SimCpu.TheDefaultThreads... times the thread tuner against one thread: a timing, not a code path
  # the sanitizers would check beyond what ResultsDoNotDependOnTheThreadCount runs.
  # The 150,000-step balance tests (CPU 4 s, GL 95 s unsanitized) take W34's paths that every
  # flood and rain test here takes in a few hundred steps.
  # EA test 4's plain with local steps against one step (2.7 s unsanitized, 29 s sanitized) and
  # its fed cell in nine runs (4.9 s unsanitized): their local-step, point-source and
  # finite-volume paths are SimLocalStepsCpu.IntegratedFacesGiveTheVolumeThatCrossed's and
  # SimInertialCpu.FlatPlainFloodAgreesWithTheFiniteVolumeScheme's.
  ctest_args=(-E 'StrataIngest\.(CtrlCStops|RefusesBadNumbers|TwoHalvesMosaic)|StrataExport\.NeverOverwrites|SimWaterCpu\.FloodRitterDryDamBreak|SimCpu\.(SkippingQuietBlocksChangesNoBit|TheDefaultThreadsAreNotSlowerThanOneOnABusyMachine)|GlTest\.SimLakeAtRestStaysFlat|GlTest\.SimRainPlaneHoldsTheKinematicWaveAtEveryStep|SimRunoffCpu\.(VCatchment|KinematicPlaneHoldsTheSameWaterAtEveryStep)|SimMorphoCpu\.(Channel|RockGorge|SandBanks|ErosionOnARainedPlaneConverges)|GlTest\.InterruptedAndResumedRunEqualsAnUninterruptedOne|StrataCli\.CtrlCToMpirunLeavesTheStoppedRunsReport|BalanceHoldsOver150kFloat32Steps|SimLocalStepsCpu\.FlatPlainAgreesWithOneStepForTheGrid|SimWaterCpu\.APointSourcesCellHoldsTheSameWaterAtEveryStep')
fi
[ "${1:-}" = "--" ] && shift

scripts/setup.sh --build-dir "$root/$build_dir" "${setup_args[@]}"
if [ "$build_dir" = build ]; then
  scripts/format.sh --check
fi
cd "$build_dir"
ctest --output-on-failure -j "$(nproc)" --timeout 600 "${ctest_args[@]}" "$@"
