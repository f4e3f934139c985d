"""The atmosphere tables (``irsig atmos``): what a geometry uses."""

from __future__ import annotations

import json as _json
import os as _os
from typing import Optional, Union

import numpy as _np
import xarray as _xr

from . import _irsig

__all__ = ["list", "show"]

_TERMS = {
    "weight": ("1", "band weight of the bin (the weights sum to 1)"),
    "tau2": ("1", "target to sensor transmission"),
    "l_ue": ("W m-2 sr-1 um-1", "path thermal radiance"),
    "l_us": ("W m-2 sr-1 um-1", "path scattered radiance"),
    "l_de": ("W m-2 sr-1 um-1", "sky thermal radiance toward the sky zenith"),
    "l_ds": ("W m-2 sr-1 um-1", "sky scattered radiance toward the sky zenith"),
    "l_de_dome": ("W m-2 sr-1 um-1", "sky thermal radiance averaged over the dome"),
    "l_ds_dome": ("W m-2 sr-1 um-1", "sky scattered radiance averaged over the dome"),
    "tau1": ("1", "sun to ground transmission"),
    "e_sun_exo": ("W m-2 um-1", "exo-atmospheric solar irradiance"),
    "e_sun_ground": ("W m-2 um-1", "solar irradiance at the ground (tau1 E_S)"),
}


def list() -> "builtins.list[dict]":  # noqa: A001 (mirrors `irsig atmos list`)
    """The shipped atmosphere tables, as ``irsig atmos list``: dicts with
    ``name``, ``source`` (a file, or "embedded in the irsig binary") and
    ``description``."""
    return [{"name": n, "source": s, "description": d} for n, s, d in _irsig.atmos_list()]


def show(
    name: Union[str, "_os.PathLike[str]"],
    altitude_km: float,
    zenith_deg: float,
    *,
    sky_zenith_deg: Optional[float] = None,
    sun_zenith_deg: float = 45.0,
    rel_azimuth_deg: float = 90.0,
    band: str = "8-14",
) -> _xr.Dataset:
    """What atmosphere ``name`` (a shipped table or a table file) gives for a
    sensor ``altitude_km`` above the target at view zenith ``zenith_deg``,
    as ``irsig atmos show``: an xarray Dataset over the band's bins
    (``wavenumber`` in cm-1, ``wavelength`` in µm as a coordinate) with the
    transmissions and radiances; the band-integrated values, geometry and
    source are attributes (``band_integrated`` a dict of label -> value)."""
    v = _json.loads(
        _irsig.atmos_show(
            _os.fspath(name), float(altitude_km), float(zenith_deg), sky_zenith_deg,
            float(sun_zenith_deg), float(rel_azimuth_deg), str(band),
        )
    )
    wn = _np.asarray(v["wavenumber_cm1"])
    data = {k: ("wavenumber", _np.asarray(v[k]), {"units": u, "long_name": ln}) for k, (u, ln) in _TERMS.items()}
    ds = _xr.Dataset(
        data,
        coords={
            "wavenumber": ("wavenumber", wn, {"units": "cm-1"}),
            "wavelength": ("wavenumber", 1e4 / wn, {"units": "um"}),
        },
        attrs={
            "name": v["name"],
            "description": v["description"],
            "source": str(v["source"]),
            "band": v["band"],
            "grid_bins": v["grid_bins"],
            **{f"{k}": x for k, x in v["geometry"].items()},
        },
    )
    ds.attrs["band_integrated"] = {label: value for label, value in v["band_integrated"]}
    return ds


import builtins  # noqa: E402  (for the annotation of `list`, shadowed above)
