"""irsig.therm, irsig.atmos and irsig.sun against the CLI's output."""

import io
import json

import numpy as np
import pandas as pd
import pytest

import irsig
from conftest import ROOT, run_cli

MATERIALS = ROOT / "scenes" / "materials.toml"
WEATHER = ROOT / "scenes" / "airfield" / "weather" / "greensboro-nc-tmy3-2001-08-04_09.csv"
THERM = dict(lat=36.1, lon=-79.95, start="2001-08-06T05:00:00Z", stop="2001-08-07T05:00:00Z")


def test_therm_dataframe_is_the_cli_csv():
    df = irsig.therm(MATERIALS, "concrete", weather=WEATHER, slope=30, aspect=200, **THERM)
    assert isinstance(df, pd.DataFrame) and len(df) == 97
    assert str(df.index.tz) == "UTC"
    cli = run_cli(
        "therm", "--materials", MATERIALS, "--material", "concrete", "--weather", WEATHER,
        "--lat", 36.1, "--lon", -79.95, "--from", THERM["start"], "--to", THERM["stop"],
        "--slope", 30, "--aspect", 200, "--csv",
    ).stdout
    ref = pd.read_csv(io.StringIO(cli))
    assert list(df.columns[: len(ref.columns) - 1]) == list(ref.columns[1:])
    assert list(pd.to_datetime(ref.time_utc, utc=True)) == list(df.index)
    for c in ref.columns[1:]:
        # The CLI prints 3 decimals.
        assert np.allclose(df[c].astype(float), ref[c], atol=6e-4, rtol=0), c
    assert df.attrs["material"] == "concrete" and df.attrs["estimators"]


def test_therm_errors_carry_the_cli_message():
    with pytest.raises(irsig.IrsigError) as e:
        irsig.therm(MATERIALS, "concrete_typo", weather=WEATHER, **THERM)
    assert str(MATERIALS) in str(e.value) and "concrete_typo" in str(e.value)
    cli = run_cli(
        "therm", "--materials", MATERIALS, "--material", "concrete_typo", "--weather", WEATHER,
        "--lat", 36.1, "--lon", -79.95, "--from", THERM["start"], "--to", THERM["stop"], check=False,
    )
    assert cli.stderr.strip().splitlines()[-1] == f"irsig: error: {e.value}"


def test_atmos_show_is_the_cli():
    ds = irsig.atmos.show("mls", 1.0, 30.0, band="8-14")
    cli = pd.read_csv(io.StringIO(run_cli("atmos", "show", "mls", "--altitude", 1, "--zenith", 30, "--band", "8-14", "--csv").stdout))
    assert np.array_equal(ds.wavenumber.values, cli.wavenumber_cm1.values)
    for c in ("tau2", "l_ue", "l_de", "tau1", "e_sun_ground"):
        # The CLI prints transmissions with 6 decimals, radiances with 7 digits.
        assert np.allclose(ds[c].values, cli[c].values, rtol=1e-6, atol=6e-7), c
    assert 0 < ds.attrs["band_integrated"]["tau2 (target->sensor)"] < 1
    assert {a["name"] for a in irsig.atmos.list()} >= {"mls", "us1976"}
    with pytest.raises(irsig.IrsigError, match="unknown atmosphere"):
        irsig.atmos.show("nowhere", 1.0, 0.0)


def test_sun_options_and_errors():
    t = "2001-08-08T16:00:00Z"
    cli = json.loads(run_cli("sun", "--lat", 43.1566, "--lon", -77.6088, "--time", t, "--pressure-hpa", 900, "--json").stdout)
    py = irsig.sun(43.1566, -77.6088, t, pressure_hpa=900)
    assert py == cli
    with pytest.raises(irsig.IrsigError, match="lat"):
        irsig.sun(123.0, 0.0, t)
