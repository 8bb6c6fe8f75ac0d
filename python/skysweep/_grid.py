"""numpy (and xarray) DEMs into library grids, and results back."""
import math

import numpy as np

from ._lib import CONST, ffi, lib


def _is_dataarray(obj):
    return type(obj).__name__ == "DataArray" and hasattr(obj, "dims") and hasattr(obj, "coords")


def _cell_size_of_dataarray(dem):
    """Cell sizes from a DataArray's last two coordinates (metres: a
    projected CRS), or None where they cannot be read."""
    sizes = []
    for dim in dem.dims[-1:-3:-1]:
        coord = dem.coords.get(dim)
        if coord is None or coord.size < 2:
            return None
        steps = np.diff(np.asarray(coord, dtype=np.float64))
        if not np.allclose(steps, steps[0], rtol=1e-6):
            return None
        sizes.append(abs(float(steps[0])))
    return tuple(sizes)


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
    NaN (or `nodata`) where there is no height."""

    def __init__(self, ctx, dem, cell_size=None, nodata=None):
        self.template = dem if _is_dataarray(dem) else None
        if self.template is not None:
            if cell_size is None:
                cell_size = _cell_size_of_dataarray(dem)
            dem = dem.values
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
            heights[heights == nodata] = np.nan
        self.ctx = ctx
        self.shape = heights.shape
        grid = ffi.new("ss_grid *")
        ctx.check(lib.ss_grid_alloc(ctx.ptr, grid, heights.shape[1], heights.shape[0], cx, cy))
        self._grid = ffi.gc(grid, lib.ss_grid_free)
        lib.ss_grid_set_heights(grid, ffi.from_buffer("double[]", heights), ffi.NULL)
        ctx.check(lib.ss_grid_check(ctx.ptr, grid, ffi.NULL))
        self.cell_size = (cx, cy)

    @property
    def ptr(self):
        return self._grid

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
