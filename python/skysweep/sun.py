"""The sun's position (NREL SPA, or PSA) for a place and instants, with
pvlib's names and units (pvlib.solarposition.spa_python)."""
import datetime as _dt

import numpy as np

from ._context import context
from ._lib import ffi, lib


def unix_seconds(time):
    """UTC Unix seconds (float64 array) from instants: numpy datetime64 (UTC:
    numpy's datetimes have no zone), aware datetime objects, a pandas
    DatetimeIndex or Timestamp with a zone (converted to UTC), or numbers
    (Unix seconds). A datetime or pandas time without a zone is refused, as
    the command line's --time refuses one: which zone it meant is unknown."""
    if _is_pandas_time(time):  # pandas DatetimeIndex, Timestamp
        if time.tz is None:
            raise _naive(time)
        time = time.tz_convert("UTC").tz_localize(None)
        if not hasattr(time, "shape"):  # a Timestamp
            time = [time.to_datetime64()]
        return _datetime64_seconds(np.asarray(time))
    items = np.atleast_1d(np.asarray(time, dtype=object if _has_aware(time) else None))
    if items.dtype == object:
        return np.array([_datetime_seconds(t) for t in items.ravel()]).reshape(items.shape)
    if np.issubdtype(items.dtype, np.datetime64):
        return _datetime64_seconds(items)
    if items.dtype.kind in "iuf":
        return items.astype(np.float64)
    raise TypeError(f"cannot read instants from {type(time).__name__} of dtype {items.dtype}")


def _datetime64_seconds(items):
    """Seconds of datetime64 values in their own unit (nanoseconds wrap
    outside 1678..2262; SPA spans -2000..6000); NaT gives NaN."""
    seconds = (items - np.datetime64(0, "s")) / np.timedelta64(1, "s")
    return np.where(np.isnat(items), np.nan, seconds).astype(np.float64)


def _has_aware(time):
    values = time if isinstance(time, (list, tuple)) else [time]
    return any(isinstance(t, _dt.datetime) for t in values)


def _naive(t):
    return ValueError(f"the time {t} has no time zone: give an aware one (tzinfo="
                      "datetime.timezone.utc, tz_localize('UTC')) or numpy datetime64 (UTC)")


def _datetime_seconds(t):
    if isinstance(t, _dt.datetime):
        if t.tzinfo is None or t.utcoffset() is None:
            raise _naive(t)
        return t.timestamp()
    if isinstance(t, np.datetime64):
        return float(_datetime64_seconds(np.asarray(t)))
    return float(t)


def iso_duration(value, name="step"):
    """An ISO 8601 duration's text, as --step takes it, from ISO 8601 text
    ("PT1H", kept as it is), a datetime.timedelta (pandas.Timedelta is one),
    a numpy timedelta64, or a pandas frequency string ("1h", "15min")."""
    if isinstance(value, str):
        if value[:1].upper() == "P":
            return value
        value = _frequency(value, name)
    if isinstance(value, np.timedelta64):
        seconds = value / np.timedelta64(1, "s")
    elif isinstance(value, _dt.timedelta):
        seconds = value.total_seconds()
    else:
        raise TypeError(f"{name} must be a duration (ISO 8601 such as 'PT1H', a timedelta, or a "
                        f"pandas frequency such as '15min'), not {value!r}")
    if not (np.isfinite(seconds) and seconds > 0):
        raise ValueError(f"{name} must be a positive duration, not {value!r}")
    return f"PT{seconds:.17g}S"


def _frequency(text, name):
    """A pandas frequency string as a Timedelta: a fixed one ("1h", "15min");
    a calendar one ("MS") has no fixed length."""
    try:
        import pandas as pd
    except ImportError:
        raise ValueError(f"{name} {text!r} is not ISO 8601 ('PT1H'), and pandas, which reads "
                         "frequency strings, is not installed") from None
    try:
        return pd.Timedelta(pd.tseries.frequencies.to_offset(text))
    except (ValueError, TypeError):
        raise ValueError(f"{name} {text!r} is neither ISO 8601 ('PT1H') nor a fixed pandas "
                         "frequency ('1h', '15min')") from None


#: The columns of pvlib.solarposition.get_solarposition (method "nrel_numpy"), in its order.
COLUMNS = ("apparent_zenith", "zenith", "apparent_elevation", "elevation", "azimuth",
           "equation_of_time")


def sun_position(time, latitude, longitude, altitude=0.0, pressure=101325.0, temperature=12.0,
                 delta_t=None, atmos_refract=0.5667, algorithm="spa"):
    """Sun position at `time` for an observer at a place, with pvlib's names and units.

    Parameters
    ----------
    time : pandas.DatetimeIndex, pandas.Timestamp, datetime64, datetime or float
        Instants: pandas times and datetimes with a time zone (any), numpy datetime64
        (UTC), or Unix seconds; arrays of them. NaT gives NaN.
    latitude, longitude : float
        Degrees, north and east positive.
    altitude : float, default 0.0
        Metres above sea level.
    pressure : float, default 101325.0
        Pa, for refraction.
    temperature : float, default 12.0
        Degrees C, for refraction.
    delta_t : float, default None
        TT - UT1 in seconds; None takes the Espenak-Meeus model for the month
        (pvlib's default is a fixed 67 s).
    atmos_refract : float, default 0.5667
        Degrees of refraction at the horizon, as pvlib's.
    algorithm : {"spa", "psa"}, default "spa"
        NREL SPA (Reda & Andreas, +-0.0003 deg) or PSA (Blanco et al. 2020, about
        0.01 deg).

    Returns
    -------
    pandas.DataFrame or dict of numpy.ndarray
        For pandas times: a DataFrame indexed by them, with the columns of
        pvlib.solarposition.get_solarposition: apparent_zenith, zenith,
        apparent_elevation, elevation, azimuth (degrees clockwise from north),
        equation_of_time (minutes). For other times: a dict of arrays shaped like
        `time`, with the same keys.

    Raises
    ------
    ValueError
        A datetime or pandas time without a time zone, or an unknown algorithm.
    TypeError
        Times of a type that holds no instants.
    SkysweepError
        The library's refusal of a place or an instant (ArgumentError).
    """
    seconds = unix_seconds(time)
    ctx = context()
    p = ffi.new("ss_spa_params *")
    lib.ss_spa_params_default(p)
    if algorithm not in ("spa", "psa"):
        raise ValueError(f"algorithm must be 'spa' or 'psa', not {algorithm!r}")
    p.algorithm = lib.SS_SUN_SPA if algorithm == "spa" else lib.SS_SUN_PSA
    p.delta_t_s = float("nan") if delta_t is None else float(delta_t)
    p.pressure_hpa = float(pressure) / 100.0
    p.temperature_c = float(temperature)
    p.atmos_refract_deg = float(atmos_refract)
    p.elevation_m = float(altitude)
    out = {k: np.empty(seconds.shape) for k in COLUMNS}
    r = ffi.new("ss_spa_result *")
    for i, s in np.ndenumerate(seconds):
        if np.isnan(s):  # NaT: no instant, no sun
            for k in COLUMNS:
                out[k][i] = np.nan
            continue
        ctx.check(lib.ss_spa(ctx.ptr, float(s), float(latitude), float(longitude), p, r))
        out["apparent_zenith"][i] = r.zenith_deg
        out["zenith"][i] = 90.0 - r.elevation_deg
        out["apparent_elevation"][i] = r.apparent_elevation_deg
        out["elevation"][i] = r.elevation_deg
        out["azimuth"][i] = r.azimuth_deg
        out["equation_of_time"][i] = r.equation_of_time_min
    if _is_pandas_time(time):
        import pandas as pd
        index = time if isinstance(time, pd.DatetimeIndex) else pd.DatetimeIndex([time])
        return pd.DataFrame({k: out[k].ravel() for k in COLUMNS}, index=index)
    return out


def _is_pandas_time(time):
    return hasattr(time, "tz") and hasattr(time, "tz_convert")
