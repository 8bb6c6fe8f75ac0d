/* Calendar dates and ISO 8601 text for instants, durations and time ranges.
 * Instants are UTC Unix seconds (doubles: microseconds survive to year
 * 6000). Calendar dates follow SPA and astronomical practice: the Gregorian
 * calendar from 1582-10-15, the Julian calendar before it (ISO 8601's
 * proleptic Gregorian would put 837-04-10 four days off SPA's Julian day),
 * astronomical year numbers (0 = 1 BC, -1000 = 1001 BC). doc/sun.md. The
 * instants, durations and ranges are public (skysweep_sun.h); the calendar
 * conversions here are the library's own. */
#ifndef SS_ISO_TIME_H
#define SS_ISO_TIME_H

#include <stddef.h>

#include "skysweep_sun.h"

typedef struct {
    long long year;
    int month, day, hour, minute;
    double second; /* [0, 60) */
} ss_civil_time;

/* Unix seconds of a UTC calendar date and time; fields are not checked, so
 * day 0 or hour 24 count on as arithmetic would. */
double ss_unix_from_civil(long long year, int month, int day, int hour, int minute, double second);
void ss_civil_from_unix(double unix_s, ss_civil_time *out);
/* Days in a month of the calendar in force (Julian leap rule before 1582);
 * 0 for a month outside 1..12. */
int ss_days_in_month(long long year, int month);

#endif
