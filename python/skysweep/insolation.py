"""Clear-sky insolation on arrays, as `skysweep insolation --time` computes it
for a DEM at a given place (doc/insolation.md): ESRA beam, diffuse and
reflected irradiation on each cell's slope, cast shadows at every step."""
import math

import numpy as np

from ._context import ArgumentError
from ._lib import ffi, lib
from .products import SWEEP_OPTIONS, _begin, _checked, _doc_options, _sweep, _value
from .sun import unix_seconds

_SHADOW = {"auto": lib.SS_SHADOW_AUTO, "exact": lib.SS_SHADOW_EXACT,
           "interpolated": lib.SS_SHADOW_INTERPOLATED, "cumulative": lib.SS_SHADOW_CUMULATIVE}
_PARTS = ("global", "beam", "diffuse", "reflected", "sun_hours")


def _linke_by_month(linke):
    values = [float(v) for v in str(linke).split(",")] if isinstance(linke, str) else \
        [float(v) for v in np.atleast_1d(linke)]
    if len(values) not in (1, 12) or not all(0.5 <= v <= 10 for v in values):
        raise ArgumentError(f"--linke expects one turbidity or twelve (January..December), "
                            f"each 0.5 to 10, not {linke!r}", 2)
    return values * 12 if len(values) == 1 else values


def _surface(surface):
    out = ffi.new("ss_surface *")
    if surface in (None, "cell"):
        out.kind = lib.SS_SURFACE_CELL
    elif surface == "horizontal":
        out.kind = lib.SS_SURFACE_HORIZONTAL
    else:
        try:
            tilt, azimuth = (float(v) for v in (surface.split(",") if isinstance(surface, str)
                                                else surface))
        except (TypeError, ValueError):
            raise ArgumentError("--surface expects cell, horizontal or TILT,AZIMUTH, not "
                                f"{surface!r}", 2) from None
        if not (0 <= tilt <= 90 and -360 <= azimuth <= 360):
            raise ArgumentError(f"--surface expects tilt 0 to 90 and azimuth -360 to 360, not "
                                f"{surface!r}", 2)
        out.kind, out.tilt_deg, out.azimuth_deg = lib.SS_SURFACE_FIXED, tilt, azimuth
    return out


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
    step = _value("insolation", "step", step)
    linke = _linke_by_month(_value("insolation", "linke", linke))
    albedo = _value("insolation", "albedo", albedo)
    shadow = _value("insolation", "shadow", shadow)
    if shadow == "cumulative":
        raise ArgumentError("--shadow cumulative bins the suns of weather records: use "
                            "insolation_file with --weather", 2)
    solar_constant = _value("insolation", "solar_constant", solar_constant)
    temperature = _value("insolation", "temperature", temperature)
    latitude, longitude = float(latitude), float(longitude)
    mids, hours = _steps(ctx, time, step)
    steps = ffi.new("double[]", list(mids))
    opt, plan = _sweep(ctx, grid, "insolation", lib.SS_PRODUCT_INSOLATION, kw,
                       n_steps=len(mids), step_unix_s=steps, shadow_mode=_SHADOW[shadow],
                       with_plan=True)
    p = ffi.new("ss_spa_params *")
    lib.ss_spa_params_default(p)
    p.delta_t_s = math.nan if delta_t is None else float(delta_t)
    p.pressure_hpa = float(pressure) / 100.0
    p.temperature_c = temperature
    p.elevation_m = grid.ptr.z_origin_m if altitude is None else float(altitude)
    # Linke by the UTC month of a step's middle (proleptic Gregorian: the CLI
    # counts Julian months before 1582).
    months = np.floor(mids).astype(np.int64).astype("datetime64[s]").astype(
        "datetime64[M]").astype(np.int64) % 12
    sun = ffi.new("ss_spa_result *")

    @ffi.callback("ss_status(ss_ctx *, int, ss_sun_step *, void *)", error=lib.SS_ERR_INTERNAL)
    def sun_at(c, k, out, user):
        status = lib.ss_spa(c, float(mids[k]), latitude, longitude, p, sun)
        if status == 0:
            lib.ss_sun_step_clear_sky(sun, sun.azimuth_deg, opt.grid_north_deg, float(hours[k]),
                                      linke[months[k]], solar_constant, out)
        return status

    options = ffi.new("ss_insolation_options *")
    options.albedo = albedo
    options.shadow_mode = plan.shadow_mode
    options.surface = _surface(surface)[0]
    planes = {k: grid.new_plane() for k in _PARTS}
    out = ffi.new("ss_insolation_out *")
    buffers = {k: ffi.from_buffer("float[]", planes[k]) for k in _PARTS}
    for k in _PARTS:
        setattr(out, k, buffers[k])  # "global" is a Python keyword: no out.global
    ctx.call(lib.ss_insolation, grid.ptr, opt, options, len(mids), sun_at, ffi.NULL, ffi.NULL,
             ffi.NULL, out, progress=kw.get("progress"))
    units = {"global": "Wh/m2", "beam": "Wh/m2", "diffuse": "Wh/m2", "reflected": "Wh/m2",
             "sun_hours": "h"}
    shadow_used = {v: k for k, v in _SHADOW.items()}[plan.shadow_mode]
    return {k: grid.finish(planes[k], k, {"units": units[k], "shadow": shadow_used,
                                          "steps": len(mids)}) for k in _PARTS}


_doc_options(insolation, "insolation", SWEEP_OPTIONS)
