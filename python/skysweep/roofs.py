"""`skysweep roofs` from Python: the solar cadastre as records.

The call runs the command line (as the file calls do) into a GeoPackage and
reads every layer it wrote back as GeoJSON-like features, which
``geopandas.GeoDataFrame.from_features`` and pandas take. The GeoPackage is
read with the standard library (it is SQLite; its geometries are WKB behind a
small header), so that neither GDAL nor geopandas is needed."""
import os
import pathlib
import sqlite3
import struct
import tempfile
from typing import NamedTuple

from .files import run


class Crs(NamedTuple):
    """A layer's coordinate reference system, as gpkg_spatial_ref_sys
    declares it."""
    srs_id: int
    name: str
    organization: str
    code: int
    wkt: str

    def to_string(self):
        """"EPSG:32632" where an authority names it, else its WKT: what
        geopandas' and pyproj's crs= take."""
        if self.organization and self.code is not None and self.code > 0:
            return f"{self.organization.upper()}:{self.code}"
        return self.wkt

    __str__ = to_string


class Roofs:
    """The layers of a roofs GeoPackage: ``result.roof_planes`` (or
    ``result["roof_planes"]``) is a list of Feature dicts; ``layers`` maps
    every layer's name to its features, in the GeoPackage's order; ``crs``
    maps it to its Crs; ``path`` is the GeoPackage (None where it was a
    temporary one, removed since)."""

    def __init__(self, layers, crs, path):
        self.layers = layers
        self.crs = crs
        self.path = path

    def __getitem__(self, layer):
        return self.layers[layer]

    def __getattr__(self, layer):
        layers = self.__dict__.get("layers", {})
        if layer in layers:
            return layers[layer]
        raise AttributeError(f"no layer {layer!r} (the GeoPackage has: {', '.join(layers)})")

    def __dir__(self):
        return sorted(set(super().__dir__()) | set(self.layers))

    def __repr__(self):
        counts = ", ".join(f"{name}: {len(f)}" for name, f in self.layers.items())
        return f"<skysweep.Roofs {counts}>"

    def to_pandas(self, layer):
        """The layer's properties as a pandas DataFrame, one row per feature,
        indexed by the feature id (needs pandas)."""
        import pandas as pd
        features = self.layers[layer]
        return pd.DataFrame([f["properties"] for f in features],
                            index=pd.Index([f["id"] for f in features], name="fid"))


def roofs(dsm, buildings, weather=None, out=None, *, progress=None, **options):
    """Runs ``skysweep roofs`` and returns its layers as records.

    Parameters
    ----------
    dsm : str, os.PathLike or list of them
        The DSM (a list of tiles: a mosaic).
    buildings : str or os.PathLike
        The footprints (--buildings): any vector source OGR reads.
    weather : str or os.PathLike, optional
        The weather records (--weather); None: a clear sky, hourly over
        ``time`` or a year (doc/roofs.md).
    out : str or os.PathLike, optional
        The GeoPackage to write and keep; None: a temporary one, removed
        once read.
    progress : bool or callable, default None
        As for the file calls.
    **options
        The command's other options, ``-`` written ``_`` (``min_area=10``,
        ``csv="planes.csv"``, ``time="2018-01-10T00:00Z/P1D"``).

    Returns
    -------
    Roofs
        One list of Feature dicts per layer (``.buildings``,
        ``.roof_planes``, ...), their CRS, and ``to_pandas(layer)``.

    Raises
    ------
    TypeError
        An option the command does not have, or a value of the wrong kind.
    SkysweepError
        The command's failure, of the class of its exit status (InputError
        for a footprints file that cannot be read, ...), with its one-line
        message.
    """
    inputs = [dsm] if isinstance(dsm, (str, os.PathLike)) else list(dsm)
    if out is not None:
        run("roofs", *inputs, out, progress=progress, buildings=buildings, weather=weather,
            **options)
        return Roofs(*read_geopackage(out), out)
    with tempfile.TemporaryDirectory(prefix="skysweep-roofs-") as folder:
        path = pathlib.Path(folder) / "roofs.gpkg"
        run("roofs", *inputs, path, progress=progress, buildings=buildings, weather=weather,
            **options)
        return Roofs(*read_geopackage(path), None)


def read_geopackage(path):
    """({layer: [Feature, ...]}, {layer: Crs}) for every features or
    attributes table of a GeoPackage, in gpkg_contents' order."""
    # Read-only, so that reading never changes (or creates) the file.
    uri = pathlib.Path(os.fspath(path)).resolve().as_uri() + "?mode=ro"
    with sqlite3.connect(uri, uri=True) as db:
        contents = db.execute("SELECT c.table_name, g.column_name, s.srs_id, s.srs_name, "
                              "s.organization, s.organization_coordsys_id, s.definition "
                              "FROM gpkg_contents c "
                              "LEFT JOIN gpkg_geometry_columns g ON g.table_name = c.table_name "
                              "LEFT JOIN gpkg_spatial_ref_sys s ON s.srs_id = c.srs_id "
                              "WHERE c.data_type IN ('features', 'attributes') "
                              "ORDER BY c.rowid").fetchall()
        layers, crs = {}, {}
        for table, geometry, srs_id, name, organization, code, wkt in contents:
            layers[table] = _features(db, table, geometry)
            if srs_id is not None:
                crs[table] = Crs(srs_id, name, organization, code, wkt)
    return layers, crs


def _quoted(name):
    return '"' + name.replace('"', '""') + '"'


def _features(db, table, geometry):
    columns = db.execute(f"PRAGMA table_info({_quoted(table)})").fetchall()
    key = next((c[1] for c in columns if c[5]), None)  # the INTEGER PRIMARY KEY: the fid
    fields = [(c[1], c[2].upper()) for c in columns if c[1] not in (key, geometry)]
    selected = [key or "rowid", geometry or "NULL"] + [name for name, _ in fields]
    rows = db.execute(f"SELECT {', '.join(_quoted(c) if c != 'NULL' else c for c in selected)} "
                      f"FROM {_quoted(table)} ORDER BY 1")
    features = []
    for fid, blob, *values in rows:
        properties = {name: (bool(v) if kind == "BOOLEAN" and v is not None else v)
                      for (name, kind), v in zip(fields, values)}
        features.append({"type": "Feature", "id": fid,
                         "geometry": None if blob is None else geometry_of(blob),
                         "properties": properties})
    return features


#: Bytes of the envelope by the header's envelope indicator (flags bits 1-3).
_ENVELOPE_BYTES = {0: 0, 1: 32, 2: 48, 3: 48, 4: 64}


def geometry_of(blob):
    """A GeoPackage geometry blob as a GeoJSON geometry dict (None where it
    is empty)."""
    blob = bytes(blob)
    if blob[:2] != b"GP":
        raise ValueError("not a GeoPackage geometry (no 'GP' magic)")
    flags = blob[3]
    if flags & 0x10:  # the empty geometry
        return None
    envelope = _ENVELOPE_BYTES.get((flags >> 1) & 7)
    if envelope is None:
        raise ValueError(f"a GeoPackage geometry with an invalid envelope indicator ({flags})")
    geometry, _ = _wkb(memoryview(blob)[8 + envelope:], 0)
    return geometry


_GEOJSON_TYPES = {1: "Point", 2: "LineString", 3: "Polygon", 4: "MultiPoint",
                  5: "MultiLineString", 6: "MultiPolygon", 7: "GeometryCollection"}


def _wkb(data, at):
    """(GeoJSON geometry, offset after it) of the WKB at data[at:]: ISO and
    extended (flag bits) Z and M codes both."""
    order = "<" if data[at] == 1 else ">"
    (code,) = struct.unpack_from(order + "I", data, at + 1)
    at += 5
    dims = 2 + bool(code & 0x80000000) + bool(code & 0x40000000)
    code &= 0x0FFFFFFF
    dims += {1: 1, 2: 1, 3: 2}.get(code // 1000, 0)
    kind = _GEOJSON_TYPES.get(code % 1000)
    if kind is None:
        raise ValueError(f"a WKB geometry of type {code}, which GeoJSON has no type for")

    def count():
        nonlocal at
        (n,) = struct.unpack_from(order + "I", data, at)
        at += 4
        return n

    def points(n):
        nonlocal at
        values = struct.unpack_from(f"{order}{n * dims}d", data, at)
        at += 8 * n * dims
        return [list(values[i:i + dims]) for i in range(0, len(values), dims)]

    if kind == "Point":
        return {"type": kind, "coordinates": points(1)[0]}, at
    if kind == "LineString":
        return {"type": kind, "coordinates": points(count())}, at
    if kind == "Polygon":
        return {"type": kind, "coordinates": [points(count()) for _ in range(count())]}, at
    parts = []
    for _ in range(count()):
        part, at = _wkb(data, at)
        parts.append(part)
    if kind == "GeometryCollection":
        return {"type": kind, "geometries": parts}, at
    return {"type": kind, "coordinates": [p["coordinates"] for p in parts]}, at
