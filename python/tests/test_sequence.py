"""irsig.sequence and irsig.sweep against the CLI's per-frame EXRs."""

import json

import numpy as np
import pytest

import irsig
from conftest import AIRFIELD, SMALL, bits, read_exr, run_cli, set_args


@pytest.fixture(scope="module")
def small():
    return irsig.Scene.load(AIRFIELD, overrides=SMALL)


def test_sequence_matches_cli_frames(small, tmp_path):
    ds = irsig.sequence(small, start="09:00", stop="15:00", step="6h", threads=2)
    assert ds.sizes == {"time": 2, "y": 48, "x": 64}
    assert list(ds.time.values) == [np.datetime64("2001-08-08T13:00:00"), np.datetime64("2001-08-08T19:00:00")]
    run_cli("sequence", AIRFIELD, "--from", "09:00", "--to", "15:00", "--step", "6h", "-o", tmp_path, *set_args(SMALL))
    index = json.loads((tmp_path / "index.json").read_text())
    for i, stem in enumerate(["frame_0900", "frame_1500"]):
        exr = read_exr(tmp_path / f"{stem}.exr")
        summary = json.loads((tmp_path / f"{stem}.json").read_text())
        assert ds.sun_zenith_deg.values[i] == summary["sun_zenith_deg"]
        for name, a in exr.items():
            assert np.array_equal(bits(ds[name].values[i]), bits(a)), (stem, name)
    assert len(index["frames"]) == 2
    # The afternoon is not the morning.
    assert not np.array_equal(ds.surface_temperature[0], ds.surface_temperature[1])


def test_sequence_times_list_equals_range(small):
    a = irsig.sequence(small, times=["09:00", "2001-08-08T19:00:00Z"])
    b = irsig.sequence(small, start="09:00", stop="15:00", step="6h")
    assert np.array_equal(a.time.values, b.time.values)
    assert np.array_equal(bits(a.band_radiance.values), bits(b.band_radiance.values))


def test_sweep_matches_cli_frames(tmp_path):
    base = irsig.Scene.load(AIRFIELD.with_name("scene-constant.toml"), overrides=SMALL)
    key = "weather.constant.wind_m_s"
    ds = irsig.sweep(base, key, [0.5, 8.0], threads=2)
    assert ds.sizes == {key: 2, "y": 48, "x": 64}
    assert list(ds[key].values) == [0.5, 8.0]
    run_cli("sweep", base.path, "--key", key, "--values", "0.5,8.0", "-o", tmp_path, *set_args(SMALL))
    for i, v in enumerate(["0.5", "8.0"]):
        exr = read_exr(tmp_path / f"{i:02}_wind_m_s_{v}.exr")
        for name, a in exr.items():
            assert np.array_equal(bits(ds[name].values[i]), bits(a)), (v, name)
