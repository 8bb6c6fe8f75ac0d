/* Calendar dates and ISO 8601 text for instants, durations and time ranges.
 * Instants are UTC Unix seconds (doubles: microseconds survive to year
 * 6000). Calendar dates follow SPA and astronomical practice: the Gregorian
 * calendar from 1582-10-15, the Julian calendar before it (ISO 8601's
 * proleptic Gregorian would put 837-04-10 four days off SPA's Julian day),
 * astronomical year numbers (0 = 1 BC, -1000 = 1001 BC). doc/sun.md. */
#ifndef SS_ISO_TIME_H
#define SS_ISO_TIME_H

#include <stddef.h>

#include "skysweep.h"

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

/* A duration as ISO 8601 writes it: years and months stay calendar units so
 * that P1M steps from month to month; weeks, days, hours, minutes and
 * seconds are exact seconds (a day is 86400 s: UTC has no daylight saving). */
typedef struct {
    long long years, months;
    double seconds;
} ss_duration;

/* unix_s + times * d. The calendar part moves the date by whole months and
 * clamps the day to the month's length (2026-01-31 + P1M = 2026-02-28,
 * + P2M = 2026-03-31); for times >= 0 it is applied before the seconds
 * (as RFC 5545 does), for times < 0 after them, so that DURATION/END undoes
 * START/DURATION where no clamping occurs. */
double ss_time_add(double unix_s, const ss_duration *d, long long times);

/* 2026-06-21T10:00:00Z, ...T10:00Z, ...T10:00:00.25+10:00, -05:30, +0530,
 * +05; a bare date is 00:00 UTC. A date and time without a zone is refused. */
ss_status ss_parse_instant(ss_ctx *ctx, const char *text, double *unix_s);
/* PnW or PnYnMnDTnHnMnS; only the last unit may carry a fraction, and not
 * years or months (they have no fixed length). */
ss_status ss_parse_duration(ss_ctx *ctx, const char *text, ss_duration *out);

#define SS_TIME_RANGE_MAX_STEPS 10000000LL

typedef struct {
    double start_unix_s;
    double end_unix_s; /* equals start for a single instant */
    int has_step;
    ss_duration step;
    /* Instants start + k * step (k = 0, 1, ...) before end: the range is
     * half-open, so consecutive ranges tile without repeating an instant.
     * 1 for a single instant; 0 for an interval given without a step. */
    long long count;
} ss_time_range;

/* START, START/END, START/DURATION or DURATION/END, each optionally followed
 * by /STEP. Refuses an empty or reversed interval, a zero step, a step on a
 * single instant and more than SS_TIME_RANGE_MAX_STEPS instants. Steps may
 * hold years and months: instant k is start + k * step (ss_time_add), so
 * monthly steps from the 31st keep returning to the 31st where it exists. */
ss_status ss_parse_time_range(ss_ctx *ctx, const char *text, ss_time_range *out);
/* Instant k of the range. */
double ss_time_range_at(const ss_time_range *r, long long k);

/* 2026-06-21T10:00:00Z, with up to 6 decimals of seconds when they are not
 * zero (rounded to the microsecond); "invalid" for NAN, infinities and
 * beyond +-9e12 s (year 285000). Returns the length the text needs, as
 * snprintf does. */
size_t ss_format_instant(double unix_s, char *buf, size_t size);

#endif
