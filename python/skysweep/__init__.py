"""skysweep: exact terrain horizons, sky-view factor, openness, shadows,
hillshade and the sun, over libskysweep.

Array calls take a DEM as a 2-D numpy array of heights in metres (rows north
to south; NaN or `nodata` where there is none) or an xarray DataArray, and
return arrays (DataArrays for DataArrays) with NaN at nodata. File calls
(`svf_file`, ...) run the command line on files and keep their georeferencing.
Conventions: azimuths in degrees clockwise from north, elevations in degrees
above the horizontal, distances in metres (doc/python.md).
"""
from ._context import (ArgumentError, Cancelled, Context, DeviceError, InputError,
                       InternalError, OutOfMemory, OutputError, SkysweepError)
from ._lib import BUILD, lib as _lib, ffi as _ffi
from .files import FILE_CALLS, run
from .products import (ARRAY_CALLS, Horizons, ShadowTrees, SvfTrees, hillshade, horizon,
                       openness, plan, shadow, sun_incidence, svf, vat)
from .insolation import insolation
from .roofs import Crs, Roofs, roofs
from .sites import site_horizon
from .sun import sun_position

globals().update(FILE_CALLS)
globals().update(ARRAY_CALLS)  # the registry's products without a call written for them

__version__ = _ffi.string(_lib.ss_version()).decode()

__all__ = ["svf", "SvfTrees", "openness", "horizon", "Horizons", "shadow", "ShadowTrees",
           "hillshade", "vat", "plan",
           "sun_incidence",
           "site_horizon", "sun_position", "insolation", "run", "Context", "SkysweepError", "ArgumentError",
           "InputError", "OutputError", "DeviceError", "OutOfMemory", "Cancelled",
           "InternalError"] + sorted(FILE_CALLS)
__all__ += ["roofs", "Roofs", "Crs"]
__all__ += sorted(ARRAY_CALLS)
