#!/usr/bin/env bash
# A longer fuzzing campaign over every parser (tests/fuzz, docs/reliability.md).
#
#   bash scripts/fuzz.sh [--cases N] [--seed S] [--renders R] [--threads T] [TARGET...]
#
# --cases N    mutated inputs per target (default 1000000; CI runs 10000)
# --seed S     RNG seed (default 17: a different stream from CI's per-target
#              seeds); every run with the same seed runs the same inputs
# --renders R  accepted scenes rendered (8x8) and checked per scene target
#              (default 100)
# --threads T  targets run at once (default 2)
# TARGET       test names to run (default all): weather_plain_csv weather_tmy3
#              weather_epw forcing_csv atmosphere_table scene_toml
#              scene_overrides material_library obj_mesh response_csv
#              emissivity_table psf_kernel dem_geotiff gltf_mesh
#              arguments_therm arguments_time path_policy (issue 33)
#              slurm_scripts python_arguments (issue 33; outside
#              tests/fuzz: the generated-script fuzz of
#              tests/reliability_args.rs, N cases of folder name, batch
#              name and sweep values, and the Python-API argument fuzz of
#              python/tests/test_reliability.py, N calls, when .venv holds
#              the irsig package)
#
# Each target prints "fuzz <target>: <cases> cases, <accepted> accepted,
# <refused> refused, <seconds> s"; a failing input is shrunk and printed with
# the reason (panic, non-finite accepted value, error without its file), and
# the script exits non-zero. slurm_scripts and python_arguments also print a
# progress line every 10 000 cases. Throughput on a 2-core machine is roughly
# 50k (scenes) to 2M (tables, kernels) inputs per minute per target.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v cargo >/dev/null 2>&1 && [ -x "$HOME/.cargo/bin/cargo" ]; then
  export PATH="$HOME/.cargo/bin:$PATH"
fi
cases=1000000 seed=17 renders=100 threads=2 targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --cases) cases="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --renders) renders="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    -h|--help) sed -n '2,34p' "$0"; exit 0 ;;
    *) targets+=("$1"); shift ;;
  esac
done
want() { [ ${#targets[@]} -eq 0 ] || printf '%s\n' "${targets[@]}" | grep -qx "$1"; }
parsers=()
for t in "${targets[@]}"; do
  case "$t" in slurm_scripts|python_arguments) ;; *) parsers+=("$t") ;; esac
done
export IRSIG_FUZZ_CASES="$cases" IRSIG_FUZZ_SEED="$seed" IRSIG_FUZZ_RENDERS="$renders"
# Builds a test binary with cargo, then runs it outside cargo, so that a run
# of hours does not hold target/'s build lock.
run_test() {
  local t="$1" exe
  shift
  exe=$(cargo test --release --locked --test "$t" --no-run --message-format=json-render-diagnostics \
    | grep '"reason":"compiler-artifact"' | grep "\"name\":\"$t\"" | grep '"test":true' \
    | sed -n 's/.*"executable":"\([^"]*\)".*/\1/p' | tail -n 1 || true)
  if [ -z "$exe" ]; then
    echo "fuzz: cannot find the $t test binary" >&2
    exit 1
  fi
  "$exe" --nocapture "$@"
}
if [ ${#targets[@]} -eq 0 ] || [ ${#parsers[@]} -gt 0 ]; then
  run_test fuzz --test-threads "$threads" "${parsers[@]}"
fi
if want slurm_scripts; then
  # Each case writes a batch (five files, each written atomically with
  # fsync): on a RAM file system (IRSIG_FUZZ_TMPDIR, default /dev/shm when
  # writable) a case takes milliseconds instead of the disk's flushes.
  shm="${IRSIG_FUZZ_TMPDIR:-/dev/shm}"
  if [ -d "$shm" ] && [ -w "$shm" ]; then
    TMPDIR="$shm" run_test reliability_args generated_scripts_keep_every_name_quoted
  else
    run_test reliability_args generated_scripts_keep_every_name_quoted
  fi
fi
if want python_arguments; then
  if [ -x .venv/bin/python ] && .venv/bin/python -c 'import irsig' 2>/dev/null; then
    .venv/bin/python -m pytest -q -s python/tests/test_reliability.py -k fuzz
  else
    echo "fuzz python_arguments: skipped (no .venv with irsig: scripts/setup.sh)" >&2
  fi
fi
