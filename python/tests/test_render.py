"""irsig.render against `irsig render`: the same planes, bit for bit (the
CLI's EXR is read with the OpenEXR wheel from PyPI), and the metadata."""

import json

import numpy as np
import pytest
import xarray as xr

import irsig
from conftest import AIRFIELD, SMALL, bits, read_exr, run_cli, set_args


@pytest.fixture(scope="module")
def small():
    return irsig.Scene.load(AIRFIELD, overrides=SMALL)


@pytest.fixture(scope="module")
def ds(small):
    return irsig.render(small, threads=2)


def test_render_equals_cli_exr_bit_for_bit(ds, cli_small):
    exr, summary = cli_small
    assert isinstance(ds, xr.Dataset)
    assert sorted(ds.data_vars) == sorted(exr)
    for name, a in exr.items():
        v = ds[name]
        assert v.dims == ("y", "x") and v.dtype == np.float32
        assert np.array_equal(bits(v.values), bits(a)), name
    assert [[n, ds[n].attrs["units"]] for n, _ in summary["planes"]] == summary["planes"]


def test_metadata_matches_cli_summary(ds, cli_small):
    _, summary = cli_small
    assert ds.attrs["image_time_utc"] == summary["image_time_utc"]
    assert ds.attrs["sun_zenith_deg"] == summary["sun_zenith_deg"]
    assert ds.attrs["sun_azimuth_deg"] == summary["sun_azimuth_deg"]
    assert ds.attrs["band"] == summary["band"]
    assert ds.attrs["estimators"] == summary["estimators"]
    assert json.loads(ds.attrs["atmosphere"]) == summary["atmosphere"]
    assert ds.sizes == {"y": 48, "x": 64}
    assert ds.time.values == np.datetime64("2001-08-08T16:00:00")
    assert 2.9 < ds.attrs["band_min_um"] < ds.attrs["band_max_um"] < 5.6
    for v in ds.data_vars.values():
        assert v.attrs["long_name"] and "units" in v.attrs


def test_planes_are_the_render_buffers(ds):
    a = ds.band_radiance.to_numpy()
    # xarray hands out the array the extension made from the render's Vec:
    # no copy, so every access sees the same memory.
    assert np.shares_memory(a, ds.band_radiance.values)
    assert a.flags.c_contiguous and not a.flags.owndata


def test_threads_and_time_forms_agree(small, ds):
    one = irsig.render(small, threads=1, time="12:00")
    utc = irsig.render(small, threads=2, time="2001-08-08T16:00:00Z")
    for other in (one, utc):
        for name in ds.data_vars:
            assert np.array_equal(bits(other[name].values), bits(ds[name].values)), name


def test_check_is_the_cli_json():
    import json

    from conftest import run_cli

    assert irsig.Scene.load(AIRFIELD).check() == json.loads(run_cli("check", AIRFIELD, "--json").stdout)


def test_sun_matches_cli():
    import json

    from conftest import run_cli

    t = "2001-08-08T16:00:00Z"
    py = irsig.sun(43.1566, -77.6088, t)
    cli = json.loads(run_cli("sun", "--lat", 43.1566, "--lon", -77.6088, "--time", t, "--json").stdout)
    for k in ("zenith_deg", "azimuth_deg", "elevation_deg", "earth_sun_distance_au"):
        assert py[k] == cli[k], k


def test_probe_is_the_cli_json_and_the_render(small, ds):
    import json

    from conftest import run_cli, set_args

    p = irsig.probe(small, 40, 30)
    cli = json.loads(run_cli("probe", AIRFIELD, "--pixel", "40,30", "--json", *set_args(SMALL)).stdout)
    assert p == cli
    r = np.float32(p["pixel_result"]["band_radiance_f32"])
    assert bits(np.array([r]))[0] == bits(ds.band_radiance.values[30:31, 40])[0]
    later = irsig.probe(small, 40, 30, time="15:00")
    assert later["image_time_local"].startswith("2001-08-08T15:00")


def test_hit_point_coordinates(ds):
    # Where the ray sees a surface, the range is the distance from the
    # camera to the point; elsewhere the coordinates are NaN.
    cam = json.loads(ds.attrs["camera"])
    pos = np.array(cam["position_m"])
    p = np.stack([ds.east.values, ds.north.values, ds.up.values], axis=-1).astype(np.float64)
    hit = np.isfinite(ds.surface_temperature.values)
    assert hit.any()
    assert np.array_equal(hit, np.isfinite(p[..., 0]))
    d = np.linalg.norm(p[hit] - pos, axis=-1)
    # The points are the centre samples'; the range plane is the mean over
    # a pixel's samples, which differs from the centre's only in the pixels
    # adaptive sampling refined (edges: by at most the relief inside the
    # pixel, here tens of metres in ~1.5 km).
    rel = np.abs(d - ds.range.values[hit]) / ds.range.values[hit]
    assert (rel < 1e-4).mean() > 0.8 and rel.max() < 0.05
    assert abs(ds.lat.values[hit].mean() - ds.attrs["latitude_deg"]) < 0.01
    assert ds.lon.units == "degrees_east"


def test_dict_overrides_are_inline_tables():
    pose = {"slant_range": {"slant_range_m": 10000.0, "view_zenith_deg": 75.0, "azimuth_deg": 180.0}}
    a = irsig.Scene.load(AIRFIELD, overrides={"sensor.pose": pose})
    b = irsig.Scene.load(
        AIRFIELD,
        overrides={"sensor.pose": "{slant_range={slant_range_m=10000.0,view_zenith_deg=75.0,azimuth_deg=180.0}}"},
    )
    assert a.check()["camera"] == b.check()["camera"] != irsig.Scene.load(AIRFIELD).check()["camera"]
    c = a.with_overrides({"sensor.width_px": 32})
    assert c.size == (32, a.size[1]) and c.check()["camera"]["forward"] == a.check()["camera"]["forward"]


@pytest.mark.parametrize("compression", ["none", "rle", "zips", "zip", "piz"])
def test_every_exr_compression_reads_back_bit_for_bit(compression, cli_small, tmp_path):
    """OpenEXR's reference library reads each of `--exr-compression`'s
    (lossless) options to the same bits as the default file."""
    import OpenEXR

    out = tmp_path / f"{compression}.exr"
    run_cli("render", AIRFIELD, "-o", out, "--exr-compression", compression, *set_args(SMALL))
    with OpenEXR.File(str(out)) as f:
        assert f.header()["compression"].name == {
            "none": "NO_COMPRESSION",
            "rle": "RLE_COMPRESSION",
            "zips": "ZIPS_COMPRESSION",
            "zip": "ZIP_COMPRESSION",
            "piz": "PIZ_COMPRESSION",
        }[compression]
    exr, default = read_exr(out), cli_small[0]
    assert sorted(exr) == sorted(default)
    for name, a in default.items():
        assert np.array_equal(bits(exr[name]), bits(a)), name


def test_the_scene_chooses_the_exr_compression_and_the_flag_overrides_it(tmp_path):
    """`output.exr_compression` in the scene picks the EXR's compression
    (read by OpenEXR's reference library); `--exr-compression` wins over
    it; a value outside the lossless options is refused with the valid
    ones."""
    import OpenEXR

    def compression(*extra):
        out = tmp_path / "x.exr"
        run_cli("render", AIRFIELD, "-o", out, *set_args(SMALL), *extra)
        with OpenEXR.File(str(out)) as f:
            return f.header()["compression"].name

    assert compression() == "ZIPS_COMPRESSION"
    assert compression("--set", 'output.exr_compression="piz"') == "PIZ_COMPRESSION"
    assert (
        compression("--set", 'output.exr_compression="piz"', "--exr-compression", "rle")
        == "RLE_COMPRESSION"
    )
    p = run_cli(
        "render", AIRFIELD, "-o", tmp_path / "y.exr", *set_args(SMALL),
        "--set", 'output.exr_compression="pxr24"', check=False,
    )
    assert p.returncode != 0, p.stderr
    assert "unknown variant `pxr24`, expected one of `none`, `rle`, `zips`, `zip`, `piz`" in p.stderr
    assert not (tmp_path / "y.exr").exists()


def test_unknown_exr_compression_is_refused_with_the_valid_names(tmp_path):
    p = run_cli("render", AIRFIELD, "-o", tmp_path / "x.exr", "--exr-compression", "pxr24", check=False)
    assert p.returncode != 0
    assert "expected one of none, rle, zips, zip, piz" in p.stderr
    assert not (tmp_path / "x.exr").exists()
