"""Horizon profiles of single sites, as `skysweep horizon --point` gives them
(doc/pv-horizons.md): exact along the sweep's own lines, without sweeping the
grid, at any position between cell centres and any height above the ground."""
import numpy as np

from ._context import context
from ._grid import Grid
from ._lib import default, ffi, lib
from .products import _numpydoc, _sweep_params, _value

_FIELDS = ("azimuth", "elevation", "distance", "cast_col", "cast_row", "cast_height")


def site_horizon(dem, cell_size=None, *, col, row, height=default("horizon", "height"),
                 step=default("horizon", "step"), curvature=default("horizon", "curvature"),
                 refraction=default("horizon", "refraction"),
                 earth_radius=default("horizon", "earth-radius"),
                 lines=default("horizon", "lines"), nodata=None, device=None):
    """Horizon profiles of sites, as `skysweep horizon --point` gives them.

    Parameters
    ----------
    {dem}
    col, row : float or array_like
        Cell-centre coordinates of the sites (the centre of cell (c, r) is col = c,
        row = r); scalars or equal-length arrays.
    height : float, default 0
        Metres above the ground.
    step : float, default 1
        Degrees of azimuth between directions, from north (grid north: an array has
        no place); must divide 360.
    curvature : {{"auto", "on", "off"}}, default "auto"
        As on the command line, curvature is on only where asked for ("on").
    refraction : float, default 0.13
        The refraction coefficient, with curvature on.
    earth_radius : float, default None
        Metres, with curvature on; None: the earth's mean radius.
    lines : {{"auto", "interpolated", "digital", "box"}}, default "auto"
        The sweep's lines; "auto": interpolated.
    {nodata}
    device : str, default None
        None (SKYSWEEP_DEVICE, else "auto"), "reference" (the C twin) or a device as
        --device names it.

    Returns
    -------
    dict of numpy.ndarray
        One row per site (a single site: 1-D): ``azimuth`` and ``elevation``
        (degrees; -90 where no terrain lies ahead inside the grid), ``distance``
        (metres, 0: none), ``cast_col``, ``cast_row`` (the casting point; NaN: none)
        and ``cast_height`` (its ground height, metres), and ``ground_height`` (per
        site, metres).

    {raises}
    """
    ctx = context(device)
    grid = Grid(ctx, dem, cell_size, nodata)
    step = _value("horizon", "step", step)
    height = _value("horizon", "height", height)
    n = 360.0 / step
    if abs(n - round(n)) > 1e-9 * n:
        raise ValueError(f"step must divide 360 degrees into a whole number of directions, "
                         f"not {step!r}")
    # The library's options for the sweep's parameters, as the CLI's --point
    # takes them (ss_sweep_params_options), with the step's directions from north.
    sweep = _sweep_params("horizon", {"lines": lines, "curvature": curvature,
                                      "refraction": refraction, "earth_radius": earth_radius})
    opt = ffi.new("ss_sweep_options *")
    lib.ss_sweep_params_options(sweep, ffi.NULL, opt)
    opt.directions = int(round(n))
    opt.offset_deg = 0.0
    ctx.check(lib.ss_sweep_options_check(ctx.ptr, opt))
    cols, rows = np.broadcast_arrays(np.asarray(col, np.float64), np.asarray(row, np.float64))
    single = cols.ndim == 0
    cols, rows = np.atleast_1d(cols).ravel(), np.atleast_1d(rows).ravel()
    pg_out = ffi.new("ss_point_grid **")
    ctx.check(lib.ss_point_grid_new(ctx.ptr, grid.ptr, pg_out))
    pg = ffi.gc(pg_out[0], lib.ss_point_grid_free)
    d = opt.directions
    out = {k: np.empty((cols.size, d)) for k in _FIELDS}
    ground = np.empty(cols.size)
    result = ffi.new("ss_point_horizon_result[]", d)
    site = ffi.new("ss_point_site *")
    g = ffi.new("double *")
    for i, (c, r) in enumerate(zip(cols, rows)):
        site.col, site.row = float(c), float(r)
        site.observer_height_m = height
        site.grid_north_deg = 0.0
        ctx.check(lib.ss_point_ground_height(ctx.ptr, pg, site.col, site.row, g))
        ground[i] = g[0]
        ctx.check(lib.ss_point_horizon(ctx.ptr, pg, opt, site, result))
        for j in range(d):
            out["azimuth"][i, j] = result[j].azimuth_deg
            out["elevation"][i, j] = result[j].elevation_deg
            out["distance"][i, j] = result[j].distance_m
            out["cast_col"][i, j] = result[j].cast_col
            out["cast_row"][i, j] = result[j].cast_row
            out["cast_height"][i, j] = result[j].cast_height_m
    out["ground_height"] = ground
    if single:
        out = {k: v[0] for k, v in out.items()}
    return out


_numpydoc(site_horizon)
