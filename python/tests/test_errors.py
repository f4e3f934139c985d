"""Bad input raises irsig exceptions carrying the CLI's message: file, line
and key."""

import pytest

import irsig
from conftest import AIRFIELD, SMALL, run_cli, set_args


def cli_error(*args) -> str:
    p = run_cli(*args, check=False)
    assert p.returncode != 0
    line = p.stderr.strip().splitlines()[-1]
    assert line.startswith("irsig: error: ")
    return line[len("irsig: error: "):]


def test_unknown_key_names_file_line_and_key(tmp_path):
    with pytest.raises(irsig.SceneError) as e:
        irsig.Scene.load(AIRFIELD, overrides={"sensor.widht_px": 64})
    err = e.value
    assert isinstance(err, irsig.IrsigError)
    # The key is on no line of the file: the override is named instead.
    assert err.file == str(AIRFIELD) and err.line == 0
    assert err.override == "--set sensor.widht_px=64"
    assert "widht_px" in str(err) and "did you mean `width_px`" in str(err)
    assert str(err) == cli_error("render", AIRFIELD, "-o", tmp_path / "x.exr", "--set", "sensor.widht_px=64")


def test_out_of_range_value(tmp_path):
    with pytest.raises(irsig.SceneError) as e:
        irsig.Scene.load(AIRFIELD, overrides={"site.latitude_deg": 123.0})
    assert e.value.file == str(AIRFIELD)
    assert "latitude_deg" in str(e.value)
    assert str(e.value) == cli_error("render", AIRFIELD, "-o", tmp_path / "x.exr", "--set", "site.latitude_deg=123.0")


def test_toml_syntax_error_in_a_scene_file(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(AIRFIELD.read_text().replace("[time]", "[time", 1))
    with pytest.raises(irsig.SceneError) as e:
        irsig.Scene.load(bad)
    assert e.value.file == str(bad) and e.value.line > 0
    assert str(e.value) == cli_error("check", bad)


def test_missing_file():
    with pytest.raises(irsig.SceneError) as e:
        irsig.Scene.load("no/such/scene.toml")
    assert e.value.file == "no/such/scene.toml"
    assert "cannot read" in str(e.value)


def test_bad_arguments():
    s = irsig.Scene.load(AIRFIELD, overrides=SMALL)
    with pytest.raises(irsig.IrsigError, match="time="):
        irsig.render(s, time="noon")
    with pytest.raises(irsig.IrsigError, match="tracer="):
        irsig.render(s, tracer="optix")
    with pytest.raises(irsig.IrsigError, match="threads"):
        irsig.render(s, threads=0)
    with pytest.raises(irsig.IrsigError, match="step"):
        irsig.sequence(s, start="09:00", stop="10:00", step="often")



def test_sweep_error_names_the_value(tmp_path):
    s = irsig.Scene.load(AIRFIELD, overrides=SMALL)
    with pytest.raises(irsig.SceneError) as e:
        irsig.sweep(s, "sensor.width_px", [32, -1])
    assert e.value.file == str(AIRFIELD)
    cli = cli_error("sweep", AIRFIELD, "--key", "sensor.width_px", "--values", "32,-1", "-o", tmp_path, *set_args(SMALL))
    assert str(e.value) == cli
    assert "sweep --key sensor.width_px = -1" in cli


def test_weather_error_names_the_weather_file_and_line(tmp_path):
    # A malformed record on line 11 of a copy of the airfield's TMY3 file.
    lines = (AIRFIELD.parent / "weather" / "greensboro-nc-tmy3-2001-08-04_09.csv").read_text().splitlines()
    lines[10] = lines[10].replace(",", ",x", 3)
    w = tmp_path / "w.csv"
    w.write_text("\n".join(lines) + "\n")
    # (files.allow: the copy lies outside the scene's folders, docs/reliability.md)
    over = {**SMALL, "files.allow": '["/"]', "weather.file.path": str(w)}
    with pytest.raises(irsig.WeatherError) as e:
        irsig.render(irsig.Scene.load(AIRFIELD, overrides=over))
    assert isinstance(e.value, irsig.IrsigError)
    assert (e.value.file, e.value.line) == (str(w), 11)
    assert str(e.value) == cli_error("render", AIRFIELD, "-o", tmp_path / "x.exr", *set_args(over))
    assert type(e.value).__module__ == "irsig" and type(e.value).__name__ == "WeatherError"


def test_weather_that_does_not_cover_the_history(tmp_path):
    s = irsig.Scene.load(AIRFIELD, overrides=SMALL)
    with pytest.raises(irsig.WeatherError, match="does not cover") as e:
        irsig.render(s, time="2001-09-01T12:00")
    assert e.value.file is None and e.value.line == 0
    over = {**SMALL, "time.local": "2001-09-01T12:00:00"}
    assert str(e.value) == cli_error("render", AIRFIELD, "-o", tmp_path / "x.exr", *set_args(over))


def test_file_error_keeps_its_line_under_overrides(tmp_path):
    # An override that inserts a key above the faulty line does not move it.
    bad = tmp_path / "bad.toml"
    bad.write_text(AIRFIELD.read_text().replace('band = "mwir"', 'band = "mwirr"', 1))
    with pytest.raises(irsig.SceneError) as plain:
        irsig.Scene.load(bad)
    with pytest.raises(irsig.SceneError) as edited:
        irsig.Scene.load(bad, overrides={"site.crs": "enu"})
    want = 1 + AIRFIELD.read_text().split("\n").index(
        next(l for l in AIRFIELD.read_text().split("\n") if l.startswith('band = "mwir"')))
    assert (plain.value.line, edited.value.line) == (want, want)
    assert edited.value.override is None and str(edited.value) == str(plain.value)


TERRAIN_KM = AIRFIELD.parents[1] / "terrain-km" / "scene.toml"


def test_overrides_reach_into_arrays_of_tables_by_index_and_name():
    """Issue 32: Python overrides reach into ``[[object]]`` entries as
    ``--set`` does, by name and by index, adding a key the entry does not
    write; an unknown name is refused naming the override, not a flag."""
    def vehicles(scene):
        return [o for o in scene.check()["object_list"] if o["name"].startswith("vehicle")]

    base = vehicles(irsig.Scene.load(TERRAIN_KM))
    by_name = vehicles(irsig.Scene.load(TERRAIN_KM, overrides={"object.vehicle.translate_m": [10, 0, 0]}))
    by_index = vehicles(irsig.Scene.load(TERRAIN_KM, overrides={"object[2].translate_m": [10, 0, 0]}))
    assert len(base) == 4
    for a, b, c in zip(base, by_name, by_index):
        assert b["bounds_min_m"] == c["bounds_min_m"]
        assert abs(b["bounds_min_m"][0] - a["bounds_min_m"][0] - 10.0) < 1e-3
    with pytest.raises(irsig.IrsigError) as e:
        irsig.Scene.load(TERRAIN_KM, overrides={"object.truck.translate_m": [0, 0, 0]})
    msg = str(e.value)
    assert "override `object.truck.translate_m`" in msg and "names: building, fuel_tank, vehicle" in msg
    assert "--set" not in msg, msg
