"""The products on numpy arrays: a DEM in metres in, arrays out.

Parameters share the command line's names (``--svf-tolerance`` is
``svf_tolerance``), defaults, ranges and meanings: they come from its option
tables (``skysweep COMMAND --help-json``), and what the command line leaves to
the planner (``--directions``, ``--curvature auto``) the planner decides here
too. An array carries no place, so azimuths are grid azimuths (north up the
columns), the earth's mean radius serves for curvature, and one sun serves the
whole grid. Results hold NaN where the DEM has no height.
"""
import math
from collections import namedtuple

import numpy as np

from ._context import ArgumentError, context
from ._grid import Grid, out_buffer
from ._lib import CONST, default, ffi, lib, option



def _choice(command, name, given):
    """The index of a choice among the table's words (the given one, or the
    default), which is how the library's parameter structs hold it."""
    return option(command, name.replace("_", "-"))["choices"].index(
        _value(command, name, given))


def _params(table, command, given):
    """The library's parameter struct for `table` (``ss_<table>_params``,
    skysweep_params.h), filled from the library's own table as the command
    line fills it: each parameter from `given` (keywords, ``-`` written
    ``_``) or its default, checked against `command`'s options; choices as
    their indices, flags as 0 or 1, no default as 0. The texts it points to
    live as long as the struct."""
    entries = lib.ss_param_table_named(table.encode()).params
    struct = ffi.new(f"ss_{table}_params *")
    base = ffi.cast("char *", struct)
    texts, known = [], set()
    k = 0
    while entries[k].name != ffi.NULL:
        entry, k = entries[k], k + 1
        key = ffi.string(entry.name).decode().replace("-", "_")
        known.add(key)
        at = base + entry.offset
        if entry.type == lib.SS_PARAM_FLAG:
            ffi.cast("int *", at)[0] = int(bool(given.get(key)))
            continue
        value = _value(command, key, given.get(key))
        if value is None:
            continue
        if entry.type == lib.SS_PARAM_CHOICE:
            ffi.cast("int *", at)[0] = _choice(command, key, value)
        elif entry.type == lib.SS_PARAM_INT:
            ffi.cast("int *", at)[0] = value
        elif entry.type == lib.SS_PARAM_DOUBLE:
            ffi.cast("double *", at)[0] = value
        else:
            texts.append(ffi.new("char[]", str(value).encode()))
            ffi.cast("char **", at)[0] = texts[-1]
    stray = set(given) - known
    if stray:  # a slip of the package's own, not the caller's (_begin checks those)
        raise KeyError(f"the library's {table} table has no {', '.join(sorted(stray))}")
    # The destructor holds the texts: they live until the struct is collected.
    return ffi.gc(struct, lambda _struct, _texts=texts: None)


def _sweep_params(command, kw):
    """The library's sweep parameters from keywords, north as the grid's
    (an array has no place)."""
    p = _params("sweep", command, {k: v for k, v in kw.items() if k in SWEEP_OPTIONS})
    p.north = CONST["SS_NORTH_GRID"]
    return p


def _svf_definition(definition):
    """The library's SVF definition for a --definition word, as its table maps it."""
    p = ffi.new("ss_svf_params *")
    p.definition = _choice("svf", "definition", definition)
    return lib.ss_svf_params_term(p)


#: Each sweeping function's options shared with every sweeping command.
SWEEP_OPTIONS = ("directions", "offset", "curvature", "refraction", "earth_radius", "lines",
                 "box_lines", "horizon_tolerance", "svf_tolerance")


def _checked(command, name, value):
    """value, checked against the command's table: range for numbers,
    choices for a choice. Raises ArgumentError as the CLI would refuse it."""
    entry = option(command, name.replace("_", "-"))
    flag = f"{entry['dash']}{entry['name']}"
    if entry["type"] in ("int", "double"):
        try:
            number = float(value)
        except (TypeError, ValueError):
            raise TypeError(f"{name} ({flag}) must be a number, not {value!r}") from None
        if entry["type"] == "int" and number != int(number):
            raise ArgumentError(f"{flag} expects a whole number, not {value!r}", 2)
        if not (math.isfinite(number) and entry["min"] <= number <= entry["max"]):
            raise ArgumentError(f"{flag} expects {entry['min']:g} to {entry['max']:g}, "
                                f"not {value!r}", 2)
        return int(number) if entry["type"] == "int" else number
    if entry["type"] == "choice":
        if value not in entry["choices"]:
            raise ArgumentError(f"{flag} expects one of {', '.join(entry['choices'])}, "
                                f"not {value!r}", 2)
    return value


def _value(command, name, given):
    """The given value, or the table's default, checked."""
    value = default(command, name.replace("_", "-")) if given is None else given
    return None if value is None else _checked(command, name, value)


def _sweep(ctx, grid, command, product, kw, svf_definition=lib.SS_SVF_DEF_GEOMETRIC,
           n_steps=0, step_unix_s=ffi.NULL, shadow_mode=lib.SS_SHADOW_EXACT, with_plan=False,
           radius=0.0):
    """Sweep options (and where asked the plan) for a product, as the CLI's
    job_plan makes them for a DEM without a place."""
    params = _sweep_params(command, kw)
    place = ffi.new("ss_place *")
    place.diagonal_m = math.hypot(grid.shape[1] * grid.cell_size[0],
                                  grid.shape[0] * grid.cell_size[1])
    place.earth_radius_m = params.earth_radius_m or CONST["SS_EARTH_RADIUS_MEAN_M"]
    req = ffi.new("ss_plan_request *")
    lib.ss_sweep_params_request(params, ffi.NULL, req)
    req.product = product
    req.svf_definition = svf_definition
    req.radius_m = radius
    req.shadow_mode = shadow_mode
    req.n_steps = n_steps
    req.step_unix_s = step_unix_s
    plan = ffi.new("ss_plan *")
    ctx.check(lib.ss_plan_make(ctx.ptr, grid.ptr, place, req, plan))
    opt = ffi.new("ss_sweep_options *")
    lib.ss_sweep_options_default(opt)
    opt.offset_deg = params.offset_deg
    lib.ss_plan_sweep_options(plan, place, params.refraction_k, opt)
    ctx.check(lib.ss_sweep_options_check(ctx.ptr, opt))
    ctx.check(lib.ss_ctx_apply_plan(ctx.ptr, plan))  # --device auto: the plan's device
    return (opt, plan) if with_plan else opt


def _begin(dem, cell_size, nodata, kw, allowed):
    unknown = set(kw) - set(allowed) - {"device", "progress"}
    if unknown:
        raise TypeError(f"unexpected keyword argument(s): {', '.join(sorted(unknown))}")
    ctx = context(kw.get("device"))
    return ctx, Grid(ctx, dem, cell_size, nodata)


def svf(dem, cell_size=None, *, definition=None, radius=None, nodata=None, **kw):
    """Sky-view factor (0..1) of every cell.

    definition: "geometric" (1 - mean sin h, Zakšek et al. 2011, RVT), "radiative"
    (Dozier & Frew 1990, the cosine-weighted sky the sloping cell sees) or
    "horizontal" (cosine-weighted, horizontal surface). radius: metres; horizons
    only that far (geometric or horizontal), 0: unlimited, exact.
    """
    ctx, grid = _begin(dem, cell_size, nodata, kw, SWEEP_OPTIONS)
    definition = _value("svf", "definition", definition)
    radius = _value("svf", "radius", radius)
    code = _svf_definition(definition)
    opt = _sweep(ctx, grid, "svf", lib.SS_PRODUCT_SVF, kw, code, radius=radius)
    out = grid.new_plane()
    if radius > 0:
        ctx.call(lib.ss_svf_within, grid.ptr, opt, code, radius, out_buffer(out),
                 progress=kw.get("progress"))
    else:
        ctx.call(lib.ss_svf, grid.ptr, opt, code, out_buffer(out), progress=kw.get("progress"))
    return grid.finish(out, "svf", {"long_name": "sky-view factor", "units": "1",
                                    "definition": definition,
                                    "directions": opt.directions})


def openness(dem, cell_size=None, *, kind=None, radius=None, nodata=None, **kw):
    """Topographic openness (Yokoyama et al. 2002) in degrees: kind "positive"
    or "negative"; radius in metres (0: unlimited). A flat plane gives 90."""
    ctx, grid = _begin(dem, cell_size, nodata, kw, SWEEP_OPTIONS)
    kind = _value("openness", "kind", kind)
    radius = _value("openness", "radius", radius)
    opt = _sweep(ctx, grid, "openness", lib.SS_PRODUCT_HORIZON, kw,  # as cmd_openness plans it
                 radius=radius)
    out = grid.new_plane()
    ctx.call(lib.ss_openness, grid.ptr, opt, int(kind == "negative"), radius, out_buffer(out),
             progress=kw.get("progress"))
    return grid.finish(out, f"{kind} openness", {"long_name": f"{kind} openness",
                                                 "units": "degree", "directions": opt.directions})


Horizons = namedtuple("Horizons", "azimuth elevation distance cast_height")
Horizons.__doc__ = """Horizons in every direction: azimuth (degrees clockwise from north, one
per direction), elevation (degrees above the horizontal, directions x rows x
columns; -90 where no terrain lies ahead inside the grid), and where asked for
distance (metres to the casting point, 0: none) and cast_height (that point's
ground height, metres; NaN: none)."""


def horizon(dem, cell_size=None, *, distance=False, cast_height=False, nodata=None, **kw):
    """Terrain horizon elevation of every cell in each direction (Horizons)."""
    ctx, grid = _begin(dem, cell_size, nodata, kw, SWEEP_OPTIONS)
    opt = _sweep(ctx, grid, "horizon", lib.SS_PRODUCT_HORIZON, kw)
    d, (h, w) = opt.directions, grid.shape
    azimuth = np.array([lib.ss_direction_azimuth(opt, i) for i in range(d)])
    angle = np.empty((d, h, w), np.float32)
    dist = np.empty((d, h, w), np.float32) if distance else None
    height = np.empty((d, h, w), np.float32) if cast_height else None
    n = h * w

    @ffi.callback("int(int, double, const float *, const float *, const float *, void *)")
    def sink(index, azimuth_deg, angle_deg, dist_m, cast_height_m, user):
        angle[index] = np.frombuffer(ffi.buffer(angle_deg, 4 * n), np.float32).reshape(h, w)
        if dist is not None:
            dist[index] = np.frombuffer(ffi.buffer(dist_m, 4 * n), np.float32).reshape(h, w)
        if height is not None:
            height[index] = np.frombuffer(ffi.buffer(cast_height_m, 4 * n),
                                          np.float32).reshape(h, w)
        return 1

    want = (CONST["SS_HORIZON_DISTANCE"] if distance else 0) | (
        CONST["SS_HORIZON_CAST_HEIGHT"] if cast_height else 0)
    ctx.call(lib.ss_horizon, grid.ptr, opt, want, sink, ffi.NULL, progress=kw.get("progress"))
    nodata_cells = angle[0] == np.float32(CONST["SS_NODATA"])
    for cube in (angle, dist, height):
        if cube is not None:
            cube[:, nodata_cells] = np.nan
    if height is not None:
        height[height == np.float32(CONST["SS_NODATA"])] = np.nan
    lead = {"azimuth": azimuth}
    return Horizons(azimuth, grid.wrap(angle, "horizon", {"long_name": "horizon elevation",
                                                          "units": "degree"}, lead),
                    None if dist is None else grid.wrap(dist, "distance", {
                        "long_name": "horizon distance", "units": "m"}, lead),
                    None if height is None else grid.wrap(height, "cast height", {
                        "long_name": "horizon cast height", "units": "m"}, lead))


def shadow(dem, cell_size=None, *, sun_azimuth, sun_elevation, nodata=None, **kw):
    """Cast shadows for one sun: 1 where a cell is sunlit (its apparent sun
    elevation above its terrain horizon in the sun's azimuth), 0 in shadow.
    sun_azimuth: degrees clockwise from north; sun_elevation: apparent
    (refracted) degrees. Self-shadow (a cell facing away) is not included:
    see hillshade and sun_incidence."""
    ctx, grid = _begin(dem, cell_size, nodata, kw, SWEEP_OPTIONS)
    sun_azimuth = _checked("shadow", "sun_azimuth", sun_azimuth)
    sun_elevation = _checked("shadow", "sun_elevation", sun_elevation)
    opt = _sweep(ctx, grid, "shadow", lib.SS_PRODUCT_SHADOW, kw)
    out = grid.new_plane()
    ctx.call(lib.ss_cast_shadow, grid.ptr, opt, sun_azimuth, sun_elevation, ffi.NULL,
             out_buffer(out), ffi.NULL, progress=kw.get("progress"))
    return grid.finish(out, "sunlit", {"long_name": "sunlit", "units": "1",
                                       "sun_azimuth": sun_azimuth,
                                       "sun_elevation": sun_elevation})


def _shade(dem, cell_size, nodata, kw, given):
    """gdaldem's hillshade or RVT's VAT blend (1..255), as `skysweep
    hillshade` computes it: the library's options from its hillshade table
    (ss_hillshade_params_options), the planner asked for what they sweep,
    and the rows of ss_hillshade_rows on the whole grid."""
    ctx, grid = _begin(dem, cell_size, nodata, kw, SWEEP_OPTIONS)
    params = _params("hillshade", "hillshade", given)
    shading = ffi.new("ss_hillshade_options *")
    lib.ss_hillshade_params_options(params, math.sqrt(grid.cell_size[0] * grid.cell_size[1]),
                                    shading)
    opt = _sweep(ctx, grid, "hillshade", lib.ss_hillshade_params_product(params), kw)
    out = grid.new_plane()
    width = grid.shape[1]

    failed = []

    @ffi.callback("ss_status(void *, int, int, int, int, const float *)",
                  error=lib.SS_ERR_INTERNAL, onerror=lambda *e: failed.append(e))
    def into_plane(user, output, index, row0, n_rows, values):
        out[row0:row0 + n_rows] = np.frombuffer(ffi.buffer(values, 4 * n_rows * width),
                                                np.float32).reshape(n_rows, width)
        return 0

    try:
        ctx.call(lib.ss_hillshade_rows, grid.source(), opt, shading, into_plane, ffi.NULL,
                 progress=kw.get("progress"))
    finally:
        if failed:  # the sink's own exception, not the library's status for it
            raise failed[0][1].with_traceback(failed[0][2])
    return grid, opt, out


def hillshade(dem, cell_size=None, *, az=None, alt=None, z=None, alg=None,
              multidirectional=False, cast_shadows=False, sky_view=None, nodata=None, **kw):
    """Hillshade as gdaldem computes it (1..255): light from azimuth `az` and
    altitude `alt` (degrees), heights scaled by `z`, slope by `alg` "Horn" or
    "ZevenbergenThorne", or gdaldem's multidirectional blend. The names are
    gdaldem's and the CLI's. cast_shadows: cells in the light's cast shadows
    (an exact sweep along it) take 1; sky_view: a weight W in 0..1 blending
    in (1 - W) shade + W (1 + 254 SVF), geometric SVF over `directions`. The
    values are the shade before the Byte rounding of the CLI's file (np.rint
    gives the file's bytes)."""
    grid, _, out = _shade(dem, cell_size, nodata, kw,
                          {"az": az, "alt": alt, "z": z, "alg": alg,
                           "multidirectional": multidirectional, "cast_shadows": cast_shadows,
                           "sky_view": sky_view})
    return grid.finish(out, "hillshade", {"long_name": "hillshade", "units": "1",
                                          "az": _value("hillshade", "az", az),
                                          "alt": _value("hillshade", "alt", alt)})


def sun_incidence(dem, cell_size=None, *, sun_azimuth, sun_elevation, nodata=None, device=None):
    """Cosine of the angle between the sun and each cell's surface normal
    (Horn's gradient); <= 0 where the cell faces away from the sun."""
    ctx, grid = _begin(dem, cell_size, nodata, {"device": device}, ())
    out = grid.new_plane()
    ctx.call(lib.ss_sun_incidence, grid.ptr, _checked("shadow", "sun_azimuth", sun_azimuth),
             _checked("shadow", "sun_elevation", sun_elevation), ffi.NULL, ffi.NULL,
             out_buffer(out))
    return grid.finish(out, "cos incidence", {"long_name": "cosine of the sun's incidence",
                                              "units": "1"})


def vat(dem, cell_size=None, *, blend_radius=None, nodata=None, **kw):
    """RVT's VAT relief blend (Kokalj & Somrak 2019), 0..1 (1 = white):
    gdaldem's hillshade at 315/35 degrees, Horn's slope, and SVF and positive
    openness from horizons within `blend_radius` cells (RVT's 10; 0:
    unlimited), as `skysweep hillshade --blend vat` computes it (its file
    holds 1 + 254 times this, rounded)."""
    grid, opt, out = _shade(dem, cell_size, nodata, kw,
                            {"blend": "vat", "blend_radius": blend_radius})
    blend = np.where(out == np.float32(CONST["SS_NODATA"]), out, (out - 1.0) / 254.0)
    return grid.finish(blend.astype(np.float32), "vat", {"long_name": "VAT relief blend",
                                                         "units": "1",
                                                         "directions": opt.directions})


_PRODUCTS = {"horizon": lib.SS_PRODUCT_HORIZON, "openness": lib.SS_PRODUCT_HORIZON,
             "svf": lib.SS_PRODUCT_SVF, "shadow": lib.SS_PRODUCT_SHADOW}


def plan(dem, cell_size=None, *, product="svf", definition=None, nodata=None, **kw):
    """What a run of `product` ("svf", "openness", "horizon" or "shadow")
    would simulate on this DEM, and why: the planner's decisions as a dict
    (`skysweep COMMAND --plan --plan-format json`): directions, sweeps,
    estimated_seconds, device, and "effects", each with its on/off, reason
    and the error it allows."""
    import json
    if product not in _PRODUCTS:
        raise ValueError(f"product must be one of {', '.join(_PRODUCTS)}, not {product!r}")
    ctx, grid = _begin(dem, cell_size, nodata, kw, SWEEP_OPTIONS)
    code = _svf_definition(definition) if product == "svf" else lib.SS_SVF_DEF_GEOMETRIC
    _, made = _sweep(ctx, grid, product, _PRODUCTS[product], kw, code, with_plan=True)
    size = lib.ss_plan_format(made, 1, ffi.NULL, 0) + 1
    text = ffi.new("char[]", size)
    lib.ss_plan_format(made, 1, text, size)
    return json.loads(ffi.string(text).decode())


def _doc_options(function, command, names):
    """Appends the table's entries for the shared options to a docstring."""
    lines = ["", "Options shared with `skysweep " + command + "` (defaults from its table):"]
    for name in names:
        entry = option(command, name.replace("_", "-"))
        shown = entry.get("default", "-")
        lines.append(f"    {name} (default {shown}): {entry['help']}")
    lines.append("    device: None (SKYSWEEP_DEVICE, else \"auto\": the plan's choice), "
                 "\"reference\" (the C twin) or a device as --device names it")
    lines.append("    progress: None, True (tqdm or text) or callable(fraction, message); "
                 "returning False cancels")
    function.__doc__ = (function.__doc__ or "") + "\n".join(lines)


for _f, _c in ((svf, "svf"), (openness, "openness"), (horizon, "horizon"), (shadow, "shadow"),
               (hillshade, "hillshade"), (vat, "hillshade"), (plan, "svf")):
    _doc_options(_f, _c, SWEEP_OPTIONS)
