"""skysweep.roofs on the synthetic city of tests/data/make_city.sh: its records
are the GeoPackage's features (as GDAL counts and measures them) and the CSV's
rows; geopandas and pandas take them. Skips without GDAL's command-line tools,
which make the city."""
import csv
import pathlib
import re
import shutil
import sqlite3
import subprocess

import pytest

import skysweep
from skysweep.files import command_line

TOP = pathlib.Path(__file__).resolve().parents[2]
WEATHER = TOP / "samples" / "weather" / "pvgis_tmy_45N_8E.csv"
OPTIONS = dict(time="2018-01-10T00:00Z/P1D", device="reference", directions=8, min_irradiation=0)

pytestmark = pytest.mark.skipif(
    not all(shutil.which(t) for t in ("gdal_translate", "ogr2ogr", "ogrinfo")),
    reason="GDAL's command-line tools (gdal_translate, ogr2ogr, ogrinfo) make the city")


@pytest.fixture(scope="module")
def city(tmp_path_factory):
    """(folder, Roofs) of one run kept in city.gpkg, with its CSV."""
    folder = tmp_path_factory.mktemp("city")
    subprocess.run(["sh", str(TOP / "tests" / "data" / "make_city.sh"), str(folder)], check=True)
    result = skysweep.roofs(folder / "city.tif", folder / "footprints.geojson", WEATHER,
                            folder / "city.gpkg", csv=folder / "planes.csv", **OPTIONS)
    return folder, result


def ogr_values(path, sql):
    """The first column of each row an OGR SQL query returns (ogrinfo)."""
    text = subprocess.run(["ogrinfo", "-ro", "-q", "-dialect", "OGRSQL", "-sql", sql, str(path)],
                          capture_output=True, text=True, check=True).stdout
    return [float(v) for v in re.findall(r"^\s+\w+ \(\w+\) = (\S+)$", text, re.M)]


def shoelace(ring):
    return 0.5 * sum(x0 * y1 - x1 * y0 for (x0, y0, *_), (x1, y1, *_) in zip(ring, ring[1:]))


def planimetric_area(geometry):
    polygons = [geometry["coordinates"]] if geometry["type"] == "Polygon" \
        else geometry["coordinates"]
    # Holes wind against their shell: the sum of the rings' absolute areas
    # with the holes' taken away.
    return sum(abs(shoelace(p[0])) - sum(abs(shoelace(h)) for h in p[1:]) for p in polygons)


def test_every_layer_with_its_features_as_gdal_counts_them(city):
    folder, result = city
    assert {"buildings", "roof_planes"} <= set(result.layers)
    assert result.path == folder / "city.gpkg"
    for layer, features in result.layers.items():
        summary = subprocess.run(["ogrinfo", "-ro", "-so", str(folder / "city.gpkg"), layer],
                                 capture_output=True, text=True, check=True).stdout
        count = int(re.search(r"Feature Count: (\d+)", summary).group(1))
        assert len(features) == count > 0, layer
        assert features is getattr(result, layer) is result[layer]
        assert all(f["type"] == "Feature" and set(f) >= {"geometry", "properties"}
                   for f in features)


def test_properties_are_the_csv_rows(city):
    folder, result = city
    with open(folder / "planes.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    planes = [f["properties"] for f in result.roof_planes]
    assert len(rows) == len(planes) > 5
    for row, plane in zip(rows, planes):
        assert set(row) <= set(plane)
        for field, text in row.items():
            value = plane[field]
            if value is None:  # a NULL field (kwh_per_kwp of a plane without panels)
                assert text == "", field
            elif isinstance(value, (int, float)) and not isinstance(value, bool):
                assert value == pytest.approx(float(text), rel=1e-6, abs=1e-6), field
            else:
                assert str(value) == text, field


def test_geometries_have_gdal_areas(city):
    folder, result = city
    for layer in ("buildings", "roof_planes"):
        gdal = ogr_values(folder / "city.gpkg", f"SELECT OGR_GEOM_AREA FROM {layer}")
        ours = [planimetric_area(f["geometry"]) for f in result[layer] if f["geometry"]]
        assert len(ours) == len(gdal) > 0
        assert ours == pytest.approx(gdal, rel=1e-6)


def test_the_layers_crs_from_the_geopackage(city):
    folder, result = city
    crs = result.crs["roof_planes"]
    assert crs.to_string() == "EPSG:32632" and "UTM" in crs.wkt
    with sqlite3.connect(folder / "city.gpkg") as db:
        (srs_id,) = db.execute("SELECT srs_id FROM gpkg_geometry_columns "
                               "WHERE table_name = 'roof_planes'").fetchone()
    assert crs.srs_id == srs_id


def test_geopandas_takes_the_records(city):
    gpd = pytest.importorskip("geopandas")
    _, result = city
    frame = gpd.GeoDataFrame.from_features(result.roof_planes,
                                           crs=result.crs["roof_planes"].to_string())
    assert len(frame) == len(result.roof_planes) and frame.crs.to_epsg() == 32632
    assert frame.geometry.area.to_numpy() == pytest.approx(
        [planimetric_area(f["geometry"]) for f in result.roof_planes], rel=1e-9)


def test_pandas_takes_the_properties(city):
    pd = pytest.importorskip("pandas")
    _, result = city
    frame = result.to_pandas("buildings")
    assert isinstance(frame, pd.DataFrame) and len(frame) == len(result.buildings)
    assert list(frame["building_id"]) == [f["properties"]["building_id"]
                                          for f in result.buildings]


def test_a_temporary_geopackage_is_read_and_removed(city, tmp_path, monkeypatch):
    folder, kept = city
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    import tempfile
    monkeypatch.setattr(tempfile, "tempdir", None)
    result = skysweep.roofs(folder / "city.tif", folder / "footprints.geojson", WEATHER,
                            **OPTIONS)
    assert result.path is None and list(tmp_path.iterdir()) == []
    assert [f["properties"] for f in result.roof_planes] == \
        [f["properties"] for f in kept.roof_planes]


def test_missing_footprints_raise_the_cli_message(city, tmp_path):
    folder, _ = city
    args = [folder / "city.tif", tmp_path / "nothere.shp", WEATHER, tmp_path / "o.gpkg"]
    with pytest.raises(skysweep.InputError) as e:
        skysweep.roofs(*args, **OPTIONS)
    cli = subprocess.run([command_line(), "roofs", "-q", "--buildings", str(args[1]),
                          "--weather", str(WEATHER), "--time", OPTIONS["time"], str(args[0]),
                          str(tmp_path / "o.gpkg")], capture_output=True, text=True)
    assert e.value.status == cli.returncode == 3
    assert f"skysweep roofs: {e.value}" == cli.stderr.strip().splitlines()[-1]
    assert "nothere.shp" in str(e.value) and not (tmp_path / "o.gpkg").exists()


def test_without_weather_a_clear_sky_with_dc_and_ac(city, tmp_path):
    folder, _ = city
    options = dict(OPTIONS, time="2018-06-21T10:00Z/PT2H")
    result = skysweep.roofs(folder / "city.tif", folder / "footprints.geojson", None,
                            tmp_path / "clear.gpkg", **options)
    planes = [f["properties"] for f in result.roof_planes]
    assert planes and any(p["n_panels"] for p in planes)
    for p in planes:
        if p["n_panels"]:
            assert p["kwh_dc_year"] > p["kwh_ac_year"] > 0
