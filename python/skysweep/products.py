"""The products on numpy arrays: a DEM in metres in, arrays out.

Parameters share the command line's names (``--svf-tolerance`` is
``svf_tolerance``), defaults, ranges and meanings: they come from its option
tables (``skysweep COMMAND --help-json``), and what the command line leaves to
the planner (``--directions``, ``--curvature auto``) the planner decides here
too. An array carries no place, so azimuths are grid azimuths (north up the
columns), the earth's mean radius serves for curvature, and one sun serves the
whole grid. Results hold NaN where the DEM has no height.
"""
import inspect
import math
import os
from collections import namedtuple

import numpy as np

from ._context import ArgumentError, context
from ._grid import Grid, _declared_nodata, _is_dataarray, out_buffer
from ._lib import CONST, PRODUCTS, default, ffi, lib, option
from ._memory import BandCost, BandedGrid, parse_size, resident_bytes, rows_sink, run_banded


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


#: Each sweeping function's options shared with every sweeping command.
SWEEP_OPTIONS = ("directions", "offset", "curvature", "refraction", "earth_radius", "lines",
                 "box_lines", "box_shadows", "box_sky", "horizon_tolerance", "svf_tolerance")


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


def _sweep(ctx, grid, name, params, kw, n_steps=0, step_unix_s=ffi.NULL, with_plan=False):
    """Sweep options (and where asked the plan) for the registry's product
    `name` with its own parameters (`params`, its table's struct; None: it
    has none): the library's one translation, ss_product_prepare, as the
    CLI's commands call it, for a grid without a place."""
    sweep = _sweep_params(name, kw)
    job = ffi.new("ss_product_job *", {"sweep": sweep, "sun": ffi.NULL, "place": ffi.NULL,
                                       "n_steps": n_steps, "step_unix_s": step_unix_s})
    opt = ffi.new("ss_sweep_options *")
    plan = ffi.new("ss_plan *")
    ctx.check(lib.ss_product_prepare(ctx.ptr, PRODUCTS[name],
                                     ffi.NULL if params is None else params, grid.ptr, job,
                                     opt, plan))
    return (opt, plan) if with_plan else opt


def _renamed(function, name, value, default_value, alias, alias_value):
    """A parameter that also has an older name (kept as an alias): the
    alias's value where only it is given. Giving both is a TypeError. The
    parameter was not given where it is its signature's own default object
    (a caller's 315.0 is another object)."""
    if alias_value is None:
        return value
    if value is not default_value:
        raise TypeError(f"{function}() got both {name} and its alias {alias}: give one")
    return alias_value


def _begin(dem, cell_size, nodata, kw, allowed, bands=True):
    """The call's context and its DEM: held whole, or with memory= (where
    the call runs in bands) read a band at a time (_memory.BandedGrid)."""
    unknown = set(kw) - set(allowed) - {"device", "progress"} - ({"memory"} if bands else set())
    if unknown:
        raise TypeError(f"unexpected keyword argument(s): {', '.join(sorted(unknown))}")
    if kw.get("memory") is None:
        ctx = context(kw.get("device"))
        return ctx, Grid(ctx, dem, cell_size, nodata)
    kw["memory"] = parse_size(kw["memory"])
    start_resident = resident_bytes()  # before the context and its device
    ctx = context(kw.get("device"))
    return ctx, BandedGrid(ctx, dem, cell_size, nodata, start_resident)


def _product_cost(name, params, outputs=0, cell_m=math.nan, **more):
    """What a band of a registry product holds (its cell_bytes and halo_m)."""
    product = PRODUCTS[name]
    params = ffi.NULL if params is None else params
    return BandCost(product.cell_bytes(params, outputs), halo_m=product.halo_m(params, cell_m),
                    **more)


def sky_rays(opt, radius=0.0):
    """Whether the sky view is each cell's own ray (box lines with box_sky
    'march', no radius): it hands no hull on, and in bands it holds the
    heights whole (a float a cell of the whole grid, as the CLI's
    run_box_sky_cell_bytes counts)."""
    return (opt.lines == lib.SS_LINES_BOX and opt.box_sky == lib.SS_BOX_SKY_MARCH
            and not radius > 0)


#: A band's cost beside the product's own where the sky view is each cell's own ray.
SKY_RAYS_COST = {"hull_lines": 1, "box_lines": 1, "grid_cell_bytes": 4.0}


def _run(ctx, grid, opt, name, params, targets, kw, cost=None, sun=ffi.NULL, outputs=0):
    """The one path of the array calls: the registry product's run call
    (skysweep_products.h), as the CLI runs it, into targets (rows_sink's:
    output, or (output, band), to a plane or cube), NaN at nodata. On the
    whole grid held in memory, or within memory= in bands of what `cost`
    says a band holds (a BandCost; None: _product_cost's)."""
    run = PRODUCTS[name].run
    args = (opt, ffi.NULL if params is None else params, sun, outputs, ffi.NULL)
    if isinstance(grid, BandedGrid):
        run_banded(ctx, grid, opt, cost or _product_cost(name, params, outputs), kw["memory"],
                   targets, lambda c, src, sink: run(c, src, *args, sink, ffi.NULL),
                   progress=kw.get("progress"))
        return
    sink, failed = rows_sink(targets, grid.shape[1])
    try:
        ctx.call(run, grid.source(), *args, sink, ffi.NULL, progress=kw.get("progress"))
    finally:
        if failed:  # the sink's own exception, not the library's status for it
            raise failed[0][1].with_traceback(failed[0][2])


_RAISES = """Raises
------
ArgumentError
    A parameter out of its table's range or choices (the CLI's wording).
TypeError, ValueError
    A DEM that is not 2-D real numbers, a missing or bad cell_size, an unknown keyword.
SkysweepError
    The library's failures (DeviceError, OutOfMemory, Cancelled, ...)."""

_DEM_PARAMETERS = """dem : array_like, numpy.ma.MaskedArray, xarray.DataArray or rasterio dataset
    Heights in metres, rows north to south (doc/python.md: how each input is read).
cell_size : float or (float, float), default None
    Cell size in metres, one number or (east-west, north-south); None takes it from a
    DataArray's x, y coordinates or a rasterio dataset's transform."""

_NODATA_PARAMETER = """nodata : float, default None
    A height that marks cells without one, besides NaN and what the input declares."""


def _name_parameter(default_name):
    return f"""name : str, default {default_name!r}
    The returned DataArray's name (for a DataArray DEM; as xarray-spatial's name=)."""


SvfTrees = namedtuple("SvfTrees", "svf svfveg svfbuveg")
SvfTrees.__doc__ = """The sky view with trees (doc/vegetation.md, "svf"): svf, the solid
surface's, as without trees; svfveg, 1 - the share of the sky crowns hide above
the solid horizon; svfbuveg, svf - (1 - svfveg)(1 - transmissivity)."""

def svf(dem, cell_size=None, *, definition=default("svf", "definition"),
        radius=default("svf", "radius"), nodata=None, name="svf", canopy=None, trunk=None,
        trunk_ratio=default("svf", "trunk-ratio"),
        transmissivity=default("svf", "transmissivity"),
        trunk_gaps=default("svf", "trunk-gaps"), **kw):
    """Sky-view factor (0..1) of every cell.

    Parameters
    ----------
    {dem}
    definition : {{"geometric", "radiative", "horizontal"}}, default "geometric"
        "geometric" (1 - mean sin h, Zakšek et al. 2011, RVT), "radiative" (Dozier &
        Frew 1990, the cosine-weighted sky the sloping cell sees) or "horizontal"
        (cosine-weighted, horizontal surface).
    radius : float, default 0
        Metres; horizons only that far (geometric or horizontal). 0: unlimited, exact.
    {nodata}
    {name}
    canopy : array_like, numpy.ma.MaskedArray, xarray.DataArray or path, default None
        Trees (the CLI's --canopy, doc/vegetation.md): crown tops in metres above the
        DEM's surface, shaped like the DEM (a DataArray in its order; a file read with
        rasterio, on the DEM's cells); NaN, masked or declared nodata cells are no tree
        (0). Not with radius, "radiative" or memory=.
    trunk : array_like or path, default None
        Crown bottoms in metres above the surface, like canopy (--trunk); None:
        trunk_ratio x the canopy height.
    trunk_ratio : float, default 0.25
        Crown bottoms as a share of the canopy height, where trunk is None.
    transmissivity : float, default 0.03
        The share of light that crosses a crown (0..1), in svfbuveg.
    trunk_gaps : {{"open", "ignore"}}, default "open"
        "open" sees the sky under the crowns (between the ground and the trunk height);
        "ignore" takes each crown down to the ground.

    Returns
    -------
    numpy.ndarray or xarray.DataArray
        float32, shaped like the DEM, NaN where it has no height; a DataArray (units
        "1") for a DataArray DEM.
    SvfTrees or xarray.Dataset
        With canopy: SvfTrees(svf, svfveg, svfbuveg), the CLI's bands 1 to 3, for an
        array; a Dataset with those three variables for a DataArray.

    {raises}
    """
    trees = _svf_trees(canopy, trunk, trunk_ratio, transmissivity, trunk_gaps, definition,
                       radius, svf.__kwdefaults__, kw)
    ctx, grid = _begin(dem, cell_size, nodata, kw, SWEEP_OPTIONS)
    definition = _value("svf", "definition", definition)
    radius = _value("svf", "radius", radius)
    params = _params("svf", "svf", {"definition": definition, "radius": radius})
    code = lib.ss_svf_params_term(params)
    opt = _sweep(ctx, grid, "svf", params, kw)
    out = grid.new_plane()
    cost = _product_cost("svf", params, **(SKY_RAYS_COST if sky_rays(opt, radius) else {}))
    _run(ctx, grid, opt, "svf", params, {0: out}, kw, cost=cost)
    attrs = {"long_name": "sky-view factor", "units": "1", "definition": definition,
             "directions": opt.directions}
    if trees is None:
        return grid.finish(out, name, attrs)
    veg, total = _svf_tree_bands(ctx, grid, opt, code, out, trees, kw)
    bands = SvfTrees(grid.finish(out, name, attrs),
                     grid.finish(veg, "svfveg", dict(attrs, long_name=(
                         "svfveg: 1 - the share of the sky crowns hide above the solid horizon"))),
                     grid.finish(total, "svfbuveg", dict(attrs, long_name=(
                         "svfbuveg: svf - (1 - svfveg) x (1 - transmissivity)"),
                         transmissivity=trees["transmissivity"])))
    if grid.template is None:
        return bands
    return grid.dataset({"svf": bands.svf, "svfveg": bands.svfveg, "svfbuveg": bands.svfbuveg},
                        {"directions": opt.directions, "transmissivity": trees["transmissivity"],
                         "trunk_gaps": trees["trunk_gaps"]})


def _svf_trees(canopy, trunk, trunk_ratio, transmissivity, trunk_gaps, definition, radius,
               defaults, kw):
    """svf's tree options, checked as the CLI checks them (its wording);
    None without a canopy."""
    trees = _trees("svf", canopy, {"trunk": trunk, "trunk_ratio": trunk_ratio,
                                   "transmissivity": transmissivity, "trunk_gaps": trunk_gaps},
                   defaults, kw)
    if trees is None:
        return None
    if _value("svf", "definition", definition) == "radiative":
        raise ArgumentError("--canopy takes --definition geometric or horizontal, not radiative",
                            2)
    if _value("svf", "radius", radius) > 0:
        raise ArgumentError("--canopy takes no --radius", 2)
    return trees


def _stated(given, defaults):
    """The keywords of `given` a caller stated: not the signature's own
    default object (a caller's 0.25 is another)."""
    return [k for k, v in given.items() if v is not defaults[k]]


def _trees(command, canopy, given, defaults, kw):
    """A command's tree options (given: trunk, trunk_ratio, ... as keywords),
    checked against its table as the CLI checks them (its wording); None
    without a canopy."""
    stated = _stated(given, defaults)
    if canopy is None:
        if stated:
            raise ArgumentError(f"--{stated[0].replace('_', '-')} needs --canopy", 2)
        return None
    if given["trunk"] is not None and "trunk_ratio" in stated:
        raise ArgumentError("--trunk and --trunk-ratio are alternatives: give one", 2)
    if kw.get("memory") is not None:
        raise ValueError(f"{command}(canopy=...) holds the DEM whole for the crowns: leave out "
                         f"memory= (or use {command}_file, which reads the DEM in bands)")
    trees = {k: v if k == "trunk" else _value(command, k, v) for k, v in given.items()}
    trees["canopy"] = canopy
    return trees


def _canopy(ctx, grid, trees):
    """The library's ss_canopy for the trees on the grid, checked; it holds
    its layers as long as it lives."""
    height = _tree_layer(grid, trees["canopy"], "canopy")
    trunk = None if trees["trunk"] is None else _tree_layer(grid, trees["trunk"], "trunk")
    canopy = ffi.new("ss_canopy *", {
        "height_m": ffi.from_buffer("float[]", height),
        "trunk_m": ffi.NULL if trunk is None else ffi.from_buffer("float[]", trunk),
        "trunk_ratio": trees["trunk_ratio"], "transmissivity": trees["transmissivity"]})
    ctx.check(lib.ss_canopy_check(ctx.ptr, grid.ptr, canopy))
    return ffi.gc(canopy, lambda _canopy, _layers=(height, trunk): None)


def _crowns_sky(ctx, grid, opt, command, trees, definition, progress=None):
    """The trees' ss_canopy (_canopy), their trunk gaps as the library's
    code, and the share of each cell's sky their crowns hide
    (ss_canopy_sky, by `definition`), as `skysweep svf --canopy` and
    `skysweep insolation --canopy` compute it."""
    canopy = _canopy(ctx, grid, trees)
    gaps = option(command, "trunk-gaps")["choices"].index(trees["trunk_gaps"])
    hidden = grid.new_plane()
    ctx.call(lib.ss_canopy_sky, grid.ptr, canopy, opt, definition, gaps, ffi.NULL,
             out_buffer(hidden), progress=progress)
    return canopy, gaps, hidden


def _tree_layer(grid, values, what):
    """A canopy or trunk layer onto the grid's cells (float32, rows north to
    south): a DataArray flipped as its DEM was, a file's band 1 as it lies,
    NaN, masked and declared nodata cells no tree (0), as the CLI reads a
    tree raster."""
    nodata_values, flips = [], grid.flips
    if isinstance(values, (str, os.PathLike)):
        values, flips = _tree_file(grid, values, what), []
    elif _is_dataarray(values):
        _same_coords(grid, values, what)
        nodata_values = _declared_nodata(values)
        values = values.values
    masked = np.ma.getmaskarray(values) if np.ma.isMaskedArray(values) else None
    a = np.asarray(np.ma.getdata(values) if masked is not None else values)
    if a.dtype.kind not in "iuf":
        raise TypeError(f"{what} must hold real numbers (metres), not dtype {a.dtype}")
    if a.shape != grid.shape:
        raise ValueError(f"{what} must be shaped like the DEM {grid.shape}, not {a.shape}")
    layer = a.astype(np.float32)
    for axis in flips:
        layer = np.flip(layer, axis)
    if masked is not None:
        for axis in flips:
            masked = np.flip(masked, axis)
        layer[masked] = 0.0
    layer[np.isnan(layer)] = 0.0
    for nodata in nodata_values:
        layer[layer == np.float32(nodata)] = 0.0
    return np.ascontiguousarray(layer)


def _tree_file(grid, path, what):
    """Band 1 of a tree raster (rasterio), its nodata masked, rows north to
    south. Where the DEM is a DataArray, the file's cell centres must be
    its x, y (the CLI warps a tree raster onto the DEM's grid; an array has
    no place to warp onto)."""
    try:
        import rasterio
    except ImportError:
        raise ImportError(f"{what} as a file needs rasterio (pip install rasterio); or give "
                          "it as an array") from None
    with rasterio.open(path) as dataset:
        t = dataset.transform
        if t.b != 0 or t.d != 0 or t.e > 0:
            raise ValueError(f"{what} {path}: its grid is rotated or its rows run south to "
                             "north: resample it north-up first")
        layer = dataset.read(1, masked=True)
    template = grid.template
    if template is not None and layer.shape == grid.shape:
        centres = {"x": t.c + t.a * (np.arange(layer.shape[1]) + 0.5),
                   "y": t.f + t.e * (np.arange(layer.shape[0]) + 0.5)}
        for dim, mine in centres.items():
            if dim in template.coords and not np.allclose(
                    mine, np.sort(np.asarray(template.coords[dim]))[::1 if dim == "x" else -1]):
                raise ValueError(f"{what} {path}: its cells are not the DEM's: put it on the "
                                 "DEM's grid first (gdalwarp, or rioxarray's reproject_match)")
    return layer


def _same_coords(grid, layer, what):
    """A tree DataArray lies on its DEM's cells, in its order: the
    coordinates it has of the DEM's dimensions must be the DEM's."""
    template = grid.template
    for dim in layer.dims:
        if template is None or dim not in layer.coords or dim not in template.coords:
            continue
        mine, theirs = np.asarray(layer.coords[dim]), np.asarray(template.coords[dim])
        if mine.shape != theirs.shape or not np.allclose(mine, theirs):
            raise ValueError(f"{what}'s {dim} coordinates are not the DEM's: put it on the "
                             "DEM's grid first (layer.interp_like(dem), or rioxarray's "
                             "reproject_match)")


def _svf_tree_bands(ctx, grid, opt, code, svf_plane, trees, kw):
    """svfveg and svfbuveg from the svf plane (NaN at nodata),
    as `skysweep svf --canopy` makes bands 2 and 3: ss_canopy_sky's crown
    share, then ss_canopy_svf_bands."""
    _, _, veg = _crowns_sky(ctx, grid, opt, "svf", trees, code, kw.get("progress"))
    total = grid.new_plane()
    lib.ss_canopy_svf_bands(veg.size, ffi.from_buffer("float[]", _nodata_marked(svf_plane)),
                            out_buffer(veg),
                            trees["transmissivity"], out_buffer(veg), out_buffer(total))
    return veg, total


def openness(dem, cell_size=None, *, kind=default("openness", "kind"),
             radius=default("openness", "radius"), nodata=None, name=None, **kw):
    """Topographic openness (Yokoyama et al. 2002) in degrees; a flat plane gives 90.

    Parameters
    ----------
    {dem}
    kind : {{"positive", "negative"}}, default "positive"
        Positive (above the terrain) or negative (below it) openness.
    radius : float, default 0
        Metres; horizons only that far. 0: unlimited.
    {nodata}
    name : str, default None
        The returned DataArray's name; None: "positive openness" or "negative openness".

    Returns
    -------
    numpy.ndarray or xarray.DataArray
        float32 degrees, shaped like the DEM, NaN where it has no height.

    {raises}
    """
    ctx, grid = _begin(dem, cell_size, nodata, kw, SWEEP_OPTIONS)
    kind = _value("openness", "kind", kind)
    radius = _value("openness", "radius", radius)
    params = _params("openness", "openness", {"kind": kind, "radius": radius})
    opt = _sweep(ctx, grid, "openness", params, kw)
    out = grid.new_plane()
    cost = _product_cost("openness", params, **(SKY_RAYS_COST if sky_rays(opt, radius) else {}))
    _run(ctx, grid, opt, "openness", params, {0: out}, kw, cost=cost)
    return grid.finish(out, name or f"{kind} openness",
                       {"long_name": f"{kind} openness", "units": "degree",
                        "directions": opt.directions})


Horizons = namedtuple("Horizons", "azimuth elevation distance cast_height")
Horizons.__doc__ = """Horizons in every direction: azimuth (degrees clockwise from north, one
per direction), elevation (degrees above the horizontal, directions x rows x
columns; -90 where no terrain lies ahead inside the grid), and where asked for
distance (metres to the casting point, 0: none) and cast_height (that point's
ground height, metres; NaN: none). On box lines by each cell's own ray
(lines="box", box_sky="march") a cell's own flat top is its horizon where
nothing rises above it: elevation 0, distance to the cell's own edge,
cast_height the cell's own height."""


def horizon(dem, cell_size=None, *, distance=False, cast_height=False, nodata=None, **kw):
    """Terrain horizon elevation of every cell in each direction.

    Parameters
    ----------
    {dem}
    distance : bool, default False
        Also the distance (metres) to the terrain that casts each horizon (0: none;
        see Horizons for box lines).
    cast_height : bool, default False
        Also that terrain's ground height (metres; NaN: none).
    {nodata}

    Returns
    -------
    Horizons or xarray.Dataset
        For an array: Horizons(azimuth, elevation, distance, cast_height), the cubes
        directions x rows x columns (None where not asked for). For a DataArray: a
        Dataset with variables ``elevation`` (degrees), and where asked ``distance``
        and ``cast_height`` (m), over the dimension coordinate ``azimuth`` (degrees
        clockwise from north) and the DEM's y, x, with its CRS and transform.

    {raises}
    """
    ctx, grid = _begin(dem, cell_size, nodata, kw, SWEEP_OPTIONS)
    opt = _sweep(ctx, grid, "horizon", None, kw)
    d, (h, w) = opt.directions, grid.shape
    azimuth = np.array([lib.ss_direction_azimuth(opt, i) for i in range(d)])
    angle = np.empty((d, h, w), np.float32)
    dist = np.empty((d, h, w), np.float32) if distance else None
    height = np.empty((d, h, w), np.float32) if cast_height else None
    want = (CONST["SS_HORIZON_DISTANCE"] if distance else 0) | (
        CONST["SS_HORIZON_CAST_HEIGHT"] if cast_height else 0)
    # Output i of the registry's horizon is ss_horizon_rows' SS_OUT_HORIZON_*:
    # its optional outputs' bits are want shifted by one.
    cubes = {i: c for i, c in enumerate((angle, dist, height)) if c is not None}
    _run(ctx, grid, opt, "horizon", None, cubes, kw, outputs=want << 1,
         cost=_product_cost("horizon", None, want << 1,
                            column_bytes=lib.ss_horizon_column_bytes(),
                            **(SKY_RAYS_COST if sky_rays(opt) else {})))
    lead = {"azimuth": ("azimuth", azimuth, {"long_name": "azimuth clockwise from north",
                                             "units": "degree"})}
    cubes = Horizons(azimuth, grid.wrap(angle, "elevation", {"long_name": "horizon elevation",
                                                             "units": "degree"}, lead),
                     None if dist is None else grid.wrap(dist, "distance", {
                         "long_name": "horizon distance", "units": "m"}, lead),
                     None if height is None else grid.wrap(height, "cast_height", {
                         "long_name": "horizon cast height", "units": "m"}, lead))
    if grid.template is None:
        return cubes
    return grid.dataset({k: v for k, v in cubes._asdict().items()
                         if k != "azimuth" and v is not None},
                        {"directions": d})


ShadowTrees = namedtuple("ShadowTrees", "sunlit shadow_class fraction")
ShadowTrees.__doc__ = """Shadows with trees (doc/vegetation.md): sunlit, the solid terrain's
verdict as without trees; shadow_class, 0 lit, 1 solid shadow, 2 vegetation
shadow; fraction, the share of the beam that arrives (1, 0, or the
transmissivity): `skysweep shadow --canopy`'s bands 1, 4 and 5."""


def shadow(dem, cell_size=None, *, sun_azimuth, sun_elevation, nodata=None, name="sunlit",
           canopy=None, trunk=None, trunk_ratio=default("shadow", "trunk-ratio"),
           transmissivity=default("shadow", "transmissivity"), **kw):
    """Cast shadows for one sun: 1 where a cell is sunlit, 0 in shadow.

    A cell is sunlit where the sun's apparent elevation lies above its terrain
    horizon in the sun's azimuth. Self-shadow (a cell facing away) is not
    included: see hillshade and sun_incidence.

    Parameters
    ----------
    {dem}
    sun_azimuth : float
        Degrees clockwise from north.
    sun_elevation : float
        Apparent (refracted) degrees above the horizontal.
    {nodata}
    {name}
    canopy, trunk, trunk_ratio, transmissivity : array_like, array_like, float, float
        Trees, as svf takes them (the CLI's --canopy, --trunk, --trunk-ratio,
        --transmissivity; not with memory=).

    Returns
    -------
    numpy.ndarray or xarray.DataArray
        float32 1 (sunlit) or 0, shaped like the DEM, NaN where it has no height.
    ShadowTrees or xarray.Dataset
        With canopy: ShadowTrees(sunlit, shadow_class, fraction) for an array; a Dataset
        with those three variables for a DataArray.

    {raises}
    """
    trees = _trees("shadow", canopy, {"trunk": trunk, "trunk_ratio": trunk_ratio,
                                      "transmissivity": transmissivity},
                   shadow.__kwdefaults__, kw)
    ctx, grid = _begin(dem, cell_size, nodata, kw, SWEEP_OPTIONS)
    sun_azimuth = _checked("shadow", "sun_azimuth", sun_azimuth)
    sun_elevation = _checked("shadow", "sun_elevation", sun_elevation)
    opt = _sweep(ctx, grid, "shadow", None, kw)
    out = grid.new_plane()
    _sunlit(ctx, grid, opt, sun_azimuth, sun_elevation, out, kw)
    attrs = {"long_name": "sunlit", "units": "1", "sun_azimuth": sun_azimuth,
             "sun_elevation": sun_elevation}
    if trees is None:
        return grid.finish(out, name, attrs)
    klass, fraction = _shadow_tree_bands(ctx, grid, opt, sun_azimuth, sun_elevation, out, trees)
    bands = ShadowTrees(grid.finish(out, name, attrs),
                        grid.finish(klass, "shadow_class", dict(attrs, long_name=(
                            "shadow class: 0 lit, 1 solid shadow, 2 vegetation shadow"))),
                        grid.finish(fraction, "fraction", dict(attrs, long_name=(
                            "fraction of the beam that arrives: 1 lit, 0 solid, T through "
                            "crowns"), transmissivity=trees["transmissivity"])))
    if grid.template is None:
        return bands
    return grid.dataset({"sunlit": bands.sunlit, "shadow_class": bands.shadow_class,
                         "fraction": bands.fraction},
                        {"transmissivity": trees["transmissivity"]})


def _nodata_marked(plane):
    """A result plane (NaN at nodata, as the run's sink gives it) as the
    library's tree calls take it: SS_NODATA at nodata."""
    return np.where(np.isnan(plane), np.float32(CONST["SS_NODATA"]), plane).astype(np.float32)


def _shadow_tree_bands(ctx, grid, opt, sun_azimuth, sun_elevation, sunlit, trees):
    """The shadow class and the beam's fraction over the solid verdict
    (NaN at nodata), as `skysweep shadow --canopy` makes bands
    4 and 5: ss_canopy_crossed on the sweep's lines, then ss_canopy_classes."""
    canopy = _canopy(ctx, grid, trees)
    crossed = np.empty(grid.shape, np.uint8)
    ctx.check(lib.ss_canopy_crossed(ctx.ptr, grid.ptr, canopy, opt, sun_azimuth, sun_elevation,
                                    ffi.from_buffer("unsigned char[]", crossed)))
    klass, fraction = grid.new_plane(), grid.new_plane()
    lib.ss_canopy_classes(canopy, klass.size, ffi.from_buffer("float[]", _nodata_marked(sunlit)),
                          ffi.from_buffer("unsigned char[]", crossed), out_buffer(klass),
                          out_buffer(fraction))
    return klass, fraction


def _sunlit(ctx, grid, opt, sun_azimuth, sun_elevation, out, kw):
    """shadow's sunlit plane: the registry's run, its sunlit rows, for one
    sun on every cell (an array's grid north is true north)."""
    @ffi.callback("ss_status(ss_ctx *, int, int, int, ss_sun_step *, void *)",
                  error=lib.SS_ERR_INTERNAL)
    def sun_rows(c, index, row0, n_rows, step, user):
        ffi.memmove(step, bytes(ffi.sizeof("ss_sun_step")), ffi.sizeof("ss_sun_step"))
        step.azimuth_deg = step.grid_azimuth_deg = sun_azimuth
        step.elevation_deg = step.apparent_elevation_deg = sun_elevation
        return lib.SS_OK

    cost = _product_cost("shadow", None, column_bytes=lib.ss_horizon_column_bytes(),
                         hull_lines=1, marches=True)
    sun = ffi.new("ss_product_sun *", {"n_steps": 1, "sun_rows": sun_rows})
    _run(ctx, grid, opt, "shadow", None, {(0, CONST["SS_OUT_SUNLIT"]): out}, kw, cost=cost,
         sun=sun)


def _shade(dem, cell_size, nodata, kw, given, radius=None):
    """gdaldem's hillshade or RVT's VAT blend (1..255), as `skysweep
    hillshade` computes it: the library's options from its hillshade table
    (ss_hillshade_params_options), the planner asked for what they sweep,
    and the registry's hillshade run. radius (metres)
    gives the blend's radius in the table's cells (the library measures
    them with the cells' geometric mean size, as here)."""
    ctx, grid = _begin(dem, cell_size, nodata, kw, SWEEP_OPTIONS)
    cell_m = math.sqrt(grid.cell_size[0] * grid.cell_size[1])
    if radius is not None:
        given = dict(given, blend_radius=_checked("svf", "radius", radius) / cell_m)
    params = _params("hillshade", "hillshade", given)
    shading = ffi.new("ss_hillshade_options *")
    lib.ss_hillshade_params_options(params, cell_m, shading)
    opt = _sweep(ctx, grid, "hillshade", params, kw)
    out = grid.new_plane()
    sweeps = params.blend or params.cast_shadows or params.sky_view > 0
    # The sky layers by each cell's own ray hold the heights whole before
    # the cast shadows' march holds them (marches counts those).
    sky_held = (params.sky_view > 0 or params.blend) and sky_rays(opt) and not (
        params.cast_shadows and opt.box_shadows == lib.SS_BOX_SHADOWS_MARCH)
    cost = _product_cost("hillshade", params, cell_m=cell_m,
                         column_bytes=lib.ss_horizon_column_bytes() if sweeps else 0.0,
                         hull_lines=None if sweeps else 1, marches=bool(params.cast_shadows),
                         grid_cell_bytes=4.0 if sky_held else 0.0)
    _run(ctx, grid, opt, "hillshade", params, {CONST["SS_OUT_SHADE"]: out}, kw, cost=cost)
    return grid, opt, out, shading.radius_m


def hillshade(dem, cell_size=None, *, sun_azimuth=default("hillshade", "az"),
              sun_elevation=default("hillshade", "alt"), z=default("hillshade", "z"),
              alg=default("hillshade", "alg"), multidirectional=False, cast_shadows=False,
              sky_view=default("hillshade", "sky-view"), nodata=None, name="hillshade",
              az=None, alt=None, **kw):
    """Hillshade as gdaldem computes it (1..255), or gdaldem's multidirectional blend.

    Parameters
    ----------
    {dem}
    sun_azimuth : float, default 315
        The light's azimuth, degrees clockwise from north (gdaldem's and the CLI's -az).
    sun_elevation : float, default 45
        The light's elevation, degrees above the horizontal (gdaldem's -alt).
    z : float, default 1
        Vertical exaggeration: heights (metres) times z (a factor, not a length).
    alg : {{"Horn", "ZevenbergenThorne"}}, default "Horn"
        The slope's algorithm, as gdaldem's -alg.
    multidirectional : bool, default False
        gdaldem's multidirectional blend instead of one light.
    cast_shadows : bool, default False
        Cells in the light's cast shadows (an exact sweep along it) take 1.
    sky_view : float, default 0
        A weight W in 0..1 blending in (1 - W) shade + W (1 + 254 SVF), geometric SVF
        over `directions`.
    {nodata}
    {name}
    az, alt : float, default None
        The former names of sun_azimuth and sun_elevation (gdaldem's), kept as aliases;
        giving a parameter under both names is a TypeError.

    Returns
    -------
    numpy.ndarray or xarray.DataArray
        float32 shade, 1..255 before the CLI's Byte rounding (np.rint gives the file's
        bytes), NaN where the DEM has no height.

    {raises}
    """
    sun_azimuth = _renamed("hillshade", "sun_azimuth", sun_azimuth,
                           hillshade.__kwdefaults__["sun_azimuth"], "az", az)
    sun_elevation = _renamed("hillshade", "sun_elevation", sun_elevation,
                             hillshade.__kwdefaults__["sun_elevation"], "alt", alt)
    grid, _, out, _ = _shade(dem, cell_size, nodata, kw,
                          {"az": sun_azimuth, "alt": sun_elevation, "z": z, "alg": alg,
                           "multidirectional": multidirectional, "cast_shadows": cast_shadows,
                           "sky_view": sky_view})
    return grid.finish(out, name, {"long_name": "hillshade", "units": "1",
                                   "sun_azimuth": _value("hillshade", "az", sun_azimuth),
                                   "sun_elevation": _value("hillshade", "alt", sun_elevation)})


def sun_incidence(dem, cell_size=None, *, sun_azimuth, sun_elevation, nodata=None,
                  name="cos_incidence", device=None):
    """Cosine of the angle between the sun and each cell's surface normal (Horn's gradient).

    Parameters
    ----------
    {dem}
    sun_azimuth : float
        Degrees clockwise from north.
    sun_elevation : float
        Degrees above the horizontal.
    {nodata}
    {name}
    device : str, default None
        None (SKYSWEEP_DEVICE, else "auto"), "reference" (the C twin) or a device as
        --device names it.

    Returns
    -------
    numpy.ndarray or xarray.DataArray
        float32 cosines, <= 0 where the cell faces away from the sun, NaN where the DEM
        has no height.

    {raises}
    """
    ctx, grid = _begin(dem, cell_size, nodata, {"device": device}, (), bands=False)
    out = grid.new_plane()
    ctx.call(lib.ss_sun_incidence, grid.ptr, _checked("shadow", "sun_azimuth", sun_azimuth),
             _checked("shadow", "sun_elevation", sun_elevation), ffi.NULL, ffi.NULL,
             out_buffer(out))
    return grid.finish(out, name, {"long_name": "cosine of the sun's incidence",
                                   "units": "1"})


def vat(dem, cell_size=None, *, radius=None, nodata=None, name="vat", blend_radius=None, **kw):
    """RVT's VAT relief blend (Kokalj & Somrak 2019), 0..1 (1 = white).

    gdaldem's hillshade at 315/35 degrees, Horn's slope, and SVF and positive
    openness from horizons within `radius`, as `skysweep hillshade --blend
    vat` computes it (its file holds 1 + 254 times this, rounded).

    Parameters
    ----------
    {dem}
    radius : float, default None
        Metres, as svf's and openness's radius; 0: unlimited; None: RVT's 10 cells
        (the CLI's --blend-radius default), in metres of the DEM's cells.
    {nodata}
    {name}
    blend_radius : float, default None
        The former parameter: the radius in cells, as the CLI's --blend-radius; giving
        it with radius is a TypeError.

    Returns
    -------
    numpy.ndarray or xarray.DataArray
        float32 0..1, shaped like the DEM, NaN where it has no height.

    {raises}
    """
    if radius is not None and blend_radius is not None:
        raise TypeError("vat() got both radius (metres) and its former blend_radius (cells): "
                        "give one")
    grid, opt, out, radius_m = _shade(dem, cell_size, nodata, kw,
                            {"blend": "vat", "blend_radius": blend_radius}, radius)
    out -= np.float32(1.0)  # NaN at nodata already: in place, no copies
    out /= np.float32(254.0)
    return grid.finish(out, name, {"long_name": "VAT relief blend", "units": "1",
                                   "radius": radius_m, "directions": opt.directions})


#: The products plan() plans: the registry's whose plan needs no time steps
#: or weather (insolation's does).
_PLANNED = tuple(name for name, p in PRODUCTS.items()
                 if p.plans_as != lib.SS_PLAN_INSOLATION)


def plan(dem, cell_size=None, *, product="svf", definition=default("svf", "definition"),
         nodata=None, **kw):
    """What a run of `product` would simulate on this DEM, and why.

    Parameters
    ----------
    {dem}
    product : {{"horizon", "svf", "openness", "hillshade", "shadow"}}, default "svf"
        The product to plan (the library's products but insolation).
    definition : {{"geometric", "radiative", "horizontal"}}, default "geometric"
        The SVF definition (for product "svf").
    {nodata}

    Returns
    -------
    dict
        The planner's decisions as `skysweep COMMAND --plan --plan-format json` prints
        them: directions, sweeps, estimated_seconds, device, and "effects", each with
        its on/off, reason and the error it allows.

    {raises}
    """
    import json
    if product not in _PLANNED:
        raise ValueError(f"product must be one of {', '.join(_PLANNED)}, not {product!r}")
    ctx, grid = _begin(dem, cell_size, nodata, kw, SWEEP_OPTIONS, bands=False)
    table = PRODUCTS[product].own_table
    params = None if table == ffi.NULL else _params(
        ffi.string(table).decode(), product, {"definition": definition} if product == "svf" else {})
    _, made = _sweep(ctx, grid, product, params, kw, with_plan=True)
    size = lib.ss_plan_format(made, 1, ffi.NULL, 0) + 1
    text = ffi.new("char[]", size)
    lib.ss_plan_format(made, 1, text, size)
    return json.loads(ffi.string(text).decode())


def _numpydoc(function, **snippets):
    """The function's docstring, dedented, with the shared sections filled in."""
    function.__doc__ = inspect.cleandoc(function.__doc__).format(
        dem=_DEM_PARAMETERS, nodata=_NODATA_PARAMETER, raises=_RAISES,
        name=_name_parameter(inspect.signature(function).parameters.get(
            "name", inspect.Parameter("name", inspect.Parameter.KEYWORD_ONLY)).default),
        **snippets)


_MEMORY_ENTRY = """memory : int, float or str, default None
    A budget for the call's working memory: bytes, or a size as --memory takes it ("512M",
    "4G"; k, M, G, T are powers of 1024). The call then runs in bands of rows that the
    library's memory planner sizes, reading the DEM a band at a time, so that the process's
    peak resident memory stays within what it held when called, plus the result, plus the
    budget. The result equals the whole grid's (up to the order of float sums); "auto"
    lines are interpolated (the DEM is not searched for walls). None: the whole grid at
    once. OutOfMemory (a MemoryError) where not one band fits, naming the least budget."""


def _doc_options(function, command, names, memory=True):
    """The shared options the function takes through **kw, from the table:
    entries at the end of its docstring's Parameters section, and keyword
    parameters with the table's defaults in its signature (inspect.signature,
    help()); memory= for a call that runs in bands."""
    entries, parameters = [], []
    for name in names:
        entry = option(command, name.replace("_", "-"))
        what = ("{" + ", ".join(f'"{c}"' for c in entry["choices"]) + "}"
                if entry["type"] == "choice" else
                {"int": "int", "double": "float"}.get(entry["type"], "str"))
        value = default(command, name.replace("_", "-"))
        entries.append(f"{name} : {what}, default {value!r}\n    {entry['help']}")
        parameters.append(inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=value))
    entries.append('device : str, default None\n    None (SKYSWEEP_DEVICE, else "auto": the '
                   'plan\'s choice), "reference" (the C twin) or a device as --device names it.')
    entries.append("progress : bool or callable, default None\n    None, True (tqdm or text) "
                   "or callable(fraction, message); returning False cancels.")
    extra = ("device", "progress")
    if memory:
        entries.append(_MEMORY_ENTRY)
        extra += ("memory",)
    parameters += [inspect.Parameter(n, inspect.Parameter.KEYWORD_ONLY, default=None)
                   for n in extra]
    doc = function.__doc__
    at = doc.index("\nReturns\n-------")
    function.__doc__ = doc[:at].rstrip("\n") + "\n" + "\n".join(entries) + "\n" + doc[at:]
    own = [p for p in inspect.signature(function).parameters.values()
           if p.kind != inspect.Parameter.VAR_KEYWORD]
    function.__signature__ = inspect.signature(function).replace(parameters=own + parameters)


for _f in (svf, openness, horizon, shadow, hillshade, sun_incidence, vat, plan):
    _numpydoc(_f)
for _f, _c in ((svf, "svf"), (openness, "openness"), (horizon, "horizon"), (shadow, "shadow"),
               (hillshade, "hillshade"), (vat, "hillshade")):
    _doc_options(_f, _c, SWEEP_OPTIONS)
_doc_options(plan, "svf", SWEEP_OPTIONS, memory=False)


def _array_call(name):
    """The array call of a registry product that has a run call and no call
    written for it, from its entry alone: its own table's parameters and the
    sweep's as keywords (the CLI's names and defaults), planned as the CLI
    plans it (_sweep), run whole or in bands within memory= by its run call.
    It returns its first output: a 2-D array for one band (a DataArray for
    a DataArray DEM), else bands x rows x columns."""
    product = PRODUCTS[name]
    table = None if product.own_table == ffi.NULL else ffi.string(product.own_table).decode()
    own = set()
    if table is not None:
        entries = lib.ss_param_table_named(table.encode()).params
        k = 0
        while entries[k].name != ffi.NULL:
            own.add(ffi.string(entries[k].name).decode().replace("-", "_"))
            k += 1
    out = product.outputs[0]

    def call(dem, cell_size=None, *, nodata=None, **kw):
        given = {k: kw.pop(k) for k in list(kw) if k in own}
        ctx, grid = _begin(dem, cell_size, nodata, kw, SWEEP_OPTIONS)
        params = None if table is None else _params(table, name, given)
        opt = _sweep(ctx, grid, name, params, kw)
        bands = out.bands or opt.directions
        result = np.empty((bands, *grid.shape) if bands > 1 else grid.shape, np.float32)
        _run(ctx, grid, opt, name, params, {0: result}, kw)
        if bands > 1:
            return result
        return grid.wrap(result, name, {"long_name": ffi.string(out.band_names).decode(),
                                        "units": ffi.string(out.unit).decode(),
                                        "directions": opt.directions})

    call.__name__ = call.__qualname__ = name
    call.__doc__ = (f"{ffi.string(product.title).decode()}: "
                    f"{ffi.string(product.description).decode()}\n\nKeywords: the "
                    f"parameters of `skysweep {name}` ({', '.join(sorted(own)) or 'none'} and "
                    "the sweep's), nodata=, memory=, device=, progress=. Generated from the "
                    "library's registry (skysweep_products.h).")
    return call


#: The array calls generated for the registry's products that have a run
#: call and none written above (a product added to the registry alone). A
#: product of the "Sun" group runs with its steps' suns, which only a call
#: written for it gives (shadow above, insolation in insolation.py).
ARRAY_CALLS = {name: _array_call(name) for name, p in PRODUCTS.items()
               if p.run != ffi.NULL and name not in globals() and
               ffi.string(p.group) != b"Sun"}
