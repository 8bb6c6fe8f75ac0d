"""Clear-sky insolation on arrays, as `skysweep insolation --time` computes it
for a DEM at a given place (doc/insolation.md): ESRA beam, diffuse and
reflected irradiation on each cell's slope, cast shadows at every step."""
import math

import numpy as np

from ._context import ArgumentError
from ._grid import out_buffer
from ._lib import CONST, PRODUCTS, default, ffi, lib
from ._memory import BandCost, BandedGrid, rows_sink, run_banded
from .products import (SWEEP_OPTIONS, _begin, _crowns_sky, _doc_options, _numpydoc, _params,
                       _renamed, _stated, _sweep, _trees, _value, sky_rays)
from .sun import iso_duration, unix_seconds

#: The library's parts (ss_insolation_out's fields, the CLI's bands, in order)
#: by pvlib's names (pvlib.irradiance.get_total_irradiance's columns).
_PARTS = {"poa_global": "global", "poa_direct": "beam", "poa_sky_diffuse": "diffuse",
          "poa_ground_diffuse": "reflected", "sun_hours": "sun_hours"}
_LONG_NAMES = {"poa_global": "global irradiation", "poa_direct": "beam irradiation",
               "poa_sky_diffuse": "sky diffuse irradiation",
               "poa_ground_diffuse": "reflected irradiation",
               "poa_diffuse": "diffuse irradiation (sky and reflected)",
               "sun_hours": "hours of direct sun"}


class Irradiation(dict):
    """insolation's parts by pvlib's names; the former names ("global",
    "beam", "diffuse", "reflected") still index it, as aliases."""

    def __missing__(self, key):
        if key in _PARTS.values() and key != "sun_hours":
            return self[next(k for k, v in _PARTS.items() if v == key)]
        raise KeyError(key)


def _as_text(value):
    """A sequence of numbers as the CLI's comma-separated text (--linke
    T,T,..., --surface TILT,AZIMUTH); text and None as they are."""
    if value is None or isinstance(value, str):
        return value
    return ",".join(repr(float(v)) for v in np.atleast_1d(value))


def _clear_sky_params(ctx, given):
    """The library's insolation parameters from keywords (--linke and
    --surface as their text, or as sequences of numbers), checked as the CLI
    checks them before it plans (the registry's run makes its options from
    them), and the Linke turbidity of each month."""
    given = dict(given, linke=_as_text(given.get("linke")),
                 surface=_as_text(given.get("surface")))
    params = _params("insolation", "insolation", given)
    options = ffi.new("ss_insolation_options *")
    ctx.check(lib.ss_insolation_params_options(ctx.ptr, params, lib.SS_SHADOW_EXACT, options))
    by_month = ffi.new("double[12]")
    ctx.check(lib.ss_insolation_params_linke(ctx.ptr, params, by_month))
    return params, by_month


def _surface(surface, tilt, azimuth):
    """--surface's value from pvlib's surface_tilt and surface_azimuth, or
    from `surface` ("cell", "horizontal", or its older (tilt, azimuth))."""
    if tilt is None and azimuth is None:
        return surface
    if tilt is None or azimuth is None:
        raise TypeError("insolation() takes surface_tilt and surface_azimuth together")
    if surface != "cell":
        raise TypeError("insolation() got both surface and surface_tilt, surface_azimuth: "
                        "give one")
    return (tilt, azimuth)


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


def _insolation_trees_options(canopy, given, defaults, kw):
    """The tree options, checked as `skysweep insolation` checks them (its
    wording); None without a canopy."""
    trees = _trees("insolation", canopy, given, defaults, kw)
    if trees is None:
        return None
    for key in ("leaf_area_density", "extinction"):
        if trees["crown_light"] != "beer-lambert" and key in _stated(given, defaults):
            raise ArgumentError(f"--{key.replace('_', '-')} needs --crown-light beer-lambert",
                                2)
    for key in ("leaf_on", "leaf_off"):
        day = trees[key]
        if day is not None:
            trees[key] = str(day)
            if not lib.ss_leaf_date_valid(trees[key].encode()):
                raise ArgumentError(f"--{key.replace('_', '-')} '{trees[key][:60]}' is neither "
                                    "a day of the year (1-366) nor a date MM-DD", 2)
    return trees


def _insolation_trees(ctx, grid, opt, trees, mids, latitude, longitude):
    """The library's ss_insolation_trees, as `skysweep insolation --canopy`
    makes them: the canopy checked, the sky its crowns hide from a
    horizontal surface (ss_canopy_sky), each step's leaf season at the
    place (ss_leaf_seasons). It holds what it points to as long as it
    lives. Returns it and the steps with the leaves off."""
    canopy, gaps, hidden = _crowns_sky(ctx, grid, opt, "insolation", trees,
                                       lib.SS_SVF_DEF_HORIZONTAL)
    leaf_off = np.zeros(max(len(mids), 1), np.uint8)
    season = ffi.new("ss_leaf_season *")
    dates = [ffi.NULL if trees[k] is None else ffi.new("char[]", trees[k].encode())
             for k in ("leaf_on", "leaf_off")]
    lib.ss_leaf_seasons(dates[0], dates[1], latitude, longitude,
                        ffi.new("double[]", list(mids)), len(mids),
                        ffi.from_buffer("unsigned char[]", leaf_off), season)
    beer_lambert = trees["crown_light"] == "beer-lambert"
    held = ffi.new("ss_insolation_trees *", {
        "ground": grid.ptr, "canopy": canopy, "sky_hidden": out_buffer(hidden),
        "transmissivity_leaf_off": trees["transmissivity_leaf_off"],
        "leaf_off": ffi.from_buffer("unsigned char[]", leaf_off),
        "digital_lines": int(trees["crown_lines"] == "digital"), "trunk_gaps": gaps,
        "leaf_area_density": trees["leaf_area_density"] if beer_lambert else 0.0,
        "extinction": trees["extinction"]})
    return ffi.gc(held, lambda _held, _keep=(canopy, hidden, leaf_off): None), \
        season.leaf_off_steps


def _run_insolation(ctx, grid, opt, params, plan, n_steps, sun_at, planes, trees, kw):
    """The registry's insolation run, the five bands of its output 0
    (SS_OUT_GLOBAL ... SS_OUT_SUN_HOURS, _PARTS' order) into planes, one sun
    for every row as sun_at gives it, shadows as planned: on the whole grid,
    or in bands within memory=. A band holds a horizon's sums and the cells'
    terms and sums, and the horizons stored where shadows are interpolated
    (the CLI's band cost); hulls are handed on for up to 64 steps at once."""
    @ffi.callback("ss_status(ss_ctx *, int, int, int, ss_sun_step *, void *)",
                  error=lib.SS_ERR_INTERNAL)
    def sun_rows(c, k, row0, n_rows, step, user):
        return sun_at(c, k, step, user)

    targets = {(0, band): plane for band, plane in enumerate(planes.values())}
    sun = ffi.new("ss_product_sun *", {"n_steps": n_steps, "sun_rows": sun_rows,
                                       "shadow_mode": plan.shadow_mode,
                                       "trees": ffi.NULL if trees is None else trees})
    run = PRODUCTS["insolation"].run
    if not isinstance(grid, BandedGrid):
        sink, failed = rows_sink(targets, grid.shape[1])
        try:
            ctx.call(run, grid.source(), opt, params, sun, 0, ffi.NULL, sink, ffi.NULL,
                     progress=kw.get("progress"))
        finally:
            if failed:  # the sink's own exception, not the library's status for it
                raise failed[0][1].with_traceback(failed[0][2])
        return
    stored = opt.directions if plan.shadow_mode == lib.SS_SHADOW_INTERPOLATED else 0
    exact = plan.shadow_mode == lib.SS_SHADOW_EXACT
    marched = (exact and opt.lines == lib.SS_LINES_BOX
               and opt.box_shadows == lib.SS_BOX_SHADOWS_MARCH)
    # Shadows by each cell's own ray walk no lines, nor do stored shadows:
    # with the sky view's horizons by each cell's own ray too (Perez's band,
    # the stored horizons) no hull is handed on; else only the sky view's
    # directions hand hulls on, each with its box lines. The rays hold the
    # heights whole before the shadows' march does (marches counts those).
    rays = sky_rays(opt)
    no_lines = rays and (marched or not exact) and trees is None  # trees' sky walks lines
    cost = BandCost(lib.ss_horizon_band_cell_bytes(0) +
                    lib.ss_insolation_band_cell_bytes(0, stored),
                    column_bytes=lib.ss_horizon_column_bytes(),
                    hull_lines=(1 if no_lines else opt.directions if marched
                                else max(opt.directions, CONST["SS_INSOLATION_STEPS_PER_RUN"])),
                    box_lines=(1 if no_lines else opt.sky_box_lines
                               if marched and opt.sky_box_lines > 0 else None),
                    # walked exact shadows' bounds keep their blocks whole
                    grid_cell_bytes=((lib.ss_insolation_grid_cell_bytes() if exact and not marched
                                      else 0.0) + (4.0 if rays and not marched else 0.0)),
                    marches=exact)
    run_banded(ctx, grid, opt, cost, kw["memory"], targets,
               lambda c, src, sink: run(c, src, opt, params, sun, 0, ffi.NULL, sink, ffi.NULL),
               progress=kw.get("progress"))


def insolation(dem, cell_size=None, *, time, latitude, longitude,
               step=default("insolation", "step"),
               linke_turbidity=default("insolation", "linke"),
               albedo=default("insolation", "albedo"), shadow=default("insolation", "shadow"),
               solar_constant=default("insolation", "solar-constant"), surface="cell",
               surface_tilt=None, surface_azimuth=None, altitude=None, pressure=101325.0,
               temperature=default("insolation", "temperature"), delta_t=None, nodata=None,
               linke=None, canopy=None, trunk=None,
               trunk_ratio=default("insolation", "trunk-ratio"),
               transmissivity=default("insolation", "transmissivity"),
               trunk_gaps=default("insolation", "trunk-gaps"),
               transmissivity_leaf_off=default("insolation", "transmissivity-leaf-off"),
               leaf_on=None, leaf_off=None, crown_lines=default("insolation", "crown-lines"),
               crown_light=default("insolation", "crown-light"),
               leaf_area_density=default("insolation", "leaf-area-density"),
               extinction=default("insolation", "extinction"), **kw):
    """Clear-sky irradiation of every cell, as `skysweep insolation --time` computes it.

    ESRA with Linke turbidity, as GRASS r.sun: beam, sky diffuse and reflected
    irradiation on each cell's surface, with cast shadows at every step, summed
    over the steps. One sun, at latitude and longitude, serves the whole grid.
    Weather files and PV yield: insolation_file (--weather, --pv).

    Parameters
    ----------
    {dem}
    time : str or instants
        An ISO 8601 range as --time takes it ("2026-06-21T00:00Z/P1D"; the step from
        `step` or its own /STEP; each step evaluated at its middle), or instants
        (any form sun_position takes), each standing for `step` around it.
    latitude, longitude : float
        The grid's centre, degrees north and east.
    step : str, datetime.timedelta, pandas.Timedelta or numpy.timedelta64, default "PT30M"
        The steps' length: ISO 8601 ("PT1H"), a timedelta, or a pandas frequency
        string ("1h", "15min").
    linke_turbidity : float, str or sequence of 12 floats, default "3"
        One Linke turbidity, or twelve (by the UTC month of a step's middle), as
        --linke (pvlib's name; `linke` is its alias).
    albedo : float, default 0.2
        Ground reflectance.
    shadow : {{"auto", "exact", "interpolated"}}, default "auto"
        "auto" (the planner's choice), "exact" (a sweep at every daylight step) or
        "interpolated".
    solar_constant : float, default 1367
        W m-2.
    surface : {{"cell", "horizontal"}} or (float, float), default "cell"
        Each cell's own slope, a horizontal surface, or (tilt, azimuth) degrees: the
        older form of surface_tilt and surface_azimuth.
    surface_tilt, surface_azimuth : float, default None
        A tilted plane for every cell, pvlib's names: tilt from horizontal, azimuth
        clockwise from north (degrees); given together.
    altitude : float, default None
        Metres; None: the DEM's datum height, as the CLI takes it.
    pressure : float, default 101325.0
        Pa, refracting the sun.
    temperature : float, default 12
        Degrees C, refracting the sun.
    delta_t : float, default None
        TT - UT1 in seconds; None: the Espenak-Meeus model.
    {nodata}
    linke : float, str or sequence of 12 floats, default None
        The former name of linke_turbidity, kept as an alias; giving both is a
        TypeError.
    canopy : array_like, numpy.ma.MaskedArray, xarray.DataArray or path, default None
        Trees (the CLI's --canopy, doc/vegetation.md): crown tops in metres above the
        DEM's surface, on the DEM's cells (a DataArray in its order; a file read with
        rasterio, its cell centres the DEM's x, y where it is a DataArray); NaN, masked
        or nodata cells are no tree (0). The beam and circumsolar light through crowns
        keep the step's transmissivity, the sky diffuse and reflected light the sky the
        crowns leave. "auto" shadows are exact with trees. Not with memory=.
    trunk : array_like or path, default None
        Crown bottoms in metres above the surface, like canopy (--trunk); None:
        trunk_ratio x the canopy height.
    trunk_ratio : float, default 0.25
        Crown bottoms as a share of the canopy height, where trunk is None.
    transmissivity : float, default 0.03
        The share of light that crosses a crown with the leaves on (0..1).
    trunk_gaps : {{"open", "ignore"}}, default "open"
        The sky under crowns: "open" sees it between the ground and the trunk height;
        "ignore" takes each crown down to the ground.
    transmissivity_leaf_off : float, default 0.5
        The share of light that crosses a crown with the leaves off (UMEP's 0.5).
    leaf_on, leaf_off : int or str, default None
        The days the leaves come out and fall: a day of the year (1-366) or "MM-DD";
        None: UMEP's days 98 and 300, half a year later south of the equator. Each
        step's season is its local date in mean solar time at `longitude`.
    crown_lines : {{"auto", "digital"}}, default "auto"
        The lines each step's crowns are swept on (doc/vegetation.md).
    crown_light : {{"constant", "beer-lambert"}}, default "constant"
        The beam through crowns: the constant transmissivity, or Beer-Lambert by the
        ray's path inside crowns in leaf-on steps.
    leaf_area_density : float, default 1
        With crown_light "beer-lambert": leaf area per volume of crown (m2/m3).
    extinction : float, default 0.5
        With crown_light "beer-lambert": the leaves' extinction coefficient.

    Returns
    -------
    Irradiation (dict of numpy.ndarray) or xarray.Dataset
        Irradiation summed over the steps, Wh m-2, by pvlib's names: ``poa_global``,
        ``poa_direct`` (beam), ``poa_sky_diffuse``, ``poa_ground_diffuse``
        (reflected), ``poa_diffuse`` (sky and ground), and ``sun_hours`` (hours of
        direct sun on the cell's surface); NaN where the DEM has no height. The dict
        still takes the former keys "global", "beam", "diffuse" (sky) and
        "reflected". For a DataArray DEM, a Dataset of these variables (units "Wh
        m-2", "h") with its CRS and transform. With canopy, the Dataset's attributes
        (for an array, the dict's attribute ``trees``) say the trees' transmissivities
        and how many steps had the leaves off.

    {raises}
    """
    linke_turbidity = _renamed("insolation", "linke_turbidity", linke_turbidity,
                               insolation.__kwdefaults__["linke_turbidity"], "linke", linke)
    surface = _surface(surface, surface_tilt, surface_azimuth)
    trees = _insolation_trees_options(canopy, {
        "trunk": trunk, "trunk_ratio": trunk_ratio, "transmissivity": transmissivity,
        "trunk_gaps": trunk_gaps, "transmissivity_leaf_off": transmissivity_leaf_off,
        "leaf_on": leaf_on, "leaf_off": leaf_off, "crown_lines": crown_lines,
        "crown_light": crown_light, "leaf_area_density": leaf_area_density,
        "extinction": extinction}, insolation.__kwdefaults__, kw)
    if trees is not None and _value("insolation", "shadow", shadow) == "auto":
        shadow = "exact"  # the CLI's too: the planner's error tables have no trees
    ctx, grid = _begin(dem, cell_size, nodata, kw, SWEEP_OPTIONS)
    params, linke = _clear_sky_params(
        ctx, {"step": iso_duration(step), "linke": linke_turbidity, "albedo": albedo,
              "shadow": shadow, "solar_constant": solar_constant, "surface": surface})
    if lib.ss_insolation_params_shadow(params) == lib.SS_SHADOW_CUMULATIVE:
        raise ArgumentError("--shadow cumulative bins the suns of weather records: use "
                            "insolation_file with --weather", 2)
    temperature = _value("insolation", "temperature", temperature)
    latitude, longitude = float(latitude), float(longitude)
    mids, hours = _steps(ctx, time, ffi.string(params.step).decode())
    steps = ffi.new("double[]", list(mids))
    opt, plan = _sweep(ctx, grid, "insolation", params, kw, n_steps=len(mids),
                       step_unix_s=steps, with_plan=True)
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

    held, leaf_off_steps = (None, 0) if trees is None else _insolation_trees(
        ctx, grid, opt, trees, mids, latitude, longitude)
    planes = {k: grid.new_plane() for k in _PARTS}
    _run_insolation(ctx, grid, opt, params, plan, len(mids), sun_at, planes, held, kw)
    shadow_used = ffi.string(lib.ss_shadow_mode_name(plan.shadow_mode)).decode()
    parts = {k: grid.finish(plane, k, {"long_name": _LONG_NAMES[k],
                                       "units": "h" if k == "sun_hours" else "Wh m-2"})
             for k, plane in planes.items()}  # NaN at nodata, in the planes too
    diffuse = planes["poa_sky_diffuse"] + planes["poa_ground_diffuse"]
    parts["poa_diffuse"] = grid.wrap(diffuse, "poa_diffuse", {
        "long_name": _LONG_NAMES["poa_diffuse"], "units": "Wh m-2"})
    about = {"shadow": shadow_used, "steps": len(mids)}
    if trees is not None:
        about.update(transmissivity=trees["transmissivity"],
                     transmissivity_leaf_off=trees["transmissivity_leaf_off"],
                     leaf_off_steps=leaf_off_steps, crown_light=trees["crown_light"])
    if grid.template is None:
        result = Irradiation(parts)
        if trees is not None:
            result.trees = about
        return result
    return grid.dataset(parts, about)


_numpydoc(insolation)
_doc_options(insolation, "insolation", SWEEP_OPTIONS)
