"""The georeferenced outputs read as GIS and DIRSIG users read them:
rasterio (GDAL in its wheel) opens the GeoTIFF with its CRS, transform,
band names and units; pyproj's PROJ pipeline (ENU at the site -> WGS 84 ->
UTM, independent of irsig's conversion) places the footprint of
``irsig check`` on the GeoTIFF's corners within half a pixel; spectral's
``open_image`` reads the ENVI wavelengths, band names and class names;
OpenEXR's reader finds the ground planes, the grouped channels, the UINT
truth planes and the header's units, time, sun, band, version and CRS, and
the JSON's material table matches the classification."""

import json

import numpy as np
import pytest

from conftest import ROOT, read_exr, run_cli, set_args

PLATE = ROOT / "scenes" / "plate" / "scene.toml"
#: Straight down from 60 m, image top to the north-east (rotated), 40x24 px.
NADIR = {
    "sensor.width_px": 40,
    "sensor.height_px": 24,
    "sensor.pose": "{altitude={altitude_m=61.5,view_zenith_deg=0.0,azimuth_deg=225.0,target_m=[0.0,0.0,1.5]}}",
}


@pytest.fixture(scope="module")
def nadir(tmp_path_factory):
    d = tmp_path_factory.mktemp("georef")
    run_cli("render", PLATE, "-o", d / "n.tif", "--exr", "--envi", "-q", *set_args(NADIR))
    check = json.loads(run_cli("check", PLATE, "--json", *set_args(NADIR)).stdout)
    return d, check


def test_rasterio_reads_crs_transform_bands_and_units(nadir):
    rasterio = pytest.importorskip("rasterio")
    from pyproj import Transformer

    d, check = nadir
    with rasterio.open(d / "n.tif") as src:
        assert src.crs.to_epsg() == 32618
        assert src.count == len(json.loads((d / "n.json").read_text())["planes"])
        names = list(src.descriptions)
        units = list(src.units)
        assert units[names.index("apparent_temperature")] == "K"
        assert units[names.index("band_radiance")] == "W m-2 sr-1 um-1"
        assert units[names.index("ground_x")] == "m"
        t = src.transform
        w, h = src.width, src.height
        corners = [
            (t.c + t.a * c + t.b * r, t.f + t.d * c + t.e * r) for c, r in ((0, 0), (w, 0), (w, h), (0, h))
        ]
        temp = src.read(names.index("apparent_temperature") + 1)
        assert np.isfinite(temp).all() and 250 < temp.mean() < 360
    # The footprint (scene ENU at the site) through PROJ: topocentric ->
    # geocentric -> geodetic -> UTM 18N.
    site = check["site"]
    pipe = Transformer.from_pipeline(
        "+proj=pipeline +step +inv +proj=topocentric +ellps=WGS84 "
        f"+lat_0={site['latitude_deg']} +lon_0={site['longitude_deg']} +h_0={site['elevation_m']} "
        "+step +inv +proj=cart +ellps=WGS84 +step +proj=utm +zone=18 +ellps=WGS84"
    )
    gsd = check["centre_gsd_m"][0]
    for (x, y), (e, n, u) in zip(corners, check["footprint_m"]):
        ux, uy, _ = pipe.transform(e, n, u)
        err = np.hypot(x - ux, y - uy)
        assert err < 0.5 * gsd and err < 0.01, (x, y, ux, uy, err)


def test_geolocation_is_float64_lat_lon(nadir):
    rasterio = pytest.importorskip("rasterio")
    from pyproj import Transformer

    d, check = nadir
    with rasterio.open(d / "n_geo.tif") as g, rasterio.open(d / "n.tif") as m:
        assert g.dtypes[0] == "float64" and list(g.descriptions) == ["lat", "lon", "map_x", "map_y"]
        lat, lon, mx, my = g.read()
        names = list(m.descriptions)
        gx = m.read(names.index("ground_x") + 1).astype(np.float64)
        gy = m.read(names.index("ground_y") + 1).astype(np.float64)
        gz = m.read(names.index("ground_z") + 1).astype(np.float64)
    site = check["site"]
    inv = Transformer.from_pipeline(
        "+proj=pipeline +step +inv +proj=topocentric +ellps=WGS84 "
        f"+lat_0={site['latitude_deg']} +lon_0={site['longitude_deg']} +h_0={site['elevation_m']} "
        "+step +inv +proj=cart +ellps=WGS84 +step +proj=unitconvert +xy_in=rad +xy_out=deg"
    )
    plon, plat, _ = inv.transform(gx.ravel(), gy.ravel(), gz.ravel())
    ok = np.isfinite(gx.ravel())
    assert ok.sum() == gx.size
    # 1e-8 deg is ~1 mm.
    assert np.abs(plat - lat.ravel()).max() < 1e-8
    assert np.abs(plon - lon.ravel()).max() < 1e-8
    utm = Transformer.from_crs("EPSG:4326", "EPSG:32618", always_xy=True)
    ux, uy = utm.transform(plon, plat)
    assert np.abs(ux - mx.ravel()).max() < 1e-3 and np.abs(uy - my.ravel()).max() < 1e-3


def test_spectral_reads_envi_wavelengths_band_names_and_classes(nadir):
    spectral = pytest.importorskip("spectral")
    d, _ = nadir
    img = spectral.open_image(str(d / "n.hdr"))
    assert img.bands.band_unit == "Micrometers"
    assert all(abs(c - 11.0) < 1e-6 for c in img.bands.centers)
    assert all(abs(w - 6.0) < 1e-6 for w in img.bands.bandwidths)
    assert img.metadata["band names"][0] == "band_radiance [W m-2 sr-1 um-1]"
    assert img.metadata["acquisition time"] == "2001-08-08T17:00:00Z"
    cls = spectral.open_image(str(d / "n_class.hdr"))
    names = cls.metadata["class names"]
    assert names[0] == "no surface"
    table = json.loads((d / "n.json").read_text())["materials"]
    assert [m["name"] for m in table] == names[1:]
    classes = np.asarray(cls.load()).reshape(cls.nrows, cls.ncols).astype(int)
    exr = read_exr(d / "n.exr")
    # class = material index + 1 (0: no surface).
    assert (classes == np.where(exr["material"] >= 0, exr["material"] + 1, 0)).all()
    truth = spectral.open_image(str(d / "n_truth.hdr"))
    tn = truth.metadata["band names"]
    assert "lat [deg]" in tn and np.dtype(truth.dtype) == np.float64


def test_exr_has_ground_planes(nadir):
    d, check = nadir
    exr = read_exr(d / "n.exr")
    j = json.loads((d / "n.json").read_text())
    assert j["georef"]["ground_origin_m"] == [0.0, 0.0, 0.0]
    # The nadir view sees the ground plane (z 0) or the plate above it.
    gz = exr["ground_z"]
    assert np.isfinite(gz).all() and gz.min() > -0.01 and gz.max() < 6.0
    assert j["irsig"]["git_commit"] and j["image_time_utc"].endswith("Z")
    assert j["band"] == "lwir 8-14 um" and j["band_um"] == [8.0, 14.0]


def test_exr_layers_uint_planes_and_header(nadir):
    """OpenEXR's reader: channels grouped as layer.channel, integer truth
    planes as UINT, and the header states units, time, sun, band, version
    and the CRS with the same affine transform as the GeoTIFF."""
    import OpenEXR

    rasterio = pytest.importorskip("rasterio")
    d, _ = nadir
    j = json.loads((d / "n.json").read_text())
    with OpenEXR.File(str(d / "n.exr")) as f:
        h = dict(f.header())
        ch = {n: np.asarray(c.pixels) for n, c in f.channels().items()}
    layers = {n.split(".")[0] for n in ch}
    assert layers == {"radiance", "terms", "truth"}
    assert {"radiance.band_radiance", "radiance.apparent_temperature", "terms.emitted", "truth.range"} <= set(ch)
    for n in ("truth.material", "truth.facet", "truth.case"):
        assert ch[n].dtype == np.uint32, n
    assert ch["radiance.band_radiance"].dtype == np.float32
    # Every plane of the JSON is a channel, with the JSON's unit.
    for name, unit in j["planes"]:
        key = next(k for k in ch if k.endswith("." + name))
        assert h[f"irsig.units.{key}"] == unit
    # Material indices and the JSON's table agree; UINT_NONE marks no surface.
    mat = ch["truth.material"]
    valid = mat != 0xFFFFFFFF
    assert valid.any() and mat[valid].max() < len(j["materials"])
    assert h["irsig.image_time_utc"] == j["image_time_utc"]
    assert float(np.ravel(h["irsig.sun_zenith_deg"])[0]) == pytest.approx(j["sun_zenith_deg"], abs=1e-12)
    assert float(np.ravel(h["irsig.sun_azimuth_deg"])[0]) == pytest.approx(j["sun_azimuth_deg"], abs=1e-12)
    assert h["irsig.band"] == j["band"]
    assert [float(np.ravel(h[k])[0]) for k in ("irsig.band_lo_um", "irsig.band_hi_um")] == j["band_um"]
    assert j["irsig"]["git_commit"][:12] in h["irsig.version"] and h["software"].startswith("irsig ")
    assert h["irsig.crs_epsg"] == "EPSG:32618"
    with rasterio.open(d / "n.tif") as src:
        assert rasterio.crs.CRS.from_wkt(h["irsig.crs_wkt"]).to_epsg() == 32618
        g = [float(v) for v in h["irsig.geotransform"].split()]
        assert g == pytest.approx(list(src.transform.to_gdal()), abs=1e-6)


def test_map_grid_geotiff_has_crs_and_xy_equal_to_gdaltransform(nadir):
    """The rotated nadir view's north-up map grid (``n_map.tif``): rasterio
    reads a CRS and a north-up transform at the GSD; rioxarray builds x/y
    coordinates that equal gdaltransform's pixel centres to 1 cm; class
    planes take the image pixel under each cell (nearest); the bilinear
    ground planes put each ground-level cell where PROJ puts it, within the
    image's own scatter of sample points about pixel centres."""
    import shutil
    import subprocess

    rasterio = pytest.importorskip("rasterio")
    rioxarray = pytest.importorskip("rioxarray")
    from pyproj import Transformer

    d, check = nadir
    with rasterio.open(d / "n.tif") as src:
        t0 = src.transform
        assert t0.b != 0 and t0.d != 0, "the fixture's view is rotated"
    with rasterio.open(d / "n_map.tif") as m:
        assert m.crs.to_epsg() == 32618
        t = m.transform
        assert t.b == 0 and t.d == 0 and t.a > 0 and t.e == -t.a
        assert abs(t.a - min(np.hypot(t0.a, t0.d), np.hypot(t0.b, t0.e))) < 1e-9
        names = list(m.descriptions)
        assert names == list(rasterio.open(d / "n.tif").descriptions)
        gx = m.read(names.index("ground_x") + 1).astype(np.float64)
        gy = m.read(names.index("ground_y") + 1).astype(np.float64)
        gz = m.read(names.index("ground_z") + 1).astype(np.float64)
        mat = m.read(names.index("material") + 1)
    da = rioxarray.open_rasterio(d / "n_map.tif")
    assert da.rio.crs.to_epsg() == 32618
    xs, ys = da.x.values, da.y.values
    assert len(xs) == gx.shape[1] and len(ys) == gx.shape[0]
    # gdaltransform: pixel (col + 0.5, row + 0.5) -> map x, y.
    gdaltransform = shutil.which("gdaltransform")
    if gdaltransform is None:
        pytest.skip("gdaltransform (gdal-bin) is not installed")
    pts = [(c + 0.5, r + 0.5) for r in (0, len(ys) // 2, len(ys) - 1) for c in (0, len(xs) // 2, len(xs) - 1)]
    out = subprocess.run(
        [gdaltransform, str(d / "n_map.tif")],
        input="".join(f"{c} {r}\n" for c, r in pts),
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split("\n")
    for (c, r), line in zip(pts, out):
        x, y = map(float, line.split()[:2])
        assert abs(xs[int(c)] - x) < 0.01 and abs(ys[int(r)] - y) < 0.01, (c, r, x, y)
    # Each cell's centre through the inverse of the image's transform
    # (rasterio's affine algebra, independent of irsig's): the class plane
    # is the value of the image pixel it falls in (nearest), NaN off the
    # image.
    with rasterio.open(d / "n.tif") as src:
        onames = list(src.descriptions)
        omat = src.read(onames.index("material") + 1)
        ogx, ogy, ogz = (src.read(onames.index(n) + 1).astype(np.float64) for n in ("ground_x", "ground_y", "ground_z"))
    oh, ow = omat.shape
    X, Y = np.meshgrid(xs, ys)
    col, row = ~t0 * (X, Y)
    on = (col >= 0) & (row >= 0) & (col < ow) & (row < oh)
    assert (np.isnan(mat) == ~on).all()
    assert (mat[on] == omat[row[on].astype(int), col[on].astype(int)]).all()
    # The ground planes, bilinear: at a cell whose four neighbouring pixel
    # centres are on the image and at ground level, the resampled ground
    # point is a convex combination of theirs, so its distance from the
    # cell centre (the field is linear in map x, y on the flat ground) is at
    # most the largest distance of a ground pixel's point from its pixel
    # centre (the samples' positions within their pixels).
    site = check["site"]
    pipe = Transformer.from_pipeline(
        "+proj=pipeline +step +inv +proj=topocentric +ellps=WGS84 "
        f"+lat_0={site['latitude_deg']} +lon_0={site['longitude_deg']} +h_0={site['elevation_m']} "
        "+step +inv +proj=cart +ellps=WGS84 +step +proj=utm +zone=18 +ellps=WGS84"
    )
    og = np.abs(ogz) < 1e-3
    oc, orr = np.meshgrid(np.arange(ow) + 0.5, np.arange(oh) + 0.5)
    ox, oy = t0 * (oc, orr)
    px, py, _ = pipe.transform(ogx[og], ogy[og], ogz[og])
    jitter = np.hypot(px - ox[og], py - oy[og]).max()
    u, v = col - 0.5, row - 0.5
    c0, r0 = np.floor(u).astype(int), np.floor(v).astype(int)
    inner = (u >= 0) & (v >= 0) & (c0 + 1 < ow) & (r0 + 1 < oh)
    for dc in (0, 1):
        for dr in (0, 1):
            inner &= og[np.clip(r0 + dr, 0, oh - 1), np.clip(c0 + dc, 0, ow - 1)]
    assert inner.sum() > 100
    ux, uy, _ = pipe.transform(gx[inner], gy[inner], gz[inner])
    err = np.hypot(ux - X[inner], uy - Y[inner])
    assert err.max() <= jitter + 1e-3, (err.max(), jitter)


#: The same plate seen at 40 deg from nadir: a perspective image, no affine
#: transform.
OBLIQUE = {
    **NADIR,
    "sensor.pose": "{altitude={altitude_m=61.5,view_zenith_deg=40.0,azimuth_deg=225.0,target_m=[0.0,0.0,1.5]}}",
}


def test_oblique_geotiff_geolocation_arrays_read_by_gdal(tmp_path):
    """An oblique view's GeoTIFF keeps its GCPs (with their CRS) and
    carries GDAL's GEOLOCATION metadata pointing at ``o_geo.tif``'s map_x
    and map_y bands (named relative to the file; Debian 12's GDAL 3.6
    opens that name from the working directory): ``gdaltransform -geoloc``
    takes pixel centres to the map coordinates of ``o_geo.tif`` within
    1 cm, pixels that see sky (NaN) included in the arrays."""
    import shutil
    import subprocess

    rasterio = pytest.importorskip("rasterio")
    run_cli("render", PLATE, "-o", tmp_path / "o.tif", "-q", *set_args(OBLIQUE))
    assert not (tmp_path / "o_map.tif").exists()
    with rasterio.open(tmp_path / "o.tif") as src:
        gcps, gcp_crs = src.gcps
        assert len(gcps) > 10 and gcp_crs.to_epsg() == 32618
        tags = src.tags(ns="GEOLOCATION")
        h, w = src.height, src.width
    assert tags["X_DATASET"] == "o_geo.tif" and tags["Y_DATASET"] == "o_geo.tif"
    assert (tags["X_BAND"], tags["Y_BAND"]) == ("3", "4")
    assert tags["GEOREFERENCING_CONVENTION"] == "PIXEL_CENTER"
    assert rasterio.crs.CRS.from_wkt(tags["SRS"]).to_epsg() == 32618
    with rasterio.open(tmp_path / "o_geo.tif") as g:
        assert list(g.descriptions)[2:] == ["map_x", "map_y"]
        mx, my = g.read(3), g.read(4)
    # The view sees sky above the horizon (NaN: no hit) and ground below.
    ok = np.isfinite(mx)
    assert ok.any() and not ok.all()
    gdaltransform = shutil.which("gdaltransform")
    if gdaltransform is None:
        pytest.skip("gdaltransform (gdal-bin) is not installed")
    # Every pixel whose 3x3 neighbourhood sees ground (GDAL interpolates
    # between array values, so a NaN neighbour makes NaN).
    inner = ok.copy()
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            inner &= np.roll(np.roll(ok, dr, axis=0), dc, axis=1)
    inner[[0, -1], :] = False
    inner[:, [0, -1]] = False
    pts = [(int(c), int(r)) for r, c in zip(*np.nonzero(inner))]
    assert len(pts) > 100
    out = subprocess.run(
        [gdaltransform, "-geoloc", str(tmp_path / "o.tif")],
        input="".join(f"{c + 0.5} {r + 0.5}\n" for c, r in pts),
        capture_output=True,
        text=True,
        check=True,
        cwd=tmp_path,
    ).stdout.split("\n")
    for (c, r), line in zip(pts, out):
        x, y = map(float, line.split()[:2])
        assert abs(mx[r, c] - x) < 0.01 and abs(my[r, c] - y) < 0.01, (c, r, x, y, mx[r, c], my[r, c])


def test_map_grid_off(tmp_path):
    run_cli("render", PLATE, "-o", tmp_path / "n.tif", "-q", "--map-grid", "off", *set_args(NADIR))
    assert (tmp_path / "n.tif").exists() and not (tmp_path / "n_map.tif").exists()
    j = json.loads((tmp_path / "n.json").read_text())
    assert "n_map.tif" not in j["files"]


def test_dataset_has_rio_crs_and_transform(nadir, tmp_path):
    """A rendered Dataset carries the CF grid mapping ``spatial_ref``:
    rioxarray reads the CLI GeoTIFF's CRS and (nadir) affine transform
    from it, and ``rio.to_raster`` writes a GeoTIFF that rasterio places
    where the CLI's is; an oblique view gets the CRS and no transform."""
    rasterio = pytest.importorskip("rasterio")
    pytest.importorskip("rioxarray")
    import irsig

    d, _ = nadir
    ds = irsig.render(irsig.Scene.load(PLATE, overrides=NADIR), threads=2)
    assert ds.rio.crs.to_epsg() == 32618
    assert ds["apparent_temperature"].attrs["grid_mapping"] == "spatial_ref"
    with rasterio.open(d / "n.tif") as src:
        want = src.transform
    got = ds.rio.transform()
    assert np.allclose(list(got)[:6], list(want)[:6], rtol=0, atol=1e-6), (got, want)
    ds["apparent_temperature"].rio.to_raster(tmp_path / "t.tif")
    with rasterio.open(tmp_path / "t.tif") as out:
        assert out.crs.to_epsg() == 32618
        assert np.allclose(list(out.transform)[:6], list(want)[:6], rtol=0, atol=1e-6)
        assert np.array_equal(out.read(1), ds["apparent_temperature"].values, equal_nan=True)
    ob = irsig.render(irsig.Scene.load(PLATE, overrides=OBLIQUE), threads=2)
    assert ob.rio.crs.to_epsg() == 32618
    assert "GeoTransform" not in ob["spatial_ref"].attrs
