# make_city.sh DIR: a synthetic city of known roofs on a 0.5 m DSM (240 x 140
# cells, UTM 32N on its central meridian, 45 N, so grid north is true north)
# and its footprints as GeoJSON (DIR/city.tif, DIR/footprints.geojson), and
# its ground as a DTM (DIR/ground.tif).
# Coordinates e, n are metres east and north of the DSM's south-west corner
# (x 499950, y 4983000); the ground lies at 10 m.
#   A gable 20 x 10 m, ridge east-west at n = 10, 30 deg, eaves at 16 m; a
#     chimney 1 x 1 m, 2 m above the south face
#   B hip 20 x 12 m, 35 deg on every side, eaves at 16 m
#   C shed 20 x 10 m, 25 deg facing south, eaves at 12 m (unshaded: pvlib)
#   S shed 15 x 10 m, 20 deg facing east, eaves at 13 m
#   E tall neighbour 15 x 8 m, flat at 40 m; D flat 15 x 15 m at 14 m north
#     of it, in its shade
#   M two flat parts of one building (a MultiPolygon), 13 m
#   P flat at 13 m, partly east of the DSM; X wholly outside it
#   bowtie: a self-intersecting ring (repaired; its edges miss the cell
#     centres, so that rasterizing it is no coin toss); empty: no geometry
set -eu
dir=$1
awk 'function tan(x) { return sin(x) / cos(x) }
function min(a, b) { return a < b ? a : b }
function inb(e, n, e0, e1, n0, n1) { return e > e0 && e < e1 && n > n0 && n < n1 }
BEGIN {
  pi = atan2(0, -1); d = pi / 180; h = 0.5; W = 240; H = 140;
  print "ncols " W; print "nrows " H; print "xllcorner 499950"; print "yllcorner 4983000";
  print "cellsize " h;
  for (r = 0; r < H; r++) { line = "";
    for (c = 0; c < W; c++) { e = (c + 0.5) * h; n = H * h - (r + 0.5) * h; z = 10;
      if (inb(e, n, 5, 25, 5, 15)) { z = 16 + tan(30 * d) * (5 - (n > 10 ? n - 10 : 10 - n));
        if (inb(e, n, 12, 13, 6.5, 7.5)) z += 2 }
      if (inb(e, n, 32, 52, 5, 17))
        z = 16 + tan(35 * d) * min(min(e - 32, 52 - e), min(n - 5, 17 - n));
      if (inb(e, n, 95, 115, 5, 15)) z = 12 + tan(25 * d) * (n - 5);
      if (inb(e, n, 60, 75, 5, 15)) z = 13 + tan(20 * d) * (75 - e);
      if (inb(e, n, 5, 20, 25, 33)) z = 40;
      if (inb(e, n, 5, 20, 40, 55)) z = 14;
      if (inb(e, n, 30, 40, 40, 50) || inb(e, n, 45, 55, 40, 50)) z = 13;
      if (inb(e, n, 110, 120, 50, 60)) z = 13;
      line = line sprintf("%.6f ", z) }
    print line } }' >"$dir/city.asc"
gdal_translate -q -ot Float32 -a_srs EPSG:32632 "$dir/city.asc" "$dir/city.tif"
# The ground alone (a DTM on the DSM's grid).
gdal_translate -q -ot Float32 -scale 0 1 10 10 "$dir/city.tif" "$dir/ground.tif"
awk 'function box(id, e0, n0, e1, n1) {
  return sprintf("{\"type\":\"Feature\",\"properties\":{\"building_id\":\"%s\"},\"geometry\":{\"type\":\"Polygon\",\"coordinates\":[%s]}}", id, ring(e0, n0, e1, n1)) }
function ring(e0, n0, e1, n1) {
  return sprintf("[[%s],[%s],[%s],[%s],[%s]]", p(e0, n0), p(e1, n0), p(e1, n1), p(e0, n1), p(e0, n0)) }
function p(e, n) { return sprintf("%.3f,%.3f", 499950 + e, 4983000 + n) }
BEGIN {
  print "{\"type\":\"FeatureCollection\",\"features\":[";
  print box("A", 5, 5, 25, 15) ","; print box("B", 32, 5, 52, 17) ",";
  print box("C", 95, 5, 115, 15) ","; print box("S", 60, 5, 75, 15) ",";
  print box("E", 5, 25, 20, 33) ","; print box("D", 5, 40, 20, 55) ",";
  printf "{\"type\":\"Feature\",\"properties\":{\"building_id\":\"M\"},\"geometry\":{\"type\":\"MultiPolygon\",\"coordinates\":[[%s],[%s]]}},\n", ring(30, 40, 40, 50), ring(45, 40, 55, 50);
  print box("P", 110, 50, 130, 60) ","; print box("X", 200, 10, 210, 20) ",";
  printf "{\"type\":\"Feature\",\"properties\":{\"building_id\":\"bowtie\"},\"geometry\":{\"type\":\"Polygon\",\"coordinates\":[[[%s],[%s],[%s],[%s],[%s]]]}},\n", p(80.1, 40), p(90.1, 50), p(90.1, 40), p(80.1, 50), p(80.1, 40);
  print "{\"type\":\"Feature\",\"properties\":{\"building_id\":\"empty\"},\"geometry\":null}";
  print "]}" }' >"$dir/raw.geojson"
ogr2ogr -f GeoJSON -a_srs EPSG:32632 "$dir/footprints.geojson" "$dir/raw.geojson"
