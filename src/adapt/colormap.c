/* Colour-map tables. viridis and magma are matplotlib's maps (van der Walt
 * and Smith, CC0) sampled at 17 evenly spaced points: linear interpolation
 * between them stays within 5.2/255 (viridis) and 3.7/255 (magma) of the
 * full 256-entry maps. terrain is
 * matplotlib's segmented "terrain" map, exact at its own break points. */
#include "config.h"

#include <math.h>
#include <string.h>

#include "colormap.h"

typedef struct {
    double t;
    unsigned char rgb[3];
} stop;

typedef struct {
    const char *name;
    const stop *stops;
    int n_stops;
} colormap;

static const stop grey_stops[] = {{0.0, {0, 0, 0}}, {1.0, {255, 255, 255}}};

/* Sky-view factor crowds near 1 (open ground: on the Kilauea DEM about 9 cells in
 * 10 lie in the top tenth of a min..max stretch) while enclosed cells are
 * few, so this grey ramp follows t^1.8: contrast where most cells are,
 * enclosed cells dark, open ones white. Stops every 1/8, within 1.3/255. */
static const stop svf_stops[] = {
    {0.0, {0, 0, 0}},        {0.125, {6, 6, 6}},       {0.25, {21, 21, 21}},
    {0.375, {44, 44, 44}},   {0.5, {73, 73, 73}},      {0.625, {109, 109, 109}},
    {0.75, {152, 152, 152}}, {0.875, {201, 201, 201}}, {1.0, {255, 255, 255}}};

#define SIXTEENTH(i) ((i) / 16.0)
static const stop viridis_stops[] = {
    {SIXTEENTH(0), {68, 1, 84}},     {SIXTEENTH(1), {72, 24, 106}},
    {SIXTEENTH(2), {71, 45, 123}},   {SIXTEENTH(3), {66, 64, 134}},
    {SIXTEENTH(4), {59, 82, 139}},   {SIXTEENTH(5), {51, 99, 141}},
    {SIXTEENTH(6), {44, 114, 142}},  {SIXTEENTH(7), {38, 130, 142}},
    {SIXTEENTH(8), {33, 145, 140}},  {SIXTEENTH(9), {31, 160, 136}},
    {SIXTEENTH(10), {40, 174, 128}}, {SIXTEENTH(11), {63, 188, 115}},
    {SIXTEENTH(12), {94, 201, 98}},  {SIXTEENTH(13), {132, 212, 75}},
    {SIXTEENTH(14), {173, 220, 48}}, {SIXTEENTH(15), {216, 226, 25}},
    {SIXTEENTH(16), {253, 231, 37}}};

static const stop magma_stops[] = {
    {SIXTEENTH(0), {0, 0, 4}},        {SIXTEENTH(1), {10, 8, 34}},
    {SIXTEENTH(2), {29, 17, 71}},     {SIXTEENTH(3), {54, 16, 107}},
    {SIXTEENTH(4), {81, 18, 124}},    {SIXTEENTH(5), {106, 28, 129}},
    {SIXTEENTH(6), {131, 38, 129}},   {SIXTEENTH(7), {156, 46, 127}},
    {SIXTEENTH(8), {183, 55, 121}},   {SIXTEENTH(9), {208, 65, 111}},
    {SIXTEENTH(10), {231, 82, 99}},   {SIXTEENTH(11), {245, 107, 92}},
    {SIXTEENTH(12), {252, 137, 97}},  {SIXTEENTH(13), {254, 167, 114}},
    {SIXTEENTH(14), {254, 196, 136}}, {SIXTEENTH(15), {253, 226, 163}},
    {SIXTEENTH(16), {252, 253, 191}}};

/* matplotlib _terrain_data: deep water, shallow water, lowland green, sand,
 * brown uplands, snow. */
static const stop terrain_stops[] = {{0.00, {51, 51, 153}}, {0.15, {0, 153, 255}},
                                     {0.25, {0, 204, 102}}, {0.50, {255, 255, 153}},
                                     {0.75, {128, 92, 84}}, {1.00, {255, 255, 255}}};

#define MAP(name, stops)                                                                           \
    {                                                                                              \
        name, stops, (int)(sizeof stops / sizeof stops[0])                                         \
    }
static const colormap maps[] = {MAP("grey", grey_stops), MAP("viridis", viridis_stops),
                                MAP("magma", magma_stops), MAP("terrain", terrain_stops),
                                MAP("svf", svf_stops)};
#define N_MAPS ((int)(sizeof maps / sizeof maps[0]))

static const colormap *find(const char *name)
{
    for (int i = 0; name && i < N_MAPS; ++i)
        if (strcmp(maps[i].name, name) == 0)
            return &maps[i];
    return NULL;
}

int ss_colormap_known(const char *name)
{
    return find(name) != NULL;
}

void ss_colormap_rgb(const char *name, double t01, unsigned char rgb[3])
{
    const colormap *map = find(name);
    if (!map)
        map = &maps[0];
    double t = isnan(t01) ? 0.0 : t01 < 0.0 ? 0.0 : t01 > 1.0 ? 1.0 : t01;
    int i = 1;
    while (i < map->n_stops - 1 && map->stops[i].t < t)
        ++i;
    const stop *a = &map->stops[i - 1], *b = &map->stops[i];
    double w = (t - a->t) / (b->t - a->t);
    for (int k = 0; k < 3; ++k)
        rgb[k] = (unsigned char)lround(a->rgb[k] + w * (b->rgb[k] - a->rgb[k]));
}
