"""Shared fixtures: the repository, the CLI built by cargo, a small airfield
scene (64x48 px) and helpers to run the CLI and read its EXR."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
AIRFIELD = ROOT / "scenes" / "airfield" / "scene.toml"
#: A small image keeps every render well under a second on 2 cores.
SMALL = {"sensor.width_px": 64, "sensor.height_px": 48}


def cli_bin() -> Path:
    b = Path(os.environ.get("IRSIG_BIN", ROOT / "target" / "release" / "irsig"))
    if not b.exists():
        pytest.fail(f"{b} missing: build the CLI first (cargo build --release)")
    return b


def run_cli(*args, check=True) -> subprocess.CompletedProcess:
    p = subprocess.run([str(cli_bin()), *map(str, args)], capture_output=True, text=True, cwd=ROOT)
    if check and p.returncode != 0:
        raise AssertionError(f"irsig {' '.join(map(str, args))} failed:\n{p.stderr}")
    return p


def set_args(overrides: dict) -> list:
    return [a for k, v in overrides.items() for a in ("--set", f"{k}={v}")]


#: The UINT value of "no surface" in truth.material and truth.facet.
UINT_NONE = 0xFFFFFFFF


def read_exr(path: Path) -> dict:
    """The planes of an EXR the CLI wrote (OpenEXR's Python bindings, the
    PyPI wheel), as plane name (the ``layer.`` prefix removed) -> float32
    (height, width) array; UINT channels as float32, with UINT_NONE -> -1 in
    material and facet (the planes' value for "no surface")."""
    import OpenEXR

    out = {}
    with OpenEXR.File(str(path)) as f:
        for name, c in f.channels().items():
            plane = name.rsplit(".", 1)[-1]
            px = np.asarray(c.pixels)
            if px.dtype == np.uint32 and plane in ("material", "facet"):
                out[plane] = np.where(px == UINT_NONE, -1.0, px).astype(np.float32)
            else:
                out[plane] = px.astype(np.float32)
    return out


def bits(a: np.ndarray) -> np.ndarray:
    """The float32 bit patterns (NaNs compare equal to the same NaN)."""
    return np.ascontiguousarray(a, dtype=np.float32).view(np.uint32)


@pytest.fixture(scope="session")
def cli_small(tmp_path_factory):
    """The CLI's render of the small airfield: (EXR channels, JSON summary)."""
    out = tmp_path_factory.mktemp("cli") / "small.exr"
    run_cli("render", AIRFIELD, "-o", out, *set_args(SMALL))
    return read_exr(out), json.loads(out.with_suffix(".json").read_text())
