"""File calls: the command line with its own option table."""
import pathlib
import subprocess

import numpy as np
import pytest

import skysweep
from conftest import read_envi, rough_dem, same, write_asc
from skysweep.files import command_line

SAMPLES = pathlib.Path(__file__).resolve().parents[2] / "samples"


def test_a_file_call_and_an_array_call_agree(tmp_path):
    z = rough_dem()
    dem = write_asc(tmp_path / "dem.asc", z)
    written = skysweep.svf_file(dem, tmp_path / "svf.envi", cell_size=10, of="ENVI",
                                directions=16, definition="radiative")
    assert written == tmp_path / "svf.envi"  # the output, to open next
    assert same(read_envi(tmp_path / "svf.envi")[0],
                skysweep.svf(z, 10, directions=16, definition="radiative"))


def test_options_are_checked_against_the_table_before_the_run(tmp_path):
    dem = write_asc(tmp_path / "dem.asc", rough_dem())
    with pytest.raises(TypeError, match="svf_tolerance"):
        skysweep.svf_file(dem, tmp_path / "o.tif", svf_tolerence=0.1)
    with pytest.raises(skysweep.ArgumentError, match="geometric"):
        skysweep.svf_file(dem, tmp_path / "o.tif", definition="sky")
    assert not (tmp_path / "o.tif").exists()


def test_failures_carry_the_cli_message_and_status(tmp_path):
    (tmp_path / "broken.tif").write_bytes(b"II*\x00 not a tiff")
    with pytest.raises(skysweep.InputError) as e:
        skysweep.hillshade_file(tmp_path / "broken.tif", tmp_path / "o.tif")
    assert e.value.status == 3 and "broken.tif" in str(e.value)
    assert not (tmp_path / "o.tif").exists()
    dem = write_asc(tmp_path / "dem.asc", rough_dem())
    with pytest.raises(skysweep.InputError, match="coordinate reference system"):
        skysweep.svf_file(dem, tmp_path / "o.tif")


def test_values_reach_the_cli_as_it_reads_them(tmp_path):
    z = rough_dem(hole=False)
    dem = write_asc(tmp_path / "dem.asc", z)
    skysweep.svf_file(dem, tmp_path / "w.envi", cell_size=10, of="ENVI", directions=16.0,
                      projwin=(100, 400, 300, 200), co={"INTERLEAVE": "BSQ"})
    window = read_envi(tmp_path / "w.envi")[0]
    assert window.shape == (20, 20)  # rows 8..27, columns 10..29 of the 10 m grid
    assert same(window, skysweep.svf(z, 10, directions=16)[8:28, 10:30])


def test_docstrings_list_every_option_help_does():
    for command in ("svf", "horizon", "insolation", "shadow", "hillshade"):
        text = subprocess.run([command_line(), command, "--help"], capture_output=True,
                              text=True).stdout
        names = [line.split()[0].lstrip("-") for line in text.splitlines()
                 if line.startswith("  -")]
        doc = getattr(skysweep, f"{command}_file").__doc__
        missing = [n for n in names if n not in ("q", "help")
                   and f"\n{n.replace('-', '_')} : " not in doc]
        assert not missing, (command, missing)


def test_progress_of_a_file_call(tmp_path):
    """The CLI shows progress once a run has lasted a second: this one does."""
    dem = write_asc(tmp_path / "dem.asc", rough_dem(200, 200))
    seen = []
    skysweep.svf_file(dem, tmp_path / "o.tif", cell_size=10, directions=3000, lines="interpolated",
                      device="reference", progress=lambda f, m: seen.append(f))
    assert len(seen) > 3 and seen[-1] == 1.0 and seen == sorted(seen)


def test_a_rasterio_dataset_is_taken_as_the_cli_takes_its_file(tmp_path):
    rasterio = pytest.importorskip("rasterio")
    from test_insolation import TM_45N_8E
    z = rough_dem()
    z[np.isnan(z)] = -9999.0
    path = tmp_path / "dem.tif"
    h, w = z.shape
    with rasterio.open(path, "w", driver="GTiff", width=w, height=h, count=1, dtype="float64",
                       crs=rasterio.crs.CRS.from_wkt(TM_45N_8E), nodata=-9999.0,
                       transform=rasterio.Affine(10.0, 0, -w * 5.0, 0, -10.0, h * 5.0)) as ds:
        ds.write(z, 1)
    skysweep.svf_file(path, tmp_path / "svf.tif", directions=16)
    with rasterio.open(path) as ds:
        mine = skysweep.svf(ds, directions=16)
    with rasterio.open(tmp_path / "svf.tif") as out:
        theirs = out.read(1, masked=True).filled(np.nan)
        assert out.crs == rasterio.crs.CRS.from_wkt(TM_45N_8E)
        assert out.descriptions[0] == "sky-view factor"
    assert same(mine, theirs)


def test_commands_without_progress_run_without_q(tmp_path):
    """info, sun and weather take no -q: run adds it only where it is an option."""
    assert "skysweep" in skysweep.run("info")
    assert "azimuth" in skysweep.run("sun", at="8,45", time="2026-06-21T10:00Z")
    assert "ghi" in skysweep.run("weather", SAMPLES / "weather" / "pvgis_tmy_45N_8E.csv")


class _Bar:
    """What a tqdm bar sees: the fractions, then close."""

    def __init__(self):
        self.seen = []

    def __call__(self, fraction, message):
        self.seen.append(fraction)

    def close(self):
        self.seen.append("closed")


def test_a_file_call_s_bar_is_full_before_it_closes(tmp_path):
    dem = write_asc(tmp_path / "dem.asc", rough_dem(200, 200))
    bar = _Bar()
    skysweep.svf_file(dem, tmp_path / "o.tif", cell_size=10, directions=3000,
                      lines="interpolated", device="reference", progress=bar)
    assert bar.seen[-2:] == [1.0, "closed"], bar.seen[-4:]


def test_paths_are_taken_wherever_a_path_is(tmp_path):
    dem = pathlib.Path(write_asc(tmp_path / "dem.asc", rough_dem()))
    out = skysweep.hillshade_file([dem], tmp_path / "h.envi", cell_size=10, of="ENVI")
    assert isinstance(out, pathlib.Path) and out.exists()
    printed = skysweep.run("sun", at="-155.28,19.41", time="2026-06-21T20:00Z",
                           horizon_from=SAMPLES / "kilauea_summit_30m.tif", format="json")
    assert "horizon" in printed
