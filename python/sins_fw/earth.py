"""Earth model used by the synthetic scenarios (documented in docs/traces.md).

Navigation frame: local level ENU (x east, y north, z up). Earth rate and radii of curvature are the
reference design's (ω_ie = 7.292115e-5 rad/s, R_e = 6378137 m, e = 1/298.257, R_N = R_e(1 − 2e +
3e sin²φ), R_E = R_e(1 + e sin²φ)); gravity is the WGS-84 normal gravity (Somigliana closed form with
the second-order free-air correction), which already contains the centrifugal part of earth rotation.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sins_fw.errors import InputError

Array = NDArray[np.float64]

#: Standard gravity, the unit "g" of traces (m/s²).
G0 = 9.80665
#: Earth rotation rate (rad/s), the reference design's value.
OMEGA_IE = 7.292115e-5
#: Equatorial radius (m) and the flattening the reference design's radii use.
R_EQUATOR = 6378137.0
FLATTENING_FIRMWARE = 1.0 / 298.257

# WGS-84 normal gravity (NIMA TR8350.2, eq. 4-1 and 4-3).
_GAMMA_E = 9.7803253359
_SOMIGLIANA_K = 0.00193185265241
_E2 = 0.00669437999013
_F_WGS84 = 1.0 / 298.257223563
_M_WGS84 = 0.00344978650684


def normal_gravity(lat_rad: ArrayLike, height_m: ArrayLike = 0.0) -> Array:
    """Magnitude of WGS-84 normal gravity (m/s²) at geodetic latitude and ellipsoidal height."""
    s2 = np.sin(np.asarray(lat_rad, dtype=np.float64)) ** 2
    h = np.asarray(height_m, dtype=np.float64)
    gamma = _GAMMA_E * (1.0 + _SOMIGLIANA_K * s2) / np.sqrt(1.0 - _E2 * s2)
    free_air = 1.0 - 2.0 / R_EQUATOR * (1.0 + _F_WGS84 + _M_WGS84 - 2.0 * _F_WGS84 * s2) * h
    return gamma * (free_air + 3.0 * h * h / R_EQUATOR**2)


def earth_rate_n(lat_rad: ArrayLike) -> Array:
    """ω_ie^n = [0, ω_ie cos φ, ω_ie sin φ] in ENU (rad/s), shape ``(..., 3)``."""
    lat = np.asarray(lat_rad, dtype=np.float64)
    return np.stack([np.zeros_like(lat), OMEGA_IE * np.cos(lat), OMEGA_IE * np.sin(lat)], axis=-1)


def radii(lat_rad: ArrayLike) -> tuple[Array, Array]:
    """(R_N, R_E): meridian and prime-vertical radii of curvature (m), the reference design's formulas."""
    s2 = np.sin(np.asarray(lat_rad, dtype=np.float64)) ** 2
    e = FLATTENING_FIRMWARE
    return R_EQUATOR * (1.0 - 2.0 * e + 3.0 * e * s2), R_EQUATOR * (1.0 + e * s2)


def earth_rate_place(profile: Any, trace_metadata: Mapping[str, str]) -> dict[str, Any]:
    """Where the firmware's earth-rate compensation takes the board to be, for a run's summary: the
    profile's ``navigation.latitude_deg`` (the firmware knows no other), whether the trace says where
    it was recorded (``latitude_deg`` in its metadata), and, when it does not, a note saying which
    latitude was assumed and the keys that change it or switch the compensation off. Without the
    compensation (``firmware.earth_rate = false``) the latitude does not matter: no note."""
    try:
        on = bool(profile.get("firmware.earth_rate"))
        latitude = float(profile.get("navigation.latitude_deg"))
    except InputError:  # a firmware without these keys: nothing to say
        return {"compensated": None, "latitude_deg": None, "trace_latitude_deg": None, "note": None}
    given = trace_metadata.get("latitude_deg")
    note = None
    if on and given is None:
        note = (
            f"latitude {latitude:g}° assumed (the profile's navigation.latitude_deg): the trace gives no "
            "`latitude_deg`; set yours with --set navigation.latitude_deg=DEG, or switch the compensation "
            "off with --set firmware.earth_rate=false"
        )
    return {"compensated": on, "latitude_deg": latitude, "trace_latitude_deg": given, "note": note}
