# mkplane.sh OUT TILT_DEG AZIMUTH_DEG: a 61 x 61 plane of 10 m cells at 8 E, 45 N (UTM 32N)
# rising away from AZIMUTH (the way it faces), tilted TILT.
awk -v t="$2" -v a="$3" 'BEGIN {
  n = 61; c = 10; pi = atan2(0, -1); g = sin(t * pi / 180) / cos(t * pi / 180);
  print "ncols " n; print "nrows " n; print "xllcorner 421000"; print "yllcorner 4982000";
  print "cellsize " c;
  for (r = 0; r < n; r++) { line = "";
    for (k = 0; k < n; k++) { e = (k - 30) * c; no = (30 - r) * c;
      d = e * sin(a * pi / 180) + no * cos(a * pi / 180); # distance toward the facing azimuth
      line = line sprintf("%.6f ", 500 - d * g) }
    print line } }' > "$1.asc"
gdal_translate -q -ot Float32 -a_srs EPSG:32632 "$1.asc" "$1"
