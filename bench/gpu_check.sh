#!/usr/bin/env bash
# The GPU check for a lent NVIDIA machine (H100/H200, 16 cores), in one run of at most ~6 min:
#   1. installs what the machine lacks from the carried wheels in .whl/ (bench/gpu_wheels.sh)
#   2. prints the versions and the GPU
#   3. runs the CUDA tests on the real GPU (pytest -m cuda)
#   4. GPU throughput of the 2D dam break at ~25.6k, ~340k, ~1.4M particles (dp 0.01/0.0025/0.00125),
#      through Simulation(device="cuda") (bench/sph_throughput.py --device cuda)
#   5. the CPU step at ~91k particles (dp 0.005) on 1, 2, 4, 8, 16 threads (bench/sph_throughput.py
#      --threads: efficiency_vs_2 per line), and its stages at 1 and 16 threads (bench/step_stages.py)
# JSON lines go to stdout and $OUT/gpu.jsonl, the whole log to $OUT/gpu_check.log.
# Every phase runs under `timeout`, capped by what is left of TOTAL_S, so the script ends in time.
# Overrides (a rerun, or a dry run here): GPU_DPS, CPU_DP, CPU_STEPS, THREADS (empty: no CPU runs), TEST_S,
# FLUMES (non-empty: the H/dp 8 wave flumes on the GPU, two lanes side by side; II: case II
# alone), RUNUP (non-empty: the solitary run-up at d/dp 80 and the breaking one at 40), HOST_THREADS (16: pytest and the GPU runs' host side), TOTAL_S, PYTHON, SKIP_WHEELS,
# SKIP_TESTS, NUMBA_ENABLE_CUDASIM.
set -u
cd "$(dirname "$0")/.."
OUT=${OUT:-/tmp/gpu_check_out}
mkdir -p "$OUT"
LOG=$OUT/gpu_check.log
JSONL=$OUT/gpu.jsonl
: > "$JSONL"
T0=$(date +%s)
TOTAL_S=${TOTAL_S:-350}
GPU_DPS=${GPU_DPS-0.01 0.0025 0.00125}
CPU_DP=${CPU_DP:-0.005}
CPU_STEPS=${CPU_STEPS:-100}
THREADS=${THREADS-1 2 4 8 16}
PY=${PYTHON:-python3}
HT=${HOST_THREADS:-16}
say() { echo "[gpu_check +$(( $(date +%s) - T0 ))s] $*" | tee -a "$LOG" >&2; }
left() { local l=$(( TOTAL_S - ($(date +%s) - T0) )); (( l > $1 )) && l=$1; echo $(( l > 5 ? l : 5 )); }

if [ -z "${SKIP_WHEELS:-}" ] && compgen -G ".whl/*.whl" > /dev/null; then
    say "installing $(ls .whl/*.whl | wc -l) carried wheels into /tmp/site"
    $PY -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
        --target /tmp/site .whl/*.whl 2>&1 | tee -a "$LOG" || say "wheel install FAILED"
    export PYTHONPATH=/tmp/site
fi
export PYTHONPATH=$PWD${PYTHONPATH:+:$PYTHONPATH}
export CUDA_HOME=${CUDA_HOME:-/usr/local/cuda}
export NUMBA_ENABLE_CUDASIM=${NUMBA_ENABLE_CUDASIM:-0}
export NUMBA_CUDA_LOW_OCCUPANCY_WARNINGS=0 PYTHONUNBUFFERED=1 PYTHONDONTWRITEBYTECODE=1

say "versions"
(nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader || true) 2>&1 | tee -a "$LOG"
NUMBA_NUM_THREADS=$HT timeout 60 $PY - <<'PYEOF' 2>&1 | tee -a "$LOG"
import sys, numpy, numba
import sph_core.cuda as sc   # sets np.row_stack before numba.cuda is imported
from importlib.metadata import version
print("python", sys.version.split()[0], "numpy", numpy.__version__, "numba", numba.__version__,
      "numba-cuda", version("numba-cuda"), "simulated", sc.simulated())
print("cuda:", sc.unavailable_reason() or "available")
PYEOF

if [ -z "${SKIP_TESTS:-}" ]; then
    # one pytest process per CUDA test file, side by side (16 cores: each compiles its own CPU
    # twins, the bulk of the time), each with its own numba cache so no two write one file
    say "pytest -m cuda, one process per file (real GPU unless NUMBA_ENABLE_CUDASIM=1)"
    TL=$(left ${TEST_S:-200})
    for f in tests/test_sph_core/test_cuda_*.py; do
        b=$(basename "$f" .py)
        NUMBA_CACHE_DIR=/tmp/nc_$b NUMBA_NUM_THREADS=2 timeout "$TL" $PY -m pytest -m cuda "$f" \
            -q -rP -p no:cacheprovider > "$OUT/$b.log" 2>&1 &
    done
    wait
    for f in tests/test_sph_core/test_cuda_*.py; do
        b=$(basename "$f" .py)
        say "$b: $(tail -1 "$OUT/$b.log")"
        grep -E "FAILED|Error|error" "$OUT/$b.log" | head -20 | tee -a "$LOG"
    done
fi

if [ -n "$GPU_DPS" ]; then
    say "GPU throughput, dp = $GPU_DPS"
    NUMBA_NUM_THREADS=$HT timeout "$(left 150)" $PY bench/sph_throughput.py --device cuda \
        --dps $GPU_DPS --budget 4 2>&1 | tee -a "$LOG" | tee >(grep '^{' >> "$JSONL")
    say "GPU bench exit ${PIPESTATUS[0]}"
fi

if [ -n "$THREADS" ]; then
    # each thread count in a fresh process (efficiency_vs_2 per line), then the step's stages at
    # 1 and at the most threads (share of each, its load balance: bench/step_stages.py)
    say "CPU throughput, dp = $CPU_DP, $CPU_STEPS steps, threads $THREADS"
    timeout "$(left 240)" $PY bench/sph_throughput.py --no-compile --steps "$CPU_STEPS" \
        --dps "$CPU_DP" --threads $THREADS 2>>"$LOG" | tee -a "$JSONL" "$LOG"
    TMAX=$(printf '%s\n' $THREADS | sort -n | tail -1)
    for t in $(printf '%s\n' 1 "$TMAX" | sort -un); do
        say "CPU step stages, dp = $CPU_DP, $t thread(s)"
        NUMBA_NUM_THREADS=$t timeout "$(left 60)" $PY bench/step_stages.py --dp "$CPU_DP" \
            --steps 20 --model-threads "$TMAX" 2>>"$LOG" | tee -a "$JSONL" "$LOG"
    done
fi
if [ "${FLUMES:-}" = "II" ]; then
    # seed 002's case II at H/dp 8 (H 0.02 m in 1 m of water, dp 0.0025 m, ~536k particles, ~1.2e11
    # particle-steps) alone: beside the lanes below it did not finish in 500 s (H200, 2026-11-27)
    say "GPU wave flume: case II at H/dp 8, alone"
    NUMBA_NUM_THREADS=$HT timeout "$(left 580)" $PY bench/flume_accuracy.py --device cuda --case II \
        --dp 0.0025 --periods 4 2>>"$LOG" | tee -a "$JSONL" "$LOG"
elif [ -n "${FLUMES:-}" ]; then
    # the wave flumes at H/dp 8 on the GPU, two lanes side by side (one process each, its own
    # numba cache; the small flumes leave the GPU idle between launches, so lanes overlap):
    #   b: the long flume's loss per wavelength (H 0.04 m, dp 0.005 m, 12 periods, its gauge
    #      records kept in $OUT/records), then the same at h/dp 3 (the closed tank's loss halves
    #      there, the flume's at H/dp 4 does not move: docs/studies/wave_decay_study.md, "At one
    #      smoothing length, more neighbours"), then case III at H/dp 16
    #   c: cases III, IV, V, I at H/dp 8 (IV and I: dp 0.7 m / 38, a whole number of layers)
    # each run prints its JSON line (device, particles, wall_s, wall_s_per_sim_s) when it ends;
    # measured with case II as a third lane (H200, 2026-11-27): lane c 382 s, the long flume 217 s
    say "GPU wave flumes at H/dp 8, two lanes"
    FA="bench/flume_accuracy.py --device cuda"
    lane() {  # lane NAME 'ARGS' ['ARGS' ...]: the runs one after another, each capped by what is left
        local name=$1; shift
        for args in "$@"; do
            say "lane $name: $args"
            NUMBA_CACHE_DIR=/tmp/nc_$name NUMBA_NUM_THREADS=4 timeout "$(left 600)" $PY $args \
                2>>"$OUT/lane_$name.log" | tee -a "$OUT/lane_$name.log" >> "$JSONL"
            say "lane $name: exit ${PIPESTATUS[0]}"
        done
    }
    lane b "bench/wave_decay.py --long --dp 0.005 --device cuda --records $OUT/records" \
           "bench/wave_decay.py --long --dp 0.005 --h-over-dp 3 --device cuda --records $OUT/records_h3" \
           "$FA --case III --dp 0.005 --periods 3 --steady" &
    lane c "$FA --case III --dp 0.01 --periods 3 --steady" \
           "$FA --case IV --dp 0.0184210526 --periods 4 --steady" \
           "$FA --case V --dp 0.0075 --periods 4 --steady" \
           "$FA --case I --dp 0.0184210526 --periods 4 --steady" &
    wait
fi
if [ -n "${RUNUP:-}" ]; then
    # run-up at the resolutions the CPU cannot reach: the non-breaking solitary run-up
    # at d/dp 80 (H/dp 4; d/dp 40 on the CPU: 30k particles, 92k steps, 1,784 s on 2 threads),
    # Boussinesq far field 2 d before the toe, then the breaking wave at d/dp 40 (theory inlet),
    # both on the smooth bed (along_slope: -37 % at d/dp 40 against the staircase's -48 %).
    # Estimate (not run): ~0.1M particles and ~185k steps, at the long flume's ~1.1 ms a step
    # (62k particles, H200) ~4 min; each run capped by what is left of TOTAL_S
    say "GPU run-up: H/d 0.05 at d/dp 80, then H/d 0.3 at d/dp 40"
    for args in "--h-over-d 0.05 --dp-over-d 0.0125 --far-field boussinesq --toe-over-d 2" \
                "--h-over-d 0.3 --dp-over-d 0.025"; do
        NUMBA_NUM_THREADS=$HT timeout "$(left 600)" $PY bench/runup.py --device cuda \
            --bed-layout along_slope $args \
            2>>"$LOG" | tee -a "$JSONL" "$LOG"
        say "run-up $args: exit ${PIPESTATUS[0]}"
    done
fi
say "done: $(wc -l < "$JSONL") JSON lines in $JSONL"
