#!/usr/bin/env bash
# Issue 35's GPU measurements, for a session lent a GPU through the `device` tool: build here,
# `scripts/gpu-carry.sh`, then two calls while the machine stays warm (each well under 5 min):
#   run(carry [.gl .gpu .gpur .gpub], timeout 400): scripts/gpu-issue35.sh sim
#     nvidia-smi's name and memory; strata_bench_sim's GL kernels at 4096^2 (flood by scheme and
#     pipes: cell-steps/s, bytes a cell-step and the share of the measured copy bandwidth) and
#     the flat plain after EA test 4 at 2 m (5 h) and 1 m (1 h) with both schemes (steps, seconds,
#     balance; the flat plain's steps chosen on the GPU, W35, and for the inertial scheme at 2 m
#     beside them chosen on the host, with their reads a step); GPU
#     SimBalanceHoldsOver150kFloat32Steps (issue 35's 1e-5 after 150k steps), and the tests that
#     count a step's host reads (W35) on NVIDIA's driver.
#   run(carry [.gl .gpu .gpua], timeout 300): scripts/gpu-issue35.sh job
#     the main job (`strata flood scenarios/grand_canyon_flood.toml`, GL backend, no plots: the
#     device has no matplotlib), timed; its
#     report. (GDAL's chain was unpacked by call 1 on the same machine: scripts/gpu-carry.sh.)
# Everything goes to $OUT (the device tool brings it back); record the figures in
# docs/benchmarks.md beside the CPU ones of this machine.
set -euo pipefail
mode=${1:?usage: scripts/gpu-issue35.sh sim|job}
out=${OUT:-/tmp/issue35}
mkdir -p "$out"
. .gpu/env.sh
. .gpu/libs.sh
# The programs come in call 1 (.gpub) and stay in /tmp/tb while the machine is warm.
if [ -f .gpub/programs.tar.xz ]; then ./.gpu/unpack-programs.sh >/dev/null; fi
[ -x /tmp/tb/strata_bench_sim ] || { echo "scripts/gpu-issue35.sh: no programs in /tmp/tb: run the sim call first" >&2; exit 2; }
nvidia-smi --query-gpu=name,memory.total,clocks.max.memory --format=csv >"$out/gpu-$mode.txt" 2>&1 || true
case $mode in
sim)
  /tmp/tb/strata_bench_sim --benchmark_filter='^(flood|flood_inertial|pipes)/gl/4096|^flat_plain/.*/gl/(2|1)/|^flat_plain/inertial/gl_host_steps/2/' \
    --benchmark_out="$out/bench_sim.json" --benchmark_out_format=json 2>&1 | tee "$out/bench_sim.txt"
  /tmp/tb/strata_sim_gpu_tests \
    --gtest_filter='GlTest.SimBalanceHoldsOver150kFloat32Steps:GlTest.SimDeviceStepsReadOnlyTheirClock:GlTest.SimStepReadsBackOnlyTheWaveSpeed' 2>&1 |
    tee "$out/balance.txt"
  ;;
job)
  start=$(date +%s%N)
  /tmp/tb/strata flood scenarios/grand_canyon_flood.toml -o /tmp/issue35-job --overwrite --backend gpu --no-plots 2>&1 |
    tee "$out/job.txt"
  echo "wall $((($(date +%s%N) - start) / 1000000)) ms" | tee -a "$out/job.txt"
  cp /tmp/issue35-job/report.md "$out/job-report.md"
  ;;
*)
  echo "scripts/gpu-issue35.sh: unknown mode '$mode' (sim or job)" >&2
  exit 2
  ;;
esac
