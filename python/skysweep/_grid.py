"""numpy (and xarray) DEMs into library grids, and results back."""
import contextlib
import math
import sys
import warnings

import numpy as np

from ._lib import CONST, ffi, lib


def _is_dataarray(obj):
    return type(obj).__name__ == "DataArray" and hasattr(obj, "dims") and hasattr(obj, "coords")


_GEOGRAPHIC_DIMS = {"lat", "lon", "latitude", "longitude"}


def _rio(da):
    """rioxarray's accessor on a DataArray, or None where rioxarray is not
    installed (importing it registers `.rio`)."""
    try:
        import rioxarray  # noqa: F401
    except ImportError:
        return None
    return da.rio


def _declared_nodata(da):
    """Every nodata value a DataArray declares: rioxarray's rio.nodata and
    rio.encoded_nodata, and the CF _FillValue and missing_value of its attrs
    and encoding (a DEM opened without masked=True keeps its int16 -32768
    there, not as NaN)."""
    found = [da.attrs.get(k) for k in ("_FillValue", "missing_value", "nodata")]
    found += [da.encoding.get(k) for k in ("_FillValue", "missing_value")]
    rio = _rio(da)
    if rio is not None:
        # With an encoded nodata, rio.nodata is NaN (and fails on integers).
        found.append(rio.nodata if rio.encoded_nodata is None else rio.encoded_nodata)
    values = []
    for value in found:
        number = np.asarray(value if value is not None else np.nan)
        if number.ndim == 0 and number.dtype.kind in "iuf" and not np.isnan(number) and \
                float(number) not in values:
            values.append(float(number))
    return values


def _crs_of(da):
    """The DataArray's CRS as rioxarray reads it, whatever its grid-mapping
    coordinate is named; None without rioxarray or without a CRS."""
    rio = _rio(da)
    return None if rio is None else rio.crs


def _metres_or_refuse(crs):
    """Refuses a CRS whose coordinates are not metres: an array call has no
    geodesy (the library's cell sizes are metres; the command line measures
    a geographic grid's cells on the ellipsoid, the C API does not)."""
    if crs is None:
        return
    if not crs.is_projected:
        raise ValueError(f"the DataArray's CRS ({crs}) is geographic: its x and y are degrees, "
                         "not metres. Reproject it (da.rio.reproject(da.rio.estimate_utm_crs())), "
                         "give cell_size in metres, or use a file call (svf_file, ...), which "
                         "takes the cells' geodesic sizes")
    if abs(crs.linear_units_factor[1] - 1) > 1e-12:
        raise ValueError(f"the DataArray's CRS ({crs}) is in {crs.linear_units}, not metres: "
                         "reproject it, give cell_size in metres, or use a file call")


def _north_up(dem, cell_size, whole=True):
    """A DataArray's heights with rows north to south and columns west to
    east (an ascending y, as netCDF often has, is flipped, and flipped back
    in the results), and its cell sizes from regular x, y coordinates in
    metres where cell_size is None. Returns (values, cell_size, flips);
    values read whole, or (whole False) as _DataArrayRows."""
    if dem.ndim != 2:
        raise ValueError(f"the DEM must be a 2-D DataArray (y, x), not dims {dem.dims}")
    flips = []
    sizes = []
    for axis, dim in ((1, dem.dims[1]), (0, dem.dims[0])):
        # Not coords.get: for a dimension without coordinates it gives the
        # positions 0, 1, 2 ..., which would read as 1 m cells.
        coord = dem.coords[dim] if dim in dem.coords else None
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
        crs = _crs_of(dem)
        _metres_or_refuse(crs)
        if _GEOGRAPHIC_DIMS & {str(d).lower() for d in dem.dims}:
            raise ValueError(f"the DataArray's coordinates {dem.dims} look like degrees: give "
                             "cell_size in metres (or use a file call, which knows the CRS)")
        if None in sizes:
            raise TypeError("cell_size is needed: the DataArray has no regular x, y coordinates")
        cell_size = tuple(sizes)
        if crs is not None:
            x, y = (float(np.asarray(dem.coords[d])[[0, -1]].mean()) for d in dem.dims[::-1])
            cell_size = _ground_cell_sizes(crs.to_wkt(), x, y, cell_size)
    if not whole:
        return _DataArrayRows(dem, flips), cell_size, flips
    values = np.asarray(dem.values)
    for axis in flips:
        values = np.flip(values, axis)
    return values, cell_size, flips


#: The GDAL block cache (rasterio's own GDAL) a DEM read in windows may
#: hold: the command line's cap, 16 MiB, counted by the plan.
GDAL_CACHE_BYTES = 16 * 1048576


class _Rows:
    """A DEM read a window of rows at a time (rows[r0:r1], rows north to
    south: a numpy array), not whole: memory='s bands read it this way, so
    that the budget bounds the read too (doc/python.md, "Memory")."""
    ndim = 2
    #: The block cache its reads may hold (a file behind it): the plan counts it.
    cache_bytes = 0

    def reading(self):
        """While a run reads it: rasterio's GDAL block cache capped at
        cache_bytes (where a file is behind it), restored after."""
        if not self.cache_bytes:
            return contextlib.nullcontext()
        import rasterio
        return rasterio.Env(GDAL_CACHEMAX=self.cache_bytes)


class _DataArrayRows(_Rows):
    """A DataArray's heights, north up as _north_up gives them, read where a
    band asks: a file rioxarray opened lazily is read a window at a time."""

    def __init__(self, da, flips):
        self.da, self.flips = da, flips
        self.shape, self.dtype = da.shape, np.dtype(da.dtype)
        # Not in memory, with rasterio loaded: a file rioxarray opened lazily.
        if not getattr(da.variable, "_in_memory", True) and "rasterio" in sys.modules:
            self.cache_bytes = GDAL_CACHE_BYTES

    def __getitem__(self, rows):
        start, stop, _ = rows.indices(self.shape[0])
        if 0 in self.flips:
            start, stop = self.shape[0] - stop, self.shape[0] - start
        values = np.asarray(self.da[start:stop].values)
        for axis in self.flips:
            values = np.flip(values, axis)
        return values


class _RasterioRows(_Rows):
    """Band 1 of an open rasterio dataset, a window of rows at a time."""

    cache_bytes = GDAL_CACHE_BYTES

    def __init__(self, dataset):
        self.dataset = dataset
        self.shape, self.dtype = (dataset.height, dataset.width), np.dtype(dataset.dtypes[0])

    def __getitem__(self, rows):
        start, stop, _ = rows.indices(self.shape[0])
        return self.dataset.read(1, window=((start, max(start, stop)), (0, self.shape[1])))


#: Half the projected step (metres) over which a cell's ground size is measured.
_GROUND_STEP_M = 50.0


def _ground_cell_sizes(crs_wkt, x, y, sizes):
    """Ground sizes (metres on the ellipsoid) of cells `sizes` projected
    metres wide, at the projected point x, y (the grid's centre), as the
    command line measures them: a projection's scale factor makes projected
    metres longer or shorter than the ground's (UTM's 0.9996 at its central
    meridian). Projected sizes where pyproj (which rioxarray brings) is not
    installed, with a warning."""
    try:
        from pyproj import CRS, Transformer
    except ImportError:
        warnings.warn("pyproj is not installed: projected cell sizes are taken as ground "
                      "sizes, off by the projection's scale factor (pass cell_size)", stacklevel=4)
        return sizes
    crs = CRS.from_user_input(crs_wkt)
    to_lonlat = Transformer.from_crs(crs, crs.geodetic_crs, always_xy=True)
    geod = crs.get_geod()
    scales = []
    for ex, ey in ((1.0, 0.0), (0.0, 1.0)):
        lon, lat = to_lonlat.transform([x - ex * _GROUND_STEP_M, x + ex * _GROUND_STEP_M],
                                       [y - ey * _GROUND_STEP_M, y + ey * _GROUND_STEP_M])
        scales.append(geod.inv(lon[0], lat[0], lon[1], lat[1])[2] / (2 * _GROUND_STEP_M))
    return sizes[0] * scales[0], sizes[1] * scales[1]


def _is_rasterio_dataset(obj):
    return all(hasattr(obj, a) for a in ("read", "transform", "crs", "res", "nodata"))


def _from_rasterio(dataset, cell_size, nodata, whole=True):
    """Band 1 of an open rasterio dataset (read whole, or as _RasterioRows),
    its nodata, and its cell size where its CRS is projected in metres
    (rows must run north to south)."""
    if dataset.transform.b != 0 or dataset.transform.d != 0:
        raise ValueError("the dataset's grid is rotated: resample it north-up first")
    if dataset.transform.e > 0:
        raise ValueError("the dataset's rows run south to north: flip it first")
    if cell_size is None:
        crs = dataset.crs
        if crs is None or not crs.is_projected or abs(crs.linear_units_factor[1] - 1) > 1e-12:
            raise ValueError("the dataset's CRS is not projected in metres: give cell_size, or use "
                             "a file call, which knows the CRS")
        t = dataset.transform  # north-up: no rotation terms
        x, y = t.c + t.a * dataset.width / 2, t.f + t.e * dataset.height / 2
        cell_size = _ground_cell_sizes(crs.to_wkt(), x, y,
                                       (abs(dataset.res[0]), abs(dataset.res[1])))
    band = dataset.read(1) if whole else _RasterioRows(dataset)
    return band, cell_size, dataset.nodata if nodata is None else nodata


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


#: Heights no terrain has (the deepest sea floor is -10 935 m, the highest
#: peak 8 849 m): an integer type's extreme beyond them is a fill, not a height.
_EARTH_Z_RANGE_M = (-11000.0, 9000.0)


def _fill_extremes(a):
    """The extremes of an integer dtype that lie beyond any terrain (int16's
    -32768 and 32767, uint16's 65535): cells holding them are fills that
    nobody declared as nodata. Float32's lowest (-3.4e38) lies beyond
    SS_Z_PLAUSIBLE_M, which the library refuses itself."""
    if a.dtype.kind not in "iu":
        return []
    info = np.iinfo(a.dtype)
    return [v for v in (info.min, info.max)
            if not _EARTH_Z_RANGE_M[0] <= v <= _EARTH_Z_RANGE_M[1]]


def _mask_nodata(a, heights, nodata_values):
    """NaN in heights where a holds one of nodata_values, compared as the
    input holds it (a float32 -9999.9), where the input's dtype can hold it
    at all (-9999 is no uint8 value)."""
    for nodata in nodata_values:
        held = np.asarray(nodata).astype(a.dtype)
        if held == nodata or (a.dtype.kind == "f" and np.isfinite(nodata)):
            heights[a == held] = np.nan


#: Attributes that say where a DataArray lies, kept on its products.
_GEOREFERENCING_ATTRS = ("crs", "grid_mapping", "spatial_ref", "transform")


def _fill_warning(filled, fill, dtype):
    return (f"{filled} heights of {fill} ({dtype}'s {'lowest' if fill < 0 else 'highest'} "
            "value, beyond any terrain) are a fill, not terrain: taken as nodata (pass "
            "nodata= or a masked array to say so)")


def _rejected_warning(rejected):
    return (f"{rejected} heights beyond +-{CONST['SS_Z_PLAUSIBLE_M']:g} m are not terrain: "
            "taken as nodata")


class _Heights:
    """Heights in metres (float64, NaN at nodata) of rows of the caller's
    array, its mask and nodata values applied, as Grid reads them all."""

    def __init__(self, a, masked, nodata_values):
        self.a, self.masked, self.nodata_values = a, masked, nodata_values

    def rows(self, row0, row1):
        raw = self.a[row0:row1]  # read once (a window of a file, for _Rows)
        heights = np.array(raw, dtype=np.float64, order="C")
        if self.masked is not None:
            heights[self.masked[row0:row1]] = np.nan
        _mask_nodata(raw, heights, self.nodata_values)
        return heights


class Grid:
    """A DEM held by the library: heights in metres, rows north to south,
    NaN (or `nodata`) where there is no height. Taken from a numpy array (a
    masked array's masked cells are nodata), an xarray DataArray (the
    nodata it declares, rioxarray's or CF's, is nodata too), or an open
    rasterio dataset (band 1, its nodata)."""

    def __init__(self, ctx, dem, cell_size=None, nodata=None):
        a, masked, nodata_values, (cx, cy) = self._take(dem, cell_size, nodata)
        heights = _Heights(a, masked, nodata_values).rows(0, a.shape[0])
        for fill in _fill_extremes(a):
            filled = np.count_nonzero(heights == fill)
            if filled:
                warnings.warn(_fill_warning(filled, fill, a.dtype), stacklevel=3)
                heights[heights == fill] = np.nan
        self.ctx = ctx
        self.shape = heights.shape
        grid = ffi.new("ss_grid *")
        ctx.check(lib.ss_grid_alloc(ctx.ptr, grid, heights.shape[1], heights.shape[0], cx, cy))
        self._grid = ffi.gc(grid, lib.ss_grid_free)
        rejected = ffi.new("size_t *")
        lib.ss_grid_set_heights(grid, ffi.from_buffer("double[]", heights), rejected)
        if rejected[0]:
            warnings.warn(_rejected_warning(rejected[0]), stacklevel=3)
        ctx.check(lib.ss_grid_check(ctx.ptr, grid, ffi.NULL))
        self.cell_size = (cx, cy)

    def _take(self, dem, cell_size, nodata, whole=True):
        """The DEM as an array (not copied where it is one; a DataArray's or
        a rasterio dataset's read whole, or with whole False as _Rows), its
        mask, the nodata values it declares, and its cell sizes; sets
        template and flips."""
        self.template = dem if _is_dataarray(dem) else None
        self.flips = []
        nodata_values = [] if nodata is None else [nodata]
        masked = np.ma.getmaskarray(dem) if np.ma.isMaskedArray(dem) else None
        if self.template is not None:
            nodata_values += _declared_nodata(dem)
            dem, cell_size, self.flips = _north_up(dem, cell_size, whole)
        elif _is_rasterio_dataset(dem):
            dem, cell_size, nodata = _from_rasterio(dem, cell_size, nodata, whole)
            nodata_values = [] if nodata is None else [nodata]
        if cell_size is None:
            raise TypeError("cell_size is needed (metres, one number or (east-west, "
                            "north-south)) unless the DEM is a DataArray with regular x, y "
                            "coordinates in metres")
        cell = _cell_sizes(cell_size)
        a = (np.ma.getdata(dem) if masked is not None else
             dem if isinstance(dem, _Rows) else np.asarray(dem))
        if a.dtype.kind not in "iuf":
            raise TypeError(f"the DEM must hold real numbers (heights in metres), not dtype {a.dtype}")
        if a.ndim != 2:
            raise ValueError(f"the DEM must be a 2-D array (rows north to south), not {a.ndim}-D "
                             f"of shape {a.shape}")
        return a, masked, nodata_values, cell

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
        # The product's own attributes, not the DEM's (its long_name, range,
        # integer _FillValue), but for where the grid lies.
        kept = {k: v for k, v in self.template.attrs.items() if k in _GEOREFERENCING_ATTRS}
        out = xr.DataArray(values, dims=dims, coords=coords, name=name,
                           attrs=dict(kept, **(attrs or {})))
        # NaN where there is no height, written as the command line writes
        # it (rioxarray's masked convention: rio.nodata NaN, encoded SS_NODATA).
        out.encoding["_FillValue"] = np.float32(CONST["SS_NODATA"])
        crs = _crs_of(self.template)
        if crs is not None:  # under whatever name the DEM's grid mapping has
            rio = self.template.rio
            # In place: a copy of the result (rioxarray's default) would be a
            # peak beyond memory='s bound.
            out = out.rio.write_crs(crs, grid_mapping_name=rio.grid_mapping, inplace=True)
            out = out.rio.write_transform(rio.transform(), grid_mapping_name=rio.grid_mapping,
                                          inplace=True)
        return out


    def dataset(self, arrays, attrs=None):
        """DataArrays from wrap (one per output band group) as one xarray
        Dataset, with the DEM's CRS and transform as wrap writes them."""
        import xarray as xr
        out = xr.Dataset(arrays, attrs=attrs or {})
        crs = _crs_of(self.template)
        if crs is not None:
            rio = self.template.rio
            out = out.rio.write_crs(crs, grid_mapping_name=rio.grid_mapping)
            out = out.rio.write_transform(rio.transform(), grid_mapping_name=rio.grid_mapping)
        return out


def out_buffer(plane):
    return ffi.from_buffer("float[]", plane)
