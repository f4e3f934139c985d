"""irsig: a physics-based thermal-infrared synthetic image generator.

The Rust library does the work (``irsig._irsig``); this module turns its
results into xarray Datasets, pandas DataFrames and plain dicts. See
docs/python.md for the API.

    >>> import irsig
    >>> scene = irsig.Scene.load("scenes/airfield/scene.toml",
    ...                          overrides={"sensor.width_px": 64, "sensor.height_px": 48})
    >>> ds = irsig.render(scene)
    >>> ds.apparent_temperature.max().item()
"""

from __future__ import annotations

import datetime as _dt
import json as _json
import os as _os
from typing import Any, Callable, Iterable, Mapping, Optional, Sequence, Union

import numpy as _np
import xarray as _xr

from . import _irsig
from ._irsig import IrsigError, SceneError, WeatherError
from . import atmos

__all__ = [
    "IrsigError",
    "SceneError",
    "WeatherError",
    "Scene",
    "render",
    "sequence",
    "sweep",
    "probe",
    "therm",
    "sun",
    "atmos",
    "PLANES",
    "material_mask",
]

__version__ = _irsig.version()

#: Long names of the render's planes (docs/render.md).
PLANES = {
    "band_radiance": "at-aperture band-averaged radiance (before PSF, noise, quantisation)",
    "apparent_temperature": "blackbody temperature of the band radiance",
    "surface_temperature": "thermal-model surface temperature at the image time",
    "material": "material index of the facet at the pixel centre (-1 none)",
    "facet": "triangle index in the loaded scene (-1 none)",
    "sun_now": "share of the pixel's samples sunlit at the image time",
    "hours_sunlit": "sunlit hours of the shadow history",
    "range": "distance sensor to surface",
    "view_angle": "angle between line of sight and facet normal",
    "case": "the paper's radiometry equation used (1-4, 0 none)",
    "emitted": "emitted radiance term",
    "reflected_solar": "reflected direct solar radiance term",
    "reflected_sky": "reflected sky radiance term",
    "reflected_background": "reflected background radiance term",
    "path_thermal": "thermal path radiance term",
    "path_scattered": "scattered path radiance term",
    "sensor_radiance": "band radiance after PSF and detector noise",
    "dn": "quantised sensor radiance",
}

PathLike = Union[str, "_os.PathLike[str]"]
Time = Union[None, str, _dt.datetime]
Progress = Optional[Any]


def _value_text(v: Any) -> str:
    """A Python value as the text of a ``--set key=value`` override."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return v
    if isinstance(v, Mapping):
        return "{" + ",".join(f"{k}={_toml_value(x)}" for k, x in v.items()) + "}"
    if isinstance(v, (list, tuple)):
        return "[" + ",".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"override value {v!r}: expected a bool, number, str, dict or list")


def _toml_value(v: Any) -> str:
    if isinstance(v, str):
        return _json.dumps(v)
    return _value_text(v)


def _time_text(t: Time) -> Optional[str]:
    """None, or the text the extension parses (see ``render``)."""
    if t is None or isinstance(t, str):
        return t
    if isinstance(t, _dt.datetime):
        return t.isoformat()
    if isinstance(t, _dt.time):
        return t.isoformat()
    if isinstance(t, _np.datetime64):
        return str(t.astype("datetime64[s]"))
    raise TypeError(f"time={t!r}: expected None, a str or a datetime")


def _progress_fn(progress: Progress) -> Optional[Callable[[int, int], None]]:
    """A ``callable(done, total)``; a tqdm-like bar (``update`` and
    ``total``) is driven directly."""
    if progress is None:
        return None
    if hasattr(progress, "update") and hasattr(progress, "total"):
        bar = progress

        def drive(done: int, total: int) -> None:
            if bar.total != total:
                bar.total = total
                if hasattr(bar, "refresh"):
                    bar.refresh()
            bar.update(done - getattr(bar, "n", 0))

        return drive
    if callable(progress):
        return progress
    raise TypeError(f"progress={progress!r}: expected a callable(done, total) or a tqdm bar")


class Scene:
    """A loaded scene (``irsig check`` has validated it). Use
    :meth:`Scene.load`."""

    def __init__(self, inner: "_irsig.Scene"):
        self._inner = inner

    @classmethod
    def load(
        cls,
        path: PathLike,
        overrides: Optional[Mapping[str, Any]] = None,
        unset: Iterable[str] = (),
    ) -> "Scene":
        """Loads a scene file. ``overrides`` maps dotted scene keys to values,
        as the CLI's ``--set key=value`` (``{"sensor.band": "lwir",
        "sensor.width_px": 128}``); ``unset`` removes keys or tables first, as
        ``--unset``. Errors raise :class:`SceneError` with ``file``, ``line``
        and ``column`` (an error in an item an override set: ``line`` 0 and
        ``override``, e.g. ``"--set sensor.band=lwirr"``)."""
        ov = [(str(k), _value_text(v)) for k, v in (overrides or {}).items()]
        return cls(_irsig.Scene.load(_os.fspath(path), ov, [str(k) for k in unset]))

    def with_overrides(self, overrides: Mapping[str, Any]) -> "Scene":
        """The same scene file loaded with more overrides."""
        merged = dict(self._inner.overrides)
        merged.update({str(k): _value_text(v) for k, v in overrides.items()})
        return Scene(_irsig.Scene.load(_os.fspath(self.path), list(merged.items()), self._inner.unset))

    @property
    def path(self) -> str:
        return self._inner.path

    @property
    def overrides(self) -> dict:
        return dict(self._inner.overrides)

    @property
    def text(self) -> str:
        """The scene file's text with the overrides applied."""
        return self._inner.text

    @property
    def size(self) -> tuple:
        """(width, height) of the image in pixels."""
        return self._inner.size

    def check(self) -> dict:
        """What ``irsig check --json`` prints: objects, facets, materials,
        bounds, footprint, band, weather and what the render will need."""
        return _json.loads(self._inner.check_json())

    def __repr__(self) -> str:
        return repr(self._inner)


def _scene(scene: Union[Scene, PathLike]) -> Scene:
    return scene if isinstance(scene, Scene) else Scene.load(scene)


_FLAT_ATTRS = (
    "scene",
    "image_time_utc",
    "image_time_local",
    "utc_offset_h",
    "latitude_deg",
    "longitude_deg",
    "sun_zenith_deg",
    "sun_azimuth_deg",
    "band",
    "band_min_um",
    "band_max_um",
    "estimators",
)


def _utc64(text: str) -> _np.datetime64:
    t = _dt.datetime.fromisoformat(text).astimezone(_dt.timezone.utc).replace(tzinfo=None)
    return _np.datetime64(t, "ns")


def _variables(planes, frame_dims=()) -> dict:
    out = {}
    for name, unit, data in planes:
        out[name] = _xr.Variable(
            (*frame_dims, "y", "x"),
            data,
            {"units": unit, "long_name": PLANES.get(name, name)},
        )
    return out


def _xy_coords(height: int, width: int) -> dict:
    return {
        "y": ("y", _np.arange(height), {"long_name": "image row (0 at the top)"}),
        "x": ("x", _np.arange(width), {"long_name": "image column (0 at the left)"}),
    }


#: Mean Earth radius for the local tangent-plane lat/lon of hit points, m.
_EARTH_RADIUS_M = 6371008.8


def _point_coords(points, meta: dict, frame_dims=()) -> dict:
    """2-D coordinates of what each pixel's centre ray hits: ``east``,
    ``north``, ``up`` in the scene frame (m, the site at the origin) and
    ``lat``/``lon`` from the site's latitude and longitude (local
    tangent-plane approximation); NaN where the ray sees no surface."""
    dims = (*frame_dims, "y", "x")
    out = {}
    for name, data in points:
        out[name] = (dims, data, {"units": "m", "long_name": f"{name} coordinate of the surface point seen (scene frame)"})
    lat0, lon0 = meta.get("latitude_deg"), meta.get("longitude_deg")
    if lat0 is not None and lon0 is not None and "east" in out:
        east, north = out["east"][1].astype(_np.float64), out["north"][1].astype(_np.float64)
        lat = lat0 + _np.degrees(north / _EARTH_RADIUS_M)
        lon = lon0 + _np.degrees(east / (_EARTH_RADIUS_M * _np.cos(_np.radians(lat0))))
        note = "of the surface point seen (local tangent plane at the site)"
        out["lat"] = (dims, lat, {"units": "degrees_north", "long_name": f"latitude {note}"})
        out["lon"] = (dims, lon, {"units": "degrees_east", "long_name": f"longitude {note}"})
    return out


def _spatial_ref(meta: dict) -> dict:
    """The CF grid-mapping coordinate ``spatial_ref`` as rioxarray and
    GDAL read it: the output CRS's WKT (``crs_wkt``, ``spatial_ref``) and,
    for a nadir view, the image's affine transform (``GeoTransform``,
    GDAL's six coefficients: pixel corners to map x, y; rotated where the
    image is, e.g. by UTM grid convergence). ``x``/``y`` stay image column
    and row, so ``ds.rio.crs`` is the CRS and ``ds.rio.transform()`` the
    image's transform, and ``ds.rio.to_raster`` writes a georeferenced
    GeoTIFF. Empty without a CRS."""
    g = meta.get("georef") or {}
    crs = g.get("crs") or {}
    wkt = crs.get("wkt")
    if not wkt:
        return {}
    attrs = {"crs_wkt": wkt, "spatial_ref": wkt, "long_name": crs.get("name", "")}
    gt = g.get("geotransform")
    if gt:
        attrs["GeoTransform"] = " ".join(repr(float(v)) for v in gt)
    return {"spatial_ref": ((), _np.int64(0), attrs)}


def _grid_mapped(ds: _xr.Dataset) -> _xr.Dataset:
    """Points every image variable at ``spatial_ref`` (if there is one)."""
    if "spatial_ref" in ds.coords:
        for v in ds.data_vars.values():
            if "y" in v.dims and "x" in v.dims:
                v.attrs["grid_mapping"] = "spatial_ref"
    return ds


def _frame_attrs(meta: dict) -> dict:
    attrs = {k: meta[k] for k in _FLAT_ATTRS if k in meta}
    attrs["camera"] = _json.dumps(meta.get("camera"))
    atm = meta.get("atmosphere") or {}
    attrs["atmosphere"] = _json.dumps(atm)
    if isinstance(atm.get("air_temp_k"), (int, float)):
        attrs["air_temperature_k"] = atm["air_temp_k"]
    attrs["stats"] = _json.dumps(meta.get("stats"))
    attrs["irsig_version"] = __version__
    return attrs


def _name_materials(ds: _xr.Dataset, meta: dict) -> _xr.Dataset:
    """CF flag attributes on the ``material`` plane: its values index
    ``materials`` (the scene's material libraries, in order)."""
    names = meta.get("materials") or []
    if "material" in ds:
        ds["material"].attrs["flag_values"] = _np.arange(len(names), dtype=_np.float32)
        ds["material"].attrs["flag_meanings"] = " ".join(names)
    ds.attrs["materials"] = _json.dumps(names)
    return ds


def _dataset(frame: dict) -> _xr.Dataset:
    meta = _json.loads(frame["meta"])
    planes = frame["planes"]
    h, w = planes[0][2].shape
    coords = {**_xy_coords(h, w), **_point_coords(frame["points"], meta), **_spatial_ref(meta)}
    ds = _xr.Dataset(_variables(planes), coords=coords, attrs=_frame_attrs(meta))
    _name_materials(ds, meta)
    _grid_mapped(ds)
    ds.coords["time"] = ((), _utc64(meta["image_time_utc"]), {"long_name": "image time (UTC)"})
    return ds


def _stacked(frames: list, dim: str, coord, coord_attrs: dict) -> _xr.Dataset:
    """Frames of equal size stacked along ``dim``."""
    metas = [_json.loads(f["meta"]) for f in frames]
    names = [p[0] for p in frames[0]["planes"]]
    units = {p[0]: p[1] for p in frames[0]["planes"]}
    h, w = frames[0]["planes"][0][2].shape
    for f in frames:
        if [p[0] for p in f["planes"]] != names or f["planes"][0][2].shape != (h, w):
            raise IrsigError(f"frames differ in planes or size along {dim}; render them one by one")
    variables = {
        name: _xr.Variable(
            (dim, "y", "x"),
            _np.stack([f["planes"][i][2] for f in frames]),
            {"units": units[name], "long_name": PLANES.get(name, name)},
        )
        for i, name in enumerate(names)
    }
    coords = _xy_coords(h, w)
    coords[dim] = (dim, coord, coord_attrs)
    first = frames[0]["points"]
    same = all(
        all(_np.array_equal(a[1], b[1], equal_nan=True) for a, b in zip(first, f["points"])) for f in frames[1:]
    )
    if same:
        coords.update(_point_coords(first, metas[0]))
    else:
        stacked = [(name, _np.stack([f["points"][i][1] for f in frames])) for i, (name, _) in enumerate(first)]
        coords.update(_point_coords(stacked, metas[0], (dim,)))
    per_frame = {
        "sun_zenith_deg": ("deg", "solar zenith angle at the image time"),
        "sun_azimuth_deg": ("deg", "solar azimuth at the image time, clockwise from north"),
    }
    for k, (u, ln) in per_frame.items():
        variables[k] = _xr.Variable((dim,), _np.array([m[k] for m in metas]), {"units": u, "long_name": ln})
    # One grid mapping where every frame has the same CRS and transform.
    refs = [_spatial_ref(m) for m in metas]
    if refs[0] and all(r == refs[0] for r in refs[1:]):
        coords.update(refs[0])
    if dim != "time":
        coords["time"] = (dim, _np.array([_utc64(m["image_time_utc"]) for m in metas]), {"long_name": "image time (UTC)"})
    attrs = {k: v for k, v in _frame_attrs(metas[0]).items() if all(
        _frame_attrs(m).get(k) == v for m in metas[1:])}
    attrs["stats"] = _json.dumps([m.get("stats") for m in metas])
    attrs["image_time_local"] = _json.dumps([m["image_time_local"] for m in metas])
    attrs["atmosphere"] = _json.dumps([m.get("atmosphere") for m in metas])
    attrs.pop("air_temperature_k", None)
    return _grid_mapped(_name_materials(_xr.Dataset(variables, coords=coords, attrs=attrs), metas[0]))


def material_mask(ds: _xr.Dataset, name: str) -> _xr.DataArray:
    """Where the ``material`` plane of a rendered Dataset is material
    ``name`` (a boolean DataArray over the image)."""
    names = _json.loads(ds.attrs["materials"])
    if name not in names:
        raise KeyError(f"material {name!r} is not in the scene's libraries: {', '.join(names)}")
    return ds["material"] == names.index(name)


def render(
    scene: Union[Scene, PathLike],
    time: Time = None,
    threads: Optional[int] = None,
    tracer: Optional[str] = None,
    progress: Progress = None,
) -> _xr.Dataset:
    """Renders ``scene`` (as ``irsig render``) into an xarray Dataset: every
    plane a float32 variable over (y, x) with ``units`` and ``long_name``;
    the image time (UTC) as the ``time`` coordinate; sun angles, band
    limits, site, estimators, camera and run statistics as attributes.

    ``time``: None (the scene's ``[time]``), a local clock time on the scene's
    date (``"14:00"``), a local date-time of the site's clock
    (``"2001-08-08T14:00"`` or a naive ``datetime``) or an instant with an
    offset (``"2001-08-08T18:00Z"`` or an aware ``datetime``).
    ``threads``: worker threads (default: all cores; results do not depend
    on it). ``tracer``: ``"embree"`` or ``"bvh"`` (default: the scene's).
    ``progress``: ``callable(done, total)`` or a tqdm bar.

    The GIL is released while rendering; Ctrl-C stops the render and raises
    KeyboardInterrupt. The arrays are the render's own buffers (no copy).
    """
    sc = _scene(scene)
    frame = _irsig.render(sc._inner, _time_text(time), threads, tracer, _progress_fn(progress))
    return _dataset(frame)


def sequence(
    scene: Union[Scene, PathLike],
    times: Optional[Sequence[Time]] = None,
    *,
    start: Optional[str] = None,
    stop: Optional[str] = None,
    step: Optional[str] = None,
    threads: Optional[int] = None,
    tracer: Optional[str] = None,
    progress: Progress = None,
) -> _xr.Dataset:
    """A time sequence (as ``irsig sequence``): a Dataset with a ``time``
    dimension (UTC), one frame per time; the static work (geometry, BVH,
    tables) is done once. Give ``times`` (each as ``render``'s ``time``) or
    ``start``, ``stop`` and ``step`` (local clock times such as ``"08:00"``,
    ``"15:00"`` and a step such as ``"1h"``, ``"30min"``, as ``--from --to
    --step``). Sun angles and air temperature are variables over ``time``;
    ``image_time_local`` and ``stats`` are JSON lists in the attributes."""
    sc = _scene(scene)
    if times is None:
        if start is None or stop is None or step is None:
            raise TypeError("sequence: give times=[...] or start=, stop= and step=")
        texts = _irsig.sequence_times(sc._inner, start, stop, step)
    else:
        if start is not None or stop is not None or step is not None:
            raise TypeError("sequence: give times=[...] or start=, stop= and step=, not both")
        texts = [_time_text(t) for t in times]
        if not texts:
            raise ValueError("sequence: times is empty")
    frames = _irsig.sequence(sc._inner, texts, threads, tracer, _progress_fn(progress))
    utc = _np.array([_utc64(_json.loads(f["meta"])["image_time_utc"]) for f in frames])
    return _stacked(frames, "time", utc, {"long_name": "image time (UTC)"})


def sweep(
    scene: Union[Scene, PathLike],
    key: str,
    values: Sequence[Any],
    *,
    time: Time = None,
    threads: Optional[int] = None,
    tracer: Optional[str] = None,
    progress: Progress = None,
) -> _xr.Dataset:
    """A sweep over a scene key (as ``irsig sweep --key --values``): a
    Dataset with a dimension named ``key`` whose coordinate holds the
    values (numbers where all are numbers). Every value's scene is loaded
    (and checked) before any is rendered; geometry and atmosphere are
    reused where the key leaves them unchanged."""
    sc = _scene(scene)
    texts = [_value_text(v) for v in values]
    if not texts:
        raise ValueError("sweep: values is empty")
    frames = _irsig.sweep(sc._inner, key, texts, _time_text(time), threads, tracer, _progress_fn(progress))
    try:
        coord = _np.array([float(t) for t in texts])
    except ValueError:
        coord = _np.array(texts)
    return _stacked(frames, key, coord, {"long_name": f"scene key {key}"})


def probe(
    scene: Union[Scene, PathLike],
    x: int,
    y: int,
    *,
    time: Time = None,
    spectral: bool = False,
    threads: Optional[int] = None,
    tracer: Optional[str] = None,
) -> dict:
    """Everything about output pixel (``x``, ``y``) (column, row from the top
    left) at ``time`` (as ``render``'s), as ``irsig probe --json``: the hit,
    material, angles, sun/shadow history, thermal series and flux terms,
    every radiometric term (per spectral bin with ``spectral=True``) and
    ``pixel_result``, what ``render`` gives for the pixel."""
    sc = _scene(scene)
    return _json.loads(_irsig.probe(sc._inner, int(x), int(y), _time_text(time), spectral, threads, tracer))


def sun(
    lat: float,
    lon: float,
    time: Union[str, _dt.datetime],
    elevation: float = 0.0,
    *,
    pressure_hpa: Optional[float] = None,
    temp_c: Optional[float] = None,
    delta_t_s: Optional[float] = None,
) -> dict:
    """Solar position (NREL SPA), as ``irsig sun --json``: zenith (apparent
    and true), azimuth, elevation, Earth-Sun distance, the ENU unit vector
    and the options used. ``time``: RFC 3339 with an offset or a datetime (a
    naive one is taken as UTC); ``pressure_hpa``, ``temp_c``: refraction
    inputs (default 1013.25 hPa, 12 °C); ``delta_t_s``: TT - UT (default
    modelled)."""
    if isinstance(time, _dt.datetime):
        if time.tzinfo is None:
            time = time.replace(tzinfo=_dt.timezone.utc)
        time = time.isoformat()
    return _json.loads(
        _irsig.sun(float(lat), float(lon), str(time), float(elevation), pressure_hpa, temp_c, delta_t_s)
    )


def _utc_text(t: Union[str, _dt.datetime]) -> str:
    if isinstance(t, _dt.datetime):
        if t.tzinfo is None:
            t = t.replace(tzinfo=_dt.timezone.utc)
        return t.isoformat()
    return str(t)


#: The columns of ``irsig therm --csv``, in its order (after ``time_utc``).
_THERM_COLUMNS = [
    "t_s", "surface_temp_k", "air_temp_k", "sunlit", "absorbed_direct_w_m2", "absorbed_diffuse_w_m2",
    "absorbed_ground_reflected_w_m2", "sky_longwave_in_w_m2", "ground_longwave_in_w_m2",
    "emitted_longwave_w_m2", "convection_w_m2", "latent_w_m2", "rain_w_m2", "internal_w_m2",
    "net_surface_w_m2", "conduction_into_slab_w_m2", "back_w_m2", "convection_coeff_w_m2k",
    "water_store_mm", "sky_view", "sunlit_fraction", "surface_temp_c", "richardson", "stability_factor",
    "soil_surface_temp_k", "melt_w_m2",
]


def therm(
    materials: PathLike,
    material: str,
    *,
    lat: float,
    lon: float,
    start: Union[str, _dt.datetime],
    stop: Union[str, _dt.datetime],
    weather: Optional[PathLike] = None,
    forcing: Optional[PathLike] = None,
    typical_year: bool = False,
    elevation: float = 0.0,
    slope: float = 0.0,
    aspect: float = 180.0,
    step_min: float = 15.0,
    spin_up_h: float = 24.0,
    spin_up_start: str = "mean-forcing",
    convection: str = "surface-layer",
    wind_height_m: float = 10.0,
    air_height_m: float = 2.0,
    site_roughness_m: float = 0.03,
    facet_height_m: float = 0.0,
    shadow: Optional[str] = None,
    sky_view: Optional[float] = None,
):
    """Surface temperature and every flux term of one material and facet
    over time, as ``irsig therm`` (its flags are the keywords, with the
    same defaults): a ``pandas.DataFrame`` indexed by UTC time with the
    columns of ``irsig therm --csv`` (``t_s``, ``surface_temp_k``,
    ``air_temp_k``, ``sunlit``, the surface fluxes in W m-2, ...,
    ``surface_temp_c``). ``df.attrs`` holds the material's properties, the
    orientation, the thermal settings and the weather estimators used.
    ``start``/``stop``: RFC 3339 instants or datetimes (naive = UTC).
    ``sky_view``: the facet's sky view factor where the scene hides part of
    its sky (``irsig therm --sky-view``; ``None``: its open sky)."""
    import pandas as pd

    out = _json.loads(
        _irsig.therm(
            _os.fspath(materials), material, float(lat), float(lon), _utc_text(start), _utc_text(stop),
            None if weather is None else _os.fspath(weather), None if forcing is None else _os.fspath(forcing),
            typical_year, float(elevation), float(slope), float(aspect), float(step_min), float(spin_up_h),
            spin_up_start, convection, float(wind_height_m), float(air_height_m), float(site_roughness_m),
            float(facet_height_m), shadow, None if sky_view is None else float(sky_view),
        )
    )
    rows = [{**{k: v for k, v in r.items() if k != "surface"}, **r["surface"]} for r in out["rows"]]
    df = pd.DataFrame(rows)
    df = df.rename(columns={"net_w_m2": "net_surface_w_m2"})
    df["surface_temp_c"] = df["surface_temp_k"] - 273.15
    first = [c for c in _THERM_COLUMNS if c in df.columns]
    df = df[first + [c for c in df.columns if c not in first]]
    df.index = pd.DatetimeIndex(pd.to_datetime(df.pop("time_utc"), utc=True), name="time_utc")
    df.attrs = {k: out[k] for k in ("material", "properties", "orientation", "settings", "nodes", "deep_ground_k",
                                    "estimators")}
    return df
