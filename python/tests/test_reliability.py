"""Issue 33: Python arguments are bounded as the CLI's flags are (one table,
irsig::bounds::args), errors name the Python argument and never a CLI flag,
and no argument can panic, abort or hang the interpreter. The fuzz at the
end runs in a child interpreter so that an abort would show as its exit
status; IRSIG_FUZZ_CASES scales it (scripts/fuzz.sh)."""

import os
import random
import subprocess
import sys
import textwrap

import pytest

import irsig
from conftest import AIRFIELD, ROOT, SMALL

MATS = """
[material.asphalt]
density_kg_m3 = 2100.0
specific_heat_j_kgk = 920.0
conductivity_w_mk = 0.75
thickness_m = 0.3
solar_absorptivity = 0.9
thermal_emissivity = 0.93
back = { deep_ground = { temp_c = 16.85 } }
"""
WEATHER = ROOT / "tests" / "data" / "tmy3_723170_greensboro_jun18-22.csv"


def therm(tmp_path, **kw):
    mats = tmp_path / "m.toml"
    mats.write_text(MATS)
    args = dict(lat=36.1, lon=-79.95, start="1989-06-19T05:00:00Z", stop="1989-06-19T07:00:00Z",
                weather=WEATHER, spin_up_h=2.0)
    args.update(kw)
    return irsig.therm(mats, "asphalt", **args)


@pytest.mark.parametrize("kw, name", [
    ({"step_min": 1e-9}, "step_min"),          # aborted the interpreter (403 TB)
    ({"step_min": 1e-320}, "step_min"),        # capacity overflow panic
    ({"step_min": 1e308}, "step_min"),         # chrono overflow panic
    ({"spin_up_h": 1e12}, "spin_up_h"),        # chrono overflow panic
    ({"slope": float("nan")}, "slope"),
    ({"elevation": 1e300}, "elevation"),
    ({"sky_view": 1.5}, "sky_view"),
])
def test_therm_arguments_out_of_range_name_the_argument(tmp_path, kw, name):
    with pytest.raises(irsig.IrsigError) as e:
        therm(tmp_path, **kw)
    msg = str(e.value)
    assert f"`{name}`" in msg and "out of range" in msg, msg
    assert "--" not in msg, msg


def test_therm_in_range_still_runs(tmp_path):
    df = therm(tmp_path, step_min=30.0)
    assert len(df) == 5 and df["surface_temp_k"].between(250, 350).all()


def test_therm_takes_a_sky_view(tmp_path):
    df = therm(tmp_path, step_min=30.0, sky_view=0.5)
    assert (df["sky_view"] == 0.5).all()
    with pytest.raises(irsig.IrsigError) as e:
        therm(tmp_path, slope=90.0, sky_view=0.8)
    assert "open sky" in str(e.value) and "--" not in str(e.value), str(e.value)


@pytest.mark.parametrize("threads", [0, 1025, 100000, 2**31])
def test_threads_are_bounded_as_the_cli_bounds_them(threads):
    scene = irsig.Scene.load(AIRFIELD, overrides=SMALL)
    with pytest.raises(irsig.IrsigError) as e:
        irsig.render(scene, threads=threads)
    assert "threads" in str(e.value) and "1024" in str(e.value)


@pytest.mark.parametrize("year", ["0001", "1800", "2500", "9999"])
def test_years_outside_1900_2200_are_refused_as_by_the_cli(year):
    scene = irsig.Scene.load(AIRFIELD, overrides=SMALL)
    with pytest.raises(irsig.IrsigError) as e:
        irsig.render(scene, time=f"{year}-06-01T12:00:00Z")
    assert "year" in str(e.value) and "2200" in str(e.value)


def test_errors_name_python_arguments_not_cli_flags():
    scene = irsig.Scene.load(AIRFIELD, overrides=SMALL)
    with pytest.raises(irsig.IrsigError) as e:
        irsig.probe(scene, 9999, 3)
    assert str(e.value).startswith("x=9999, y=3: outside the 64x48 image"), str(e.value)
    with pytest.raises(irsig.IrsigError) as e:
        irsig.sequence(scene, start="09:00", stop="10:00", step="0h")
    assert str(e.value).startswith('step "0h"') and "--" not in str(e.value), str(e.value)
    with pytest.raises(irsig.IrsigError) as e:
        irsig.sequence(scene, start="10:00", stop="09:00", step="1h")
    assert "stop" in str(e.value) and "--" not in str(e.value), str(e.value)


FUZZ = textwrap.dedent("""
    import os, random, sys
    import irsig
    seed, first, cases, mats, weather, state = sys.argv[1:7]
    seed, first, cases = int(seed), int(first), int(cases)
    hostile = [0.0, -0.0, -1.0, 1e-9, 1e-320, 1e308, -1e308, float("nan"), float("inf"),
               -float("inf"), 2.0**31, 2.0**63, 1e12, 9999.0, -9999.0, 0.5]
    names = ["step_min", "spin_up_h", "facet_height_m", "lat", "lon", "elevation", "slope",
             "aspect", "wind_height_m", "air_height_m", "site_roughness_m"]
    # The case being called, written (not appended) before each call: if the
    # interpreter dies, the parent reads which case killed it.
    fd = os.open(state, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    ok = refused = 0
    for k in range(first, cases):
        # One generator per case (from the seed and the case number), so a
        # restart after a crash goes on with exactly the cases that follow.
        rng = random.Random(seed * 1_000_003 + k)
        kw = dict(lat=36.1, lon=-79.95, start="1989-06-19T05:00:00Z", stop="1989-06-19T06:00:00Z",
                  weather=weather, spin_up_h=1.0, step_min=30.0)
        for _ in range(rng.randint(1, 3)):
            v = rng.choice(hostile) if rng.random() < 0.7 else rng.uniform(-1e4, 1e4)
            kw[rng.choice(names)] = v
        # In range but long marches (up to 2e6 steps) would take seconds
        # each; the therm arguments target (tests/fuzz) runs those.
        sm, sp = kw["step_min"], kw["spin_up_h"]
        if 1 / 60 <= sm <= 1440 and 0 <= sp <= 8760 and (1 + sp) * 60 / sm > 2e4:
            kw["spin_up_h"] = 1.0
            kw["step_min"] = 30.0
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{k} {kw!r}".encode(), 0)
        try:
            irsig.therm(mats, "asphalt", **kw)
            ok += 1
        except irsig.IrsigError as e:
            if "--" in str(e):
                print(f"FAIL case {k}: {kw!r}: the error names a CLI flag: {e}", flush=True)
                sys.exit(3)
            refused += 1
        if (k + 1) % 10000 == 0:
            print(f"progress {k + 1} {ok} {refused}", flush=True)
    print(f"done {cases} {ok} {refused}", flush=True)
""")


def test_fuzz_therm_arguments_cannot_kill_the_interpreter(tmp_path):
    """IRSIG_FUZZ_CASES calls of ``irsig.therm`` (default 40) with 1-3
    hostile keywords, all in one child interpreter; a child that dies (a
    panic that escapes, an abort, a signal) or stops answering for 60 s is
    a failure naming the case, and a new child goes on with the next case,
    so a long run reports every failure, not only the first."""
    import threading
    import time

    mats = tmp_path / "m.toml"
    mats.write_text(MATS)
    state = tmp_path / "case"
    cases = max(40, int(os.environ.get("IRSIG_FUZZ_CASES", "0")))
    seed = int(os.environ.get("IRSIG_FUZZ_SEED", "33"))
    first, ok, refused, failures, t0 = 0, 0, 0, [], time.time()
    startup_failures = 0
    while first < cases:
        if state.exists():
            state.unlink()
        child = subprocess.Popen(
            [sys.executable, "-c", FUZZ, str(seed), str(first), str(cases), str(mats), str(WEATHER),
             str(state)],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        lines = []
        base = (ok, refused)

        def read(child=child, lines=lines, base=base):
            # Each progress line is shown as it comes (a run stopped early
            # still reports how far it got).
            for line in iter(child.stdout.readline, ""):
                lines.append(line)
                w = line.split()
                if w and w[0] == "progress":
                    print(f"fuzz python-therm: {w[1]}/{cases} cases, {base[0] + int(w[2])} accepted, "
                          f"{base[1] + int(w[3])} refused, {len(failures)} failures, "
                          f"{time.time() - t0:.0f} s", flush=True)

        reader = threading.Thread(target=read)
        reader.start()
        # A hang: no new case for 60 s once the child has started its first
        # (starting the interpreter and importing irsig may take longer on
        # a loaded machine: 600 s).
        seen, last_change = None, time.time()
        while child.poll() is None:
            time.sleep(1)
            now = state.read_text() if state.exists() else None
            if now != seen:
                seen, last_change = now, time.time()
            elif time.time() - last_change > (60 if seen is not None else 600):
                child.kill()
        reader.join()
        err = child.stderr.read()
        for line in lines:
            w = line.split()
            if w and w[0] in ("progress", "done"):
                ok, refused = base[0] + int(w[2]), base[1] + int(w[3])
        if child.returncode == 0:
            break
        if not state.exists():
            # The child died before its first case: not a case's failure;
            # start it again (a few times) at the same case.
            startup_failures += 1
            assert startup_failures <= 3, f"the child interpreter did not start: {err[-2000:]}"
            continue
        case = state.read_text().strip()
        why = "a hang (no progress for 60 s)" if child.returncode == -9 else \
            f"exit status {child.returncode}"
        failures.append(f"case {case}: {why}: {''.join(lines[-3:])}{err[-2000:]}")
        print(f"fuzz python-therm: FAILURE {failures[-1]}", flush=True)
        first = int(case.split()[0]) + 1
    print(f"fuzz python-therm: {cases} cases, {ok} accepted, {refused} refused, "
          f"{len(failures)} failures, seed {seed}, {time.time() - t0:.0f} s")
    assert not failures, "\n".join(failures)
