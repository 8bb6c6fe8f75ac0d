"""A file's missing DNI (and DHI) as skysweep completes it against pvlib.

Usage: python decomposition.py SKYSWEEP FILE LON,LAT

Runs `skysweep weather --at LON,LAT FILE` and recomputes each record from
its GHI (and DHI) with pvlib at skysweep's zenith and sun time:
pvlib.irradiance.erbs for a file of GHI alone, pvlib.irradiance.dni for
one of GHI and DHI (whose NaN skysweep writes as 0: no beam). Each DNI and
DHI must agree within 0.1 % (0.01 W/m^2 near zero). skysweep's zenith is
also checked against pvlib's SPA (within 0.01 degrees), so that the model
is compared at the sun pvlib would take. Prints 'ok - ...' or
'not ok - ...' per check; exits 1 if any fails.
"""
import io
import subprocess
import sys

import numpy as np
import pandas as pd
import pvlib

skysweep, path, at = sys.argv[1:4]
lon, lat = (float(v) for v in at.split(","))
text = subprocess.run([skysweep, "weather", "--at", at, path], check=True,
                      capture_output=True, text=True).stdout
ours = pd.read_csv(io.StringIO(text), comment="#")
times = pd.DatetimeIndex(pd.to_datetime(ours["sun_time"], utc=True))
zenith = ours["zenith"].to_numpy()
ghi = ours["ghi"].to_numpy()
failed = 0


def check(ok, what):
    global failed
    failed += not ok
    print(("ok - " if ok else "not ok - ") + what)


def agree(name, mine, ref):
    ref = np.asarray(ref, dtype=float)
    bad = np.abs(mine - ref) > np.maximum(1e-3 * np.abs(ref), 0.01)
    worst = int(np.argmax(np.abs(mine - ref)))
    check(not bad.any(),
          f"{name}: {len(ref) - bad.sum()} of {len(ref)} records within 0.1 % of pvlib; "
          f"worst at {times[worst]}: skysweep {mine[worst]:.3f}, pvlib {ref[worst]:.3f} "
          f"(zenith {zenith[worst]:.2f}, ghi {ghi[worst]:.1f})")


models = set(ours["model"])
check(len(models) == 1, f"one model for every record: {sorted(models)}")
if "erbs" in models:
    ref = pvlib.irradiance.erbs(ghi, zenith, times)
    agree("Erbs DNI", ours["dni"].to_numpy(), ref["dni"])
    agree("Erbs DHI", ours["dhi"].to_numpy(), ref["dhi"])
else:
    ref = pvlib.irradiance.dni(pd.Series(ghi, index=times),
                               pd.Series(ours["dhi"].to_numpy(), index=times),
                               pd.Series(zenith, index=times))
    undefined = ref.isna().to_numpy()
    check(np.all(ours["dni"].to_numpy()[undefined] == 0),
          f"closure DNI: {undefined.sum()} records where pvlib's is NaN are 0 (no beam)")
    agree("closure DNI", ours["dni"].to_numpy()[~undefined], ref.to_numpy()[~undefined])

# The sun skysweep completes at, against pvlib's SPA (true zenith, no refraction).
spa = pvlib.solarposition.get_solarposition(times, lat, lon, method="nrel_numpy")
up = spa["zenith"].to_numpy() < 90
diff = np.abs(zenith - (90 - spa["elevation"].to_numpy()))
check(np.all(diff < 0.01), f"true zenith within 0.01 deg of pvlib's SPA: worst {diff.max():.5f} deg"
      f" ({up.sum()} of {len(up)} records with the sun up)")
sys.exit(1 if failed else 0)
