"""memory=: array calls run in bands of rows within a memory budget, as the
command line's --memory runs them (doc/python.md, "Memory").

The budget bounds the call's own working memory: the process's peak resident
memory stays within what it held when the call began, plus the arrays the call
returns, plus the budget. The library's one memory planner
(ss_memory_plan_make, doc/engine.md) sizes the bands from it, and the product
runs through the library's banded calls (ss_*_rows) with the caller's array as
the band source, read a band at a time, and a sink that writes the finished
rows into the result."""
import contextlib
import math
import re
import resource
import sys
import warnings

import numpy as np

from ._context import ArgumentError, OutOfMemory
from ._grid import Grid, _fill_extremes, _fill_warning, _Heights, _rejected_warning, _Rows
from ._lib import CONST, ffi, lib

_SIZE = re.compile(r"([0-9]+\.?[0-9]*(?:[eE][-+]?[0-9]+)?)([kMGT]?)")
_UNIT_BYTES = {"": 1.0, "k": 1024.0, "M": 1024.0 ** 2, "G": 1024.0 ** 3, "T": 1024.0 ** 4}
_MIB = 1048576.0


def parse_size(memory):
    """Bytes from memory=: a number of bytes (int or float), or a size as
    the command line's --memory takes it: a number with an optional k, M, G
    or T (powers of 1024), "512M", "4G". Raises ArgumentError for anything
    else, zero and negatives included."""
    if isinstance(memory, (bool, np.bool_)):
        raise TypeError(f"memory must be bytes or a size such as '512M', not {memory!r}")
    if isinstance(memory, str):
        m = _SIZE.fullmatch(memory.strip())
        value = float(m.group(1)) * _UNIT_BYTES[m.group(2)] if m else math.nan
    elif isinstance(memory, (int, float, np.integer, np.floating)):
        value = float(memory)
    else:
        raise TypeError(f"memory must be bytes or a size such as '512M', not {memory!r}")
    if not (math.isfinite(value) and value > 0):
        raise ArgumentError(f"memory expects bytes or a size such as 512M or 4G, not {memory!r}",
                            2)
    return value


def resident_bytes():
    """The process's resident memory now. /proc/self/statm's, as the
    command line measures it: the planner's baseline is what the process
    holds now, and getrusage gives only the peak so far, which an earlier
    call may have left far above it (bands would shrink for nothing). Where
    there is no /proc (macOS), that peak: an overestimate, so bands only
    get smaller."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * resource.getpagesize()
    except (OSError, IndexError, ValueError):
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        return float(peak) * (1 if sys.platform == "darwin" else 1024)


def peak_resident_bytes():
    """The process's peak resident memory so far: the kernel's VmHWM
    (/proc/self/status); 0 where there is none. Not getrusage's ru_maxrss,
    which in a child also keeps its parent's resident size at the fork."""
    try:
        with open("/proc/self/status") as f:
            return next((int(line.split()[1]) * 1024 for line in f
                         if line.startswith("VmHWM:")), 0)
    except (OSError, ValueError):
        return 0


class BandedGrid(Grid):
    """A DEM the library reads a band of rows at a time from the caller's
    array (not copied whole): each band's heights are masked and stored as
    Grid stores them (ss_grid_stored_height: relative to the first
    plausible height, rounded to the metre), so that bands give the whole
    grid's values bit for bit."""

    def __init__(self, ctx, dem, cell_size=None, nodata=None, start_resident=0.0):
        """start_resident: the process's resident memory when the call
        began, before its context (resident_bytes)."""
        a, masked, nodata_values, (cx, cy) = self._take(dem, cell_size, nodata, whole=False)
        self.ctx, self.shape, self.cell_size = ctx, a.shape, (cx, cy)
        self.start_resident = start_resident
        # A DataArray's or rasterio dataset's heights are read a window at a
        # time (_Rows): its reads and their GDAL cache within the budget too.
        self._reads = a if isinstance(a, _Rows) else None
        self._heights = _Heights(a, masked, nodata_values)
        self._fills = _fill_extremes(a)
        self._origin = ffi.new("double *", 0.0)
        with self.reading():
            self._scan(a)

    @property
    def cache_bytes(self):
        """The GDAL block cache its reads may hold (the plan counts it)."""
        return self._reads.cache_bytes if self._reads is not None else 0

    def reading(self):
        """The context a run reads the DEM in (_Rows.reading)."""
        return self._reads.reading() if self._reads is not None else contextlib.nullcontext()

    def _chunks(self, row0=0, row1=None):
        """(row, heights) of rows [row0, row1) a chunk of rows at a time."""
        row1 = self.shape[0] if row1 is None else row1
        for r in range(row0, row1, chunk_rows(self.shape[1])):
            yield r, self._band(r, min(r + chunk_rows(self.shape[1]), row1))

    def _band(self, row0, row1):
        heights = self._heights.rows(row0, row1)
        for fill in self._fills:
            heights[heights == fill] = np.nan
        return heights

    def _store(self, heights, out):
        """Heights (metres, float64) into out as ss_grid_stored_height stores
        them: relative to the origin in double, then rounded to float; NaN
        where not plausible."""
        out[...] = heights - self._origin[0]
        out[~(np.abs(heights) <= CONST["SS_Z_PLAUSIBLE_M"])] = np.nan

    def _check(self, row0, stored):
        """ss_grid_check on rows of stored heights, as Grid checks the whole:
        the first rows with the grid's sizes and cell sizes (a valid height
        put in where they have none: only the sizes are asked then), every
        row's heights against the origin; rows named from the DEM's first."""
        if row0 == 0 and not np.isfinite(stored).any():
            stored = np.zeros_like(stored)
        elif not np.isfinite(stored).any():
            return
        g = ffi.new("ss_grid *", {"width": self.shape[1], "height": stored.shape[0],
                                  "cell_x_m": self.cell_size[0], "cell_y_m": self.cell_size[1],
                                  "z_origin_m": self._origin[0],
                                  "z": ffi.from_buffer("float[]", stored)})
        status = lib.ss_grid_check(self.ctx.ptr, g, ffi.NULL)
        if status != lib.SS_OK:
            message = re.sub(r"row (\d+)", lambda m: f"row {int(m.group(1)) + row0}",
                             self.ctx.message())
            self.ctx.fail(status, message)

    def _scan(self, a):
        """One pass in chunks of rows (each read once): the stored zero, and
        the warnings and refusals Grid gives for the whole array (fills
        counted where no mask or nodata took the cell, as Grid counts them)."""
        found, filled, rejected, valid = False, dict.fromkeys(self._fills, 0), 0, 0
        step = chunk_rows(self.shape[1])
        for row0 in range(0, self.shape[0], step):
            heights = self._heights.rows(row0, min(row0 + step, self.shape[0]))
            for fill in filled:
                hit = heights == fill
                filled[fill] += np.count_nonzero(hit)
                heights[hit] = np.nan
            plausible = np.abs(heights) <= CONST["SS_Z_PLAUSIBLE_M"]
            rejected += np.count_nonzero(np.isfinite(heights) & ~plausible)
            valid += np.count_nonzero(plausible)
            if not found and plausible.any():
                self._origin[0] = np.rint(heights[plausible][0])  # nearbyint's
                found = True
            stored = np.empty(heights.shape, np.float32)
            self._store(heights, stored)
            self._check(row0, stored)
        for fill, count in filled.items():
            if count:
                warnings.warn(_fill_warning(count, fill, a.dtype), stacklevel=4)
        if rejected:
            warnings.warn(_rejected_warning(rejected), stacklevel=4)
        if not valid:
            self.ctx.fail(lib.SS_ERR_INPUT, "the DEM has no valid heights (every cell is nodata)")

    @property
    def ptr(self):
        """An ss_grid without heights (z NULL), for the planner: as for the
        command line's DEM read in bands, it is not searched for walls (lines
        "auto" is interpolated) nor for its highest horizon."""
        return ffi.new("ss_grid *", {"width": self.shape[1], "height": self.shape[0],
                                     "cell_x_m": self.cell_size[0],
                                     "cell_y_m": self.cell_size[1],
                                     "z_origin_m": self._origin[0]})

    def finish(self, plane, name=None, attrs=None):
        """As Grid's: the sink has written NaN at nodata already (the whole
        plane is not searched again, which would take a byte a cell)."""
        return self.wrap(plane, name, attrs)

    def source(self, band_rows=0):
        """The DEM as the row-wise calls take it: read band_rows rows at a
        time (0: the whole grid in one band) from the caller's array."""
        width = self.shape[1]
        failed = []

        @ffi.callback("ss_status(void *, int, int, float *)", error=lib.SS_ERR_INTERNAL,
                      onerror=lambda *e: failed.append(e))
        def read(user, row0, n_rows, z):
            band = np.frombuffer(ffi.buffer(z, 4 * n_rows * width), np.float32)
            band = band.reshape(n_rows, width)
            for r, heights in self._chunks(row0, row0 + n_rows):
                self._store(heights, band[r - row0:r - row0 + heights.shape[0]])
            return lib.SS_OK

        self._keep = (read, failed)  # the callback lives as long as the source
        return ffi.new("ss_source *", {"width": width, "height": self.shape[0],
                                       "cell_x_m": self.cell_size[0],
                                       "cell_y_m": self.cell_size[1],
                                       "z_origin_m": self._origin, "z": ffi.NULL,
                                       "read": read, "band_rows": band_rows})

    def raise_failure(self):
        """The read callback's own exception, if it raised one."""
        failed = self._keep[1]
        if failed:
            raise failed[0][1].with_traceback(failed[0][2])


#: Cells the front end converts at once (heights read, rows received): its
#: own temporaries (about 30 bytes a cell, 2 MiB) stay within the planner's
#: fixed 16 MiB allowance for what a run holds beside its bands.
CHUNK_CELLS = 65536


def chunk_rows(width):
    return max(1, CHUNK_CELLS // width)


class BandCost:
    """What a band of the product holds (the CLI's band_cost): bytes per
    cell, per column and hull line carried between bands, the lines handing
    hulls on, and the metres of terrain read beyond a band (radius walks).
    box_lines: the box lines per cell of those lines (None: the options').
    grid_cell_bytes: held per cell of the whole grid beside the bands.
    marches: its cast shadows are each cell's own ray on box lines with
    box_shadows 'march', which in bands holds the heights whole (a float a
    cell of the whole grid more, as the CLI's run_march_cell_bytes counts)."""

    def __init__(self, cell_bytes, column_bytes=0.0, hull_lines=None, halo_m=0.0,
                 box_lines=None, grid_cell_bytes=0.0, marches=False):
        self.cell_bytes, self.column_bytes = cell_bytes, column_bytes
        self.hull_lines, self.halo_m = hull_lines, halo_m
        self.box_lines, self.grid_cell_bytes, self.marches = box_lines, grid_cell_bytes, marches


def plan_bands(ctx, grid, opt, cost, memory, result_bytes):
    """Band rows for the call (0: the whole grid in one band) from
    ss_memory_plan_make, within `memory` bytes (parse_size's) of working
    memory on top of the process's resident memory when the call began
    (grid.start_resident) and the results' result_bytes. The context's device is
    opened before it plans, as the command line opens it, so that what it
    holds and the peak of its kernels' build count within the budget (on the
    first call of a context; later calls find it open). A budget too small
    for one band raises OutOfMemory naming the least memory= that would do."""
    held = grid.start_resident + result_bytes
    peak_before = peak_resident_bytes()
    ctx.device_name()
    peak = peak_resident_bytes()
    width, height = grid.shape[1], grid.shape[0]
    cx, cy = grid.cell_size
    cell_bytes = cost.cell_bytes + lib.ss_lines_extra_cell_bytes(opt.lines)
    halo_rows = 0
    if cost.halo_m > 0:
        cell_bytes += lib.ss_radius_extra_cell_bytes(cost.halo_m, cx, cy)
        halo_rows = min(math.ceil(cost.halo_m / cy), height)
    lines = cost.hull_lines if cost.hull_lines is not None else opt.directions
    if opt.lines == lib.SS_LINES_BOX:
        lines *= cost.box_lines if cost.box_lines is not None else opt.box_lines
    marched = (cost.marches and opt.lines == lib.SS_LINES_BOX
               and opt.box_shadows == lib.SS_BOX_SHADOWS_MARCH)
    need = ffi.new("ss_memory_need *", {
        # What the process holds now, the device included; never less than
        # when the call began (memory freed since is not this call's to use:
        # the least named stays the same from call to call).
        "budget_bytes": held + memory,
        "baseline_bytes": max(resident_bytes(), grid.start_resident) + result_bytes,
        # The device's set-up peak, where opening it raised the process's
        # peak; an earlier peak of the process is not this call's.
        "peak_bytes": peak if peak > peak_before else 0.0,
        "width": width, "height": height, "cell_bytes": cell_bytes,
        "whole_cell_bytes": cell_bytes, "column_bytes": cost.column_bytes,
        "hull_lines": max(lines, 1), "halo_rows": halo_rows,
        "grid_cell_bytes": cost.grid_cell_bytes + (4.0 if marched else 0.0),
        "cache_bytes": float(grid.cache_bytes)})
    plan = ffi.new("ss_memory_plan *")
    ctx.check(lib.ss_memory_plan_make(ctx.ptr, need, plan))
    if plan.band_rows < 0:
        # Whole MiB and 1 MiB more, as the CLI names it: what the process
        # holds moves by a few hundred KiB from call to call.
        least = math.ceil((plan.least_budget - held) / _MIB) + 1
        forget_plan(ctx)
        raise OutOfMemory(f"memory ({memory:.0f} bytes) is too small for this DEM and call: "
                          f"it needs at least memory='{least}M' (one band of {width} cells with "
                          "the hulls handed on and the device's buffers, besides the process's "
                          f"{held / _MIB:.0f} MiB with the results; doc/python.md)", 6)
    return plan.band_rows


def forget_plan(ctx):
    """Clears the plan the context keeps for its device's batch and cells,
    so that later calls on it without memory= size them as before."""
    lib.ss_memory_plan_make(ctx.ptr, ffi.new("ss_memory_need *"), ffi.new("ss_memory_plan *"))


def rows_sink(targets, width):
    """A sink (ss_rows_sink) writing finished rows into targets[output]
    (2-D planes) or targets[output][index] (cubes), or targets[output, index]
    (one band's plane), NaN at nodata. Returns the callback and a list that
    holds its own exception, if any."""
    failed = []
    nodata = np.float32(CONST["SS_NODATA"])

    @ffi.callback("ss_status(void *, int, int, int, int, const float *)",
                  error=lib.SS_ERR_INTERNAL, onerror=lambda *e: failed.append(e))
    def sink(user, output, index, row0, n_rows, values):
        plane = targets.get((output, index), targets.get(output))
        if plane is None:  # an output the call does not return
            return lib.SS_OK
        if plane.ndim == 3:
            plane = plane[index]
        given = np.frombuffer(ffi.buffer(values, 4 * n_rows * width),
                              np.float32).reshape(n_rows, width)
        step = chunk_rows(width)
        for r in range(0, n_rows, step):
            rows = plane[row0 + r:row0 + min(r + step, n_rows)]
            rows[...] = given[r:r + rows.shape[0]]
            rows[rows == nodata] = np.nan
        return lib.SS_OK

    return sink, failed


def run_banded(ctx, grid, opt, cost, memory, targets, run, progress=None):
    """Runs `run(source, sink)` (a library call returning a status, its
    context first) in the bands the planner gives, into targets (see
    rows_sink), NaN at nodata."""
    result_bytes = sum(t.nbytes for t in targets.values())
    rows = plan_bands(ctx, grid, opt, cost, memory, result_bytes)
    sink, failed = rows_sink(targets, grid.shape[1])
    try:
        with grid.reading():
            ctx.call(lambda c: run(c, grid.source(rows), sink), progress=progress)
    finally:
        forget_plan(ctx)
        grid.raise_failure()
        if failed:
            raise failed[0][1].with_traceback(failed[0][2])
