"""Clear-sky insolation on arrays, as `skysweep insolation --time` computes it
for a DEM at a given place (doc/insolation.md): ESRA beam, diffuse and
reflected irradiation on each cell's slope, cast shadows at every step."""
import math

import numpy as np

from ._context import ArgumentError
from ._lib import ffi, lib
from .products import SWEEP_OPTIONS, _begin, _doc_options, _params, _sweep, _value
from .sun import unix_seconds

_PARTS = ("global", "beam", "diffuse", "reflected", "sun_hours")
_LONG_NAMES = {"global": "global irradiation", "beam": "beam irradiation",
               "diffuse": "diffuse irradiation", "reflected": "reflected irradiation",
               "sun_hours": "hours of direct sun"}


def _as_text(value):
    """A sequence of numbers as the CLI's comma-separated text (--linke
    T,T,..., --surface TILT,AZIMUTH); text and None as they are."""
    if value is None or isinstance(value, str):
        return value
    return ",".join(repr(float(v)) for v in np.atleast_1d(value))


def _clear_sky_params(ctx, given):
    """The library's insolation parameters from keywords (--linke and
    --surface as their text, or as sequences of numbers), checked as the CLI
    checks them before it plans: the run's options (their shadow mode the
    plan's, set once it is made) and the Linke turbidity of each month."""
    given = dict(given, linke=_as_text(given.get("linke")),
                 surface=_as_text(given.get("surface")))
    params = _params("insolation", "insolation", given)
    options = ffi.new("ss_insolation_options *")
    ctx.check(lib.ss_insolation_params_options(ctx.ptr, params, lib.SS_SHADOW_EXACT, options))
    by_month = ffi.new("double[12]")
    ctx.check(lib.ss_insolation_params_linke(ctx.ptr, params, by_month))
    return params, options, by_month


def _steps(ctx, time, step):
    """The steps' middles (Unix seconds) and hours: `time` an ISO 8601 range
    as --time takes it (START/END, START/DURATION, with or without /STEP,
    `step` otherwise), or instants (any form sun_position takes), each
    standing for `step` (an ISO 8601 duration) around it."""
    if isinstance(time, str):
        text = time + ("/" + step if time.count("/") == 1 else "")
        r = ffi.new("ss_time_range *")
        ctx.check(lib.ss_parse_time_range(ctx.ptr, text.encode(), r))
        if r.count < 1:
            raise ArgumentError("--time must be a range (START/END or START/DURATION)", 2)
        mid, hours = ffi.new("double *"), ffi.new("double *")
        out = []
        for k in range(r.count):
            lib.ss_time_range_step(r, k, mid, hours)
            out.append((mid[0], hours[0]))
        return np.array([m for m, _ in out]), np.array([h for _, h in out])
    d = ffi.new("ss_duration *")
    ctx.check(lib.ss_parse_duration(ctx.ptr, step.encode(), d))
    if d.years or d.months or not d.seconds > 0:
        raise ArgumentError("with instants, step must be a fixed duration (PT1H, PT30M), not "
                            f"{step!r}", 2)
    mids = np.atleast_1d(unix_seconds(time)).astype(np.float64).ravel()
    return mids, np.full(mids.shape, d.seconds / 3600.0)


def insolation(dem, cell_size=None, *, time, latitude, longitude, step=None, linke=None,
               albedo=None, shadow=None, solar_constant=None, surface="cell", altitude=None,
               pressure=101325.0, temperature=None, delta_t=None, nodata=None, **kw):
    """Clear-sky irradiation of every cell (ESRA with Linke turbidity, as
    GRASS r.sun and the CLI's --time): a dict of arrays "global", "beam",
    "diffuse", "reflected" (Wh/m^2, summed over the steps) and "sun_hours"
    (hours of direct sun on the cell's surface).

    time: an ISO 8601 range as --time takes it ("2026-06-21T00:00Z/P1D", the
    step from `step` or its own /STEP; each step evaluated at its middle), or
    instants (datetime64, datetimes, pandas, Unix seconds), each standing for
    `step` around it. latitude, longitude: the grid's centre (degrees), where
    one sun serves the whole grid; altitude (metres) defaults to the DEM's
    datum height, as the CLI takes it. pressure in Pa and temperature in C
    refract the sun. linke: one turbidity or twelve (by the UTC month of a
    step's middle). surface: "cell" (each cell's own slope), "horizontal" or
    (tilt, azimuth). shadow: "auto" (the planner's choice), "exact" (a sweep
    at every daylight step) or "interpolated". Weather files and PV yield:
    insolation_file (--weather, --pv).
    """
    ctx, grid = _begin(dem, cell_size, nodata, kw, SWEEP_OPTIONS)
    params, options, linke = _clear_sky_params(
        ctx, {"step": step, "linke": linke, "albedo": albedo, "shadow": shadow,
              "solar_constant": solar_constant, "surface": surface})
    shadow = lib.ss_insolation_params_shadow(params)
    if shadow == lib.SS_SHADOW_CUMULATIVE:
        raise ArgumentError("--shadow cumulative bins the suns of weather records: use "
                            "insolation_file with --weather", 2)
    temperature = _value("insolation", "temperature", temperature)
    latitude, longitude = float(latitude), float(longitude)
    mids, hours = _steps(ctx, time, ffi.string(params.step).decode())
    steps = ffi.new("double[]", list(mids))
    opt, plan = _sweep(ctx, grid, "insolation", lib.SS_PRODUCT_INSOLATION, kw,
                       n_steps=len(mids), step_unix_s=steps, shadow_mode=shadow,
                       with_plan=True)
    p = ffi.new("ss_spa_params *")
    lib.ss_spa_params_default(p)
    p.delta_t_s = math.nan if delta_t is None else float(delta_t)
    p.pressure_hpa = float(pressure) / 100.0
    p.temperature_c = temperature
    p.elevation_m = grid.ptr.z_origin_m if altitude is None else float(altitude)
    sun = ffi.new("ss_spa_result *")
    civil = ffi.new("ss_civil_time *")

    @ffi.callback("ss_status(ss_ctx *, int, ss_sun_step *, void *)", error=lib.SS_ERR_INTERNAL)
    def sun_at(c, k, out, user):
        status = lib.ss_spa(c, float(mids[k]), latitude, longitude, p, sun)
        if status == 0:
            lib.ss_civil_from_unix(float(mids[k]), civil)  # Linke by the UTC month, as the CLI
            lib.ss_sun_step_clear_sky(sun, sun.azimuth_deg, opt.grid_north_deg, float(hours[k]),
                                      linke[civil.month - 1], params.solar_constant, out)
        return status

    options.shadow_mode = plan.shadow_mode  # as the CLI sets it once planned
    planes = {k: grid.new_plane() for k in _PARTS}
    out = ffi.new("ss_insolation_out *")
    buffers = {k: ffi.from_buffer("float[]", planes[k]) for k in _PARTS}
    for k in _PARTS:
        setattr(out, k, buffers[k])  # "global" is a Python keyword: no out.global
    ctx.call(lib.ss_insolation, grid.ptr, opt, options, len(mids), sun_at, ffi.NULL, ffi.NULL,
             ffi.NULL, out, progress=kw.get("progress"))
    units = {"global": "Wh m-2", "beam": "Wh m-2", "diffuse": "Wh m-2", "reflected": "Wh m-2",
             "sun_hours": "h"}
    shadow_used = ffi.string(lib.ss_shadow_mode_name(plan.shadow_mode)).decode()
    return {k: grid.finish(planes[k], k, {"long_name": _LONG_NAMES[k], "units": units[k],
                                          "shadow": shadow_used, "steps": len(mids)})
            for k in _PARTS}


_doc_options(insolation, "insolation", SWEEP_OPTIONS)
