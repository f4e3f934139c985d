#!/usr/bin/env bash
# The batch runner on a real Slurm: starts a one-node cluster
# (scripts/slurm-cluster.sh), plans a 6-frame batch (3 times x 2 wind speeds
# of the airfield at 32x32 px) in 3 shards, submits it as a job array with a
# dependent merge job (`irsig batch slurm --submit`), waits, and checks that
# the merged stack and every frame equal a local `irsig batch run` + merge of
# the same spec bit for bit. Tears the cluster down afterwards; on failure
# prints the daemons' and the tasks' logs.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
IRSIG=${IRSIG:-$ROOT/target/release/irsig}
[ -x "$IRSIG" ] || { echo "slurm-test: no $IRSIG (build first)" >&2; exit 1; }
T=$(mktemp -d /tmp/irsig-slurm-test.XXXXXX)
CLUSTER="$T/cluster"
cleanup() {
  rc=$?
  bash scripts/slurm-cluster.sh stop "$CLUSTER" || true
  if [ $rc -ne 0 ]; then
    echo "slurm-test: FAILED (rc=$rc); logs:" >&2
    for f in "$CLUSTER"/log/*.log "$T"/slurm-batch/slurm/logs/*.out; do
      [ -f "$f" ] && { echo "== $f" >&2; tail -n 40 "$f" >&2; }
    done
  else
    rm -rf "$T" 2>/dev/null || true
  fi
  exit $rc
}
trap cleanup EXIT
cat > "$T/spec.toml" <<SPEC
name = "slurm-test"
shards = 3

[[scene]]
path = "$ROOT/scenes/airfield/scene-constant.toml"
id = "airfield"
set = { "sensor.width_px" = 32, "sensor.height_px" = 32, "render.history_hours" = 6 }

[time]
at = ["09:00", "12:00", "15:00"]

[[sweep]]
key = "weather.constant.wind_m_s"
values = [0.0, 6.0]
SPEC
"$IRSIG" batch plan "$T/spec.toml" -o "$T/slurm-batch"
"$IRSIG" batch plan "$T/spec.toml" -o "$T/local-batch"

export SLURM_CONF
SLURM_CONF=$(bash scripts/slurm-cluster.sh start "$CLUSTER")
echo "slurm-test: cluster up ($SLURM_CONF)"
out=$("$IRSIG" batch slurm "$T/slurm-batch" --cpus-per-task 1 --submit)
echo "$out"
merge_job=$(echo "$out" | sed -n 's/.*merge job \([0-9]*\).*/\1/p')
[ -n "$merge_job" ] || { echo "slurm-test: no merge job id in: $out" >&2; exit 1; }

# The local reference, rendered while Slurm works.
"$IRSIG" batch run "$T/local-batch" --threads 1 >/dev/null
"$IRSIG" batch merge "$T/local-batch" >/dev/null

for _ in $(seq 600); do
  if ! squeue -h -j "$merge_job" 2>/dev/null | grep -q .; then break; fi
  sleep 1
done
state=$(sacct -n -X -j "$merge_job" -o State 2>/dev/null | head -1 | tr -d ' ' || true)
[ -f "$T/slurm-batch/merged/stack.nc" ] || {
  echo "slurm-test: the merge job $merge_job left no stack (state: ${state:-unknown})" >&2
  "$IRSIG" batch status "$T/slurm-batch" >&2 || true
  exit 1
}
"$IRSIG" batch status "$T/slurm-batch"
n=0
for f in "$T"/local-batch/frames/*.exr; do
  cmp "$f" "$T/slurm-batch/frames/$(basename "$f")"
  n=$((n + 1))
done
[ "$n" -eq 6 ] || { echo "slurm-test: expected 6 frames, found $n" >&2; exit 1; }
.venv/bin/python - "$T/slurm-batch/merged/stack.nc" "$T/local-batch/merged/stack.nc" <<'PY'
import sys
import numpy as np
import xarray as xr
a = xr.open_dataset(sys.argv[1])
b = xr.open_dataset(sys.argv[2])
# The product (1 scene x 3 times x 2 winds) is the stack's dimensions.
want = {"scene": 1, "time": 3, "weather.constant.wind_m_s": 2, "y": 32, "x": 32}
assert a.sizes == b.sizes == want, dict(a.sizes)
for name in list(a.data_vars) + list(a.coords):
    x, y = a[name].values, b[name].values
    if x.dtype.kind == "f":
        assert x.tobytes() == y.tobytes(), name   # bit for bit, NaNs included
    else:
        assert (x == y).all(), name
assert a["apparent_temperature"].attrs["units"] == "K"
for c in ["time", "image_time", "id", "scene", "local_time", "sun_zenith", "weather.constant.wind_m_s"]:
    assert c in a.coords, (c, list(a.coords))
assert a["time"].dtype.kind == "M", a["time"].dtype   # decoded as datetime64
assert list(a["weather.constant.wind_m_s"].values) == [0, 6]
assert a["case"].attrs["flag_meanings"].split()[0] == "outside_scene"
assert np.isfinite(a["apparent_temperature"].values).all()
print(f"slurm-test: merged stacks equal bit for bit ({len(a.data_vars)} variables)")
PY
echo "slurm-test: ok (6 frames in 3 array tasks, merge job $merge_job)"
