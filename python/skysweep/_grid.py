"""numpy (and xarray) DEMs into library grids, and results back."""
import math
import warnings

import numpy as np

from ._lib import CONST, ffi, lib


def _is_dataarray(obj):
    return type(obj).__name__ == "DataArray" and hasattr(obj, "dims") and hasattr(obj, "coords")


_GEOGRAPHIC_DIMS = {"lat", "lon", "latitude", "longitude"}


def _north_up(dem, cell_size):
    """A DataArray's heights with rows north to south and columns west to
    east (an ascending y, as netCDF often has, is flipped, and flipped back
    in the results), and its cell sizes from regular x, y coordinates in
    metres where cell_size is None. Returns (values, cell_size, flips)."""
    if dem.ndim != 2:
        raise ValueError(f"the DEM must be a 2-D DataArray (y, x), not dims {dem.dims}")
    values = np.asarray(dem.values)
    flips = []
    sizes = []
    for axis, dim in ((1, dem.dims[1]), (0, dem.dims[0])):
        coord = dem.coords.get(dim)
        if coord is None or coord.size < 2:
            sizes.append(None)
            continue
        steps = np.diff(np.asarray(coord, dtype=np.float64))
        regular = np.allclose(steps, steps[0], rtol=1e-6) and steps[0] != 0
        sizes.append(abs(float(steps[0])) if regular else None)
        # Columns must run west to east (x rising), rows north to south (y falling).
        if regular and ((axis == 1 and steps[0] < 0) or (axis == 0 and steps[0] > 0)):
            flips.append(axis)
    if cell_size is None:
        if _GEOGRAPHIC_DIMS & {str(d).lower() for d in dem.dims}:
            raise ValueError(f"the DataArray's coordinates {dem.dims} look like degrees: give "
                             "cell_size in metres (or use a file call, which knows the CRS)")
        if None in sizes:
            raise TypeError("cell_size is needed: the DataArray has no regular x, y coordinates")
        cell_size = tuple(sizes)
    for axis in flips:
        values = np.flip(values, axis)
    return values, cell_size, flips


def _is_rasterio_dataset(obj):
    return all(hasattr(obj, a) for a in ("read", "transform", "crs", "res", "nodata"))


def _from_rasterio(dataset, cell_size, nodata):
    """Band 1 of an open rasterio dataset, its nodata, and its cell size
    where its CRS is projected in metres (rows must run north to south)."""
    if dataset.transform.b != 0 or dataset.transform.d != 0:
        raise ValueError("the dataset's grid is rotated: resample it north-up first")
    if dataset.transform.e > 0:
        raise ValueError("the dataset's rows run south to north: flip it first")
    if cell_size is None:
        crs = dataset.crs
        if crs is None or not crs.is_projected or abs(crs.linear_units_factor[1] - 1) > 1e-12:
            raise ValueError("the dataset's CRS is not projected in metres: give cell_size, or use "
                             "a file call, which knows the CRS")
        cell_size = (abs(dataset.res[0]), abs(dataset.res[1]))
    return dataset.read(1), cell_size, dataset.nodata if nodata is None else nodata


def _cell_sizes(cell_size):
    try:
        if np.ndim(cell_size) == 0:
            x = y = float(cell_size)
        else:
            x, y = (float(v) for v in cell_size)
    except (TypeError, ValueError):
        raise TypeError("cell_size must be metres, one number or (east-west, north-south), "
                        f"not {cell_size!r}") from None
    if not (math.isfinite(x) and math.isfinite(y) and x > 0 and y > 0):
        raise ValueError(f"cell_size must be positive metres, not {cell_size!r}")
    return x, y


class Grid:
    """A DEM held by the library: heights in metres, rows north to south,
    NaN (or `nodata`) where there is no height. Taken from a numpy array, an
    xarray DataArray, or an open rasterio dataset (band 1, its nodata)."""

    def __init__(self, ctx, dem, cell_size=None, nodata=None):
        self.template = dem if _is_dataarray(dem) else None
        self.flips = []
        if self.template is not None:
            dem, cell_size, self.flips = _north_up(dem, cell_size)
        elif _is_rasterio_dataset(dem):
            dem, cell_size, nodata = _from_rasterio(dem, cell_size, nodata)
        if cell_size is None:
            raise TypeError("cell_size is needed (metres, one number or (east-west, "
                            "north-south)) unless the DEM is a DataArray with regular x, y "
                            "coordinates in metres")
        cx, cy = _cell_sizes(cell_size)
        a = np.asarray(dem)
        if a.dtype.kind not in "iuf":
            raise TypeError(f"the DEM must hold real numbers (heights in metres), not dtype {a.dtype}")
        if a.ndim != 2:
            raise ValueError(f"the DEM must be a 2-D array (rows north to south), not {a.ndim}-D "
                             f"of shape {a.shape}")
        heights = np.array(a, dtype=np.float64, order="C")
        if nodata is not None:
            # Compared as the input holds it (a float32 -9999.9), where the
            # input's dtype can hold it at all (-9999 is no uint8 value).
            held = np.asarray(nodata).astype(a.dtype)
            if held == nodata or (a.dtype.kind == "f" and np.isfinite(nodata)):
                heights[a == held] = np.nan
        self.ctx = ctx
        self.shape = heights.shape
        grid = ffi.new("ss_grid *")
        ctx.check(lib.ss_grid_alloc(ctx.ptr, grid, heights.shape[1], heights.shape[0], cx, cy))
        self._grid = ffi.gc(grid, lib.ss_grid_free)
        rejected = ffi.new("size_t *")
        lib.ss_grid_set_heights(grid, ffi.from_buffer("double[]", heights), rejected)
        if rejected[0]:
            warnings.warn(f"{rejected[0]} heights beyond +-{CONST['SS_Z_PLAUSIBLE_M']:g} m are "
                          "not terrain: taken as nodata", stacklevel=3)
        ctx.check(lib.ss_grid_check(ctx.ptr, grid, ffi.NULL))
        self.cell_size = (cx, cy)

    @property
    def ptr(self):
        return self._grid

    def source(self):
        """The grid as the row-wise calls (ss_*_rows) take it: held whole,
        in one band. The grid must outlive it."""
        grid = self._grid
        return ffi.new("ss_source *", {"width": grid.width, "height": grid.height,
                                       "cell_x_m": grid.cell_x_m, "cell_y_m": grid.cell_y_m,
                                       "z_origin_m": ffi.addressof(grid[0], "z_origin_m"),
                                       "z": grid.z})

    def new_plane(self):
        return np.empty(self.shape, dtype=np.float32)

    def finish(self, plane, name=None, attrs=None):
        """A result plane with NaN at nodata (the library writes SS_NODATA),
        as a DataArray shaped like the input where the input was one."""
        plane[plane == np.float32(CONST["SS_NODATA"])] = np.nan
        return self.wrap(plane, name, attrs)

    def wrap(self, values, name=None, attrs=None, leading=None):
        if self.template is None:
            return values
        for axis in self.flips:  # back to the DataArray's own order
            values = np.flip(values, axis + values.ndim - 2)
        import xarray as xr
        dims = self.template.dims
        coords = {k: v for k, v in self.template.coords.items() if set(v.dims) <= set(dims)}
        if leading is not None:
            (lead_name, lead_values), = leading.items()
            dims = (lead_name,) + tuple(dims)
            coords[lead_name] = lead_values
        out = xr.DataArray(values, dims=dims, coords=coords, name=name,
                           attrs=dict(self.template.attrs))
        out.attrs.update(attrs or {})
        return out


def out_buffer(plane):
    return ffi.from_buffer("float[]", plane)
