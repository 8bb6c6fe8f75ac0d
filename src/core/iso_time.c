/* Calendar conversions and ISO 8601 parsing and formatting (skysweep_sun.h):
 * instants are UTC Unix seconds (doubles: microseconds survive to year
 * 6000); calendar dates follow SPA (doc/sun.md). */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ctx_internal.h"
#include "skysweep_sun.h"

#define SECONDS_PER_DAY 86400.0
/* Julian day number of 1970-01-01 and of 1582-10-15, the first Gregorian day. */
#define JDN_UNIX_EPOCH 2440588LL
#define JDN_GREGORIAN_START 2299161LL

static long long floor_div(long long a, long long b)
{
    long long q = a / b;
    return (a % b != 0 && (a < 0) != (b < 0)) ? q - 1 : q;
}

static int is_gregorian(long long year, int month, int day)
{
    return year > 1582 || (year == 1582 && (month > 10 || (month == 10 && day >= 15)));
}

/* Days from 1970-01-01 of a proleptic Gregorian date (Hinnant's
 * days_from_civil, "chrono-compatible low-level date algorithms"). */
static long long gregorian_days(long long y, int m, int d)
{
    y -= m <= 2;
    long long era = floor_div(y, 400);
    long long yoe = y - era * 400;
    long long doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
    long long doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    return era * 146097 + doe - 719468;
}

static void gregorian_date(long long days, long long *y, int *m, int *d)
{
    long long z = days + 719468;
    long long era = floor_div(z, 146097);
    long long doe = z - era * 146097;
    long long yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
    long long doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    long long mp = (5 * doy + 2) / 153;
    *d = (int)(doy - (153 * mp + 2) / 5 + 1);
    *m = (int)(mp < 10 ? mp + 3 : mp - 9);
    *y = yoe + era * 400 + (*m <= 2);
}

/* Julian day number of a Julian-calendar date (Meeus ch. 7 in integer form);
 * floor division keeps it right before -4800. */
static long long julian_calendar_jdn(long long y, int m, int d)
{
    long long a = (14 - m) / 12;
    long long y2 = y + 4800 - a, m2 = m + 12 * a - 3;
    return d + (153 * m2 + 2) / 5 + 365 * y2 + floor_div(y2, 4) - 32083;
}

static void julian_calendar_date(long long jdn, long long *y, int *m, int *d)
{
    long long c = jdn + 32082;
    long long cycles = floor_div(c, 1461); /* whole 4-year cycles before day 0 */
    c -= cycles * 1461;
    long long dd = (4 * c + 3) / 1461;
    long long e = c - (1461 * dd) / 4;
    long long mm = (5 * e + 2) / 153;
    *d = (int)(e - (153 * mm + 2) / 5 + 1);
    *m = (int)(mm + 3 - 12 * (mm / 10));
    *y = dd - 4800 + mm / 10 + 4 * cycles;
}

static long long days_from_civil(long long y, int m, int d)
{
    if (is_gregorian(y, m, d))
        return gregorian_days(y, m, d);
    return julian_calendar_jdn(y, m, d) - JDN_UNIX_EPOCH;
}

static void civil_from_days(long long days, long long *y, int *m, int *d)
{
    if (days + JDN_UNIX_EPOCH >= JDN_GREGORIAN_START)
        gregorian_date(days, y, m, d);
    else
        julian_calendar_date(days + JDN_UNIX_EPOCH, y, m, d);
}

double ss_unix_from_civil(long long year, int month, int day, int hour, int minute, double second)
{
    /* Months outside 1..12 carry into the year and days outside the month
     * count on from its first day, like mktime. */
    long long months = year * 12 + (month - 1);
    long long y = floor_div(months, 12);
    int m = (int)(months - y * 12) + 1;
    int in_month = day >= 1 && day <= ss_days_in_month(y, m);
    double days =
        (double)(in_month ? days_from_civil(y, m, day) : days_from_civil(y, m, 1) + (day - 1));
    return days * SECONDS_PER_DAY + hour * 3600.0 + minute * 60.0 + second;
}

void ss_civil_from_unix(double unix_s, ss_civil_time *out)
{
    double days = floor(unix_s / SECONDS_PER_DAY);
    double sod = unix_s - days * SECONDS_PER_DAY;
    if (sod >= SECONDS_PER_DAY) { /* rounding just below midnight */
        days += 1;
        sod = 0;
    }
    civil_from_days((long long)days, &out->year, &out->month, &out->day);
    out->hour = (int)(sod / 3600);
    out->minute = (int)((sod - out->hour * 3600.0) / 60);
    out->second = sod - out->hour * 3600.0 - out->minute * 60.0;
}

int ss_days_in_month(long long year, int month)
{
    static const int days[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    if (month < 1 || month > 12)
        return 0;
    if (month != 2)
        return days[month - 1];
    int leap = year < 1582 ? floor_div(year, 4) * 4 == year
                           : (year % 4 == 0 && (year % 100 != 0 || year % 400 == 0));
    return 28 + leap;
}

/* ---- durations -------------------------------------------------------------------------- */

static double add_months(double unix_s, long long months)
{
    if (months == 0)
        return unix_s;
    ss_civil_time c;
    ss_civil_from_unix(unix_s, &c);
    long long total = c.year * 12 + (c.month - 1) + months;
    long long y = floor_div(total, 12);
    int m = (int)(total - y * 12) + 1;
    int d = c.day < ss_days_in_month(y, m) ? c.day : ss_days_in_month(y, m);
    if (y == 1582 && m == 10 && d > 4 && d < 15)
        d = 15; /* the days the Gregorian reform skipped */
    return ss_unix_from_civil(y, m, d, c.hour, c.minute, c.second);
}

double ss_time_add(double unix_s, const ss_duration *d, long long times)
{
    long long months = times * (d->years * 12 + d->months);
    double seconds = (double)times * d->seconds;
    if (times >= 0)
        return add_months(unix_s, months) + seconds;
    return add_months(unix_s + seconds, months);
}

/* ---- parsing ---------------------------------------------------------------------------- */

/* Reads exactly n digits. */
static int digits(const char **p, int n, int *value)
{
    int v = 0;
    for (int i = 0; i < n; ++i) {
        if ((*p)[i] < '0' || (*p)[i] > '9')
            return 0;
        v = v * 10 + ((*p)[i] - '0');
    }
    *p += n;
    *value = v;
    return 1;
}

static const char *const month_names[12] = {"January",   "February", "March",    "April",
                                            "May",       "June",     "July",     "August",
                                            "September", "October",  "November", "December"};

/* Year, month and day; *p is left after them. */
static ss_status parse_date(ss_ctx *ctx, const char *text, const char **p, long long *year,
                            int *month, int *day)
{
    const char *q = *p;
    int sign = 1, n = 0;
    if (*q == '+' || *q == '-')
        sign = *q++ == '-' ? -1 : 1;
    long long y = 0;
    while (q[n] >= '0' && q[n] <= '9' && n < 7)
        y = y * 10 + (q[n++] - '0');
    int plain = q == *p;
    if ((plain && n != 4) || (!plain && (n < 4 || n > 6)))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "time '%s': expected a date YYYY-MM-DD (years before 0 or after 9999 "
                       "as -YYYY or +YYYYY)",
                       text);
    q += n;
    if (*q != '-' || (++q, !digits(&q, 2, month)) || *q != '-' || (++q, !digits(&q, 2, day)))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "time '%s': expected a date YYYY-MM-DD", text);
    *year = sign * y;
    if (*month < 1 || *month > 12)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "time '%s': month %d does not exist (1..12)", text,
                       *month);
    int dim = ss_days_in_month(*year, *month);
    if (*day < 1 || *day > dim)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "time '%s': %s %lld has %d days, not %d", text,
                       month_names[*month - 1], *year, dim, *day);
    if (*year == 1582 && *month == 10 && *day > 4 && *day < 15)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "time '%s': 1582-10-05 to 1582-10-14 do not exist (the Julian calendar "
                       "ends on 1582-10-04, the Gregorian begins on 1582-10-15)",
                       text);
    *p = q;
    return SS_OK;
}

/* hh:mm[:ss[.fff]]; *p is left after it. */
static ss_status parse_clock(ss_ctx *ctx, const char *text, const char **p, int *hour, int *minute,
                             double *second)
{
    const char *q = *p;
    int s = 0;
    if (!digits(&q, 2, hour) || *q != ':' || (++q, !digits(&q, 2, minute)))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "time '%s': expected the time as hh:mm or hh:mm:ss",
                       text);
    *second = 0;
    if (*q == ':') {
        ++q;
        if (!digits(&q, 2, &s))
            return ss_fail(ctx, SS_ERR_ARGUMENT, "time '%s': expected two digits of seconds", text);
        *second = s;
        if (*q == '.' || *q == ',') {
            double scale = 0.1;
            ++q;
            if (*q < '0' || *q > '9')
                return ss_fail(ctx, SS_ERR_ARGUMENT,
                               "time '%s': expected digits after the decimal sign", text);
            for (; *q >= '0' && *q <= '9'; ++q, scale *= 0.1)
                *second += (*q - '0') * scale;
        }
    }
    if (*hour > 24)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "time '%s': hour %d does not exist (0..24)", text,
                       *hour);
    if (*minute > 59)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "time '%s': minute %d does not exist (0..59)", text,
                       *minute);
    if (s == 60)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "time '%s': leap second 60 cannot be represented in UTC Unix time", text);
    if (s > 59)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "time '%s': second %d does not exist (0..59)", text,
                       s);
    if (*hour == 24 && (*minute != 0 || *second != 0))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "time '%s': hour 24 is allowed only as 24:00:00 (the end of the day)", text);
    *p = q;
    return SS_OK;
}

/* Z, +hh:mm, +hhmm or +hh; the offset is east of Greenwich positive. */
static ss_status parse_zone(ss_ctx *ctx, const char *text, const char **p, double *offset_s)
{
    const char *q = *p;
    int hh = 0, mm = 0;
    if (*q == 'Z' || *q == 'z') {
        *offset_s = 0;
        *p = q + 1;
        return SS_OK;
    }
    if (*q != '+' && *q != '-')
        return ss_fail(ctx, SS_ERR_ARGUMENT, "time '%s' needs a time zone: add Z or +-hh:mm", text);
    int sign = *q++ == '-' ? -1 : 1;
    if (!digits(&q, 2, &hh))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "time '%s': expected the zone offset as +-hh:mm, +-hhmm or +-hh", text);
    if (*q == ':')
        ++q;
    if (*q >= '0' && *q <= '9' && !digits(&q, 2, &mm))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "time '%s': expected the zone offset as +-hh:mm, +-hhmm or +-hh", text);
    if (hh > 18 || mm > 59 || (hh == 18 && mm > 0))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "time '%s': zone offset %c%02d:%02d is outside -18:00..+18:00", text,
                       sign < 0 ? '-' : '+', hh, mm);
    *offset_s = sign * (hh * 3600.0 + mm * 60.0);
    *p = q;
    return SS_OK;
}

ss_status ss_parse_instant(ss_ctx *ctx, const char *text, double *unix_s)
{
    ss_call_begin(ctx);
    const char *p = text;
    long long year = 0;
    int month = 1, day = 1, hour = 0, minute = 0;
    double second = 0, offset_s = 0;
    ss_status st = parse_date(ctx, text, &p, &year, &month, &day);
    if (st != SS_OK)
        return st;
    if (*p) {
        if (*p != 'T' && *p != 't' && *p != ' ')
            return ss_fail(ctx, SS_ERR_ARGUMENT,
                           "time '%s': expected 'T' and a time after the date", text);
        ++p;
        st = parse_clock(ctx, text, &p, &hour, &minute, &second);
        if (st == SS_OK)
            st = parse_zone(ctx, text, &p, &offset_s);
        if (st != SS_OK)
            return st;
        if (*p)
            return ss_fail(ctx, SS_ERR_ARGUMENT, "time '%s': unexpected '%s' after the time zone",
                           text, p);
    }
    *unix_s = ss_unix_from_civil(year, month, day, hour, minute, second) - offset_s;
    return SS_OK;
}

ss_status ss_parse_duration(ss_ctx *ctx, const char *text, ss_duration *out)
{
    ss_call_begin(ctx);
    static const char date_units[] = "YMWD", time_units[] = "HMS";
    static const double unit_s[] = {0, 0, 7 * 86400.0, 86400.0, 3600.0, 60.0, 1.0};
    const char *p = text;
    int in_time = 0, next_unit = 0, parts = 0, fraction_seen = 0, weeks = 0;
    memset(out, 0, sizeof *out);
    if (*p != 'P' && *p != 'p')
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "duration '%s' must start with P (e.g. P1D, PT30M, P1Y2M)", text);
    ++p;
    while (*p) {
        if ((*p == 'T' || *p == 't') && !in_time) {
            in_time = 1;
            next_unit = 4;
            if (!p[1])
                return ss_fail(ctx, SS_ERR_ARGUMENT,
                               "duration '%s': T must be followed by hours, minutes or seconds",
                               text);
            ++p;
            continue;
        }
        double value = 0, scale = 1;
        int int_digits = 0, frac = 0;
        for (; *p >= '0' && *p <= '9'; ++p, ++int_digits)
            value = value * 10 + (*p - '0');
        if (*p == '.' || *p == ',') {
            frac = 1;
            for (++p; *p >= '0' && *p <= '9'; ++p)
                value += (*p - '0') * (scale *= 0.1);
        }
        if (int_digits == 0 || int_digits > 9)
            return ss_fail(ctx, SS_ERR_ARGUMENT,
                           "duration '%s': expected a number of 1 to 9 digits before each unit",
                           text);
        const char *units = in_time ? time_units : date_units;
        char letter = *p >= 'a' && *p <= 'z' ? (char)(*p - 'a' + 'A') : *p;
        const char *u = letter >= 'A' && letter <= 'Z' ? strchr(units, letter) : NULL;
        int unit = u ? (int)(u - units) + (in_time ? 4 : 0) : -1;
        if (unit < 0)
            return ss_fail(ctx, SS_ERR_ARGUMENT,
                           "duration '%s': expected a unit (%s) after the number", text,
                           in_time ? "H, M or S after T" : "Y, M, W or D; T before hours");
        if (unit < next_unit)
            return ss_fail(ctx, SS_ERR_ARGUMENT,
                           "duration '%s': units must come once each, largest first", text);
        if (fraction_seen)
            return ss_fail(ctx, SS_ERR_ARGUMENT,
                           "duration '%s': only the last (smallest) unit may have a fraction",
                           text);
        if (frac && unit < 2)
            return ss_fail(ctx, SS_ERR_ARGUMENT,
                           "duration '%s': a fraction of a year or month has no fixed length; "
                           "use days",
                           text);
        fraction_seen = frac;
        weeks |= unit == 2;
        if (unit == 0)
            out->years = (long long)value;
        else if (unit == 1)
            out->months = (long long)value;
        else
            out->seconds += value * unit_s[unit];
        next_unit = unit + 1;
        parts++;
        ++p;
    }
    if (parts == 0)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "duration '%s' has no value (e.g. P1D, PT30M)", text);
    if (weeks && parts > 1)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "duration '%s': weeks cannot be combined with other units (write days)",
                       text);
    return SS_OK;
}

static int is_zero(const ss_duration *d)
{
    return d->years == 0 && d->months == 0 && d->seconds == 0;
}

/* Number of k >= 0 with start + k step < end, found by doubling then
 * bisection so that calendar steps count exactly like ss_time_range_at. */
static ss_status count_steps(ss_ctx *ctx, const char *text, ss_time_range *r)
{
    long long lo = 0, hi = 1; /* at(lo) < end <= at(hi) once the loop ends */
    while (ss_time_range_at(r, hi) < r->end_unix_s) {
        lo = hi;
        if (hi >= SS_TIME_RANGE_MAX_STEPS)
            return ss_fail(ctx, SS_ERR_ARGUMENT,
                           "time range '%s' has more than %lld steps; use a larger step or a "
                           "shorter range",
                           text, SS_TIME_RANGE_MAX_STEPS);
        hi *= 2;
    }
    while (hi - lo > 1) {
        long long mid = lo + (hi - lo) / 2;
        if (ss_time_range_at(r, mid) < r->end_unix_s)
            lo = mid;
        else
            hi = mid;
    }
    r->count = lo + 1;
    if (r->count > SS_TIME_RANGE_MAX_STEPS)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "time range '%s' has %lld steps, more than %lld; use a larger step or a "
                       "shorter range",
                       text, r->count, SS_TIME_RANGE_MAX_STEPS);
    return SS_OK;
}

static int is_duration_text(const char *s)
{
    return *s == 'P' || *s == 'p';
}

ss_status ss_parse_time_range(ss_ctx *ctx, const char *text, ss_time_range *out)
{
    ss_call_begin(ctx);
    char part[3][128];
    int n = 0;
    memset(out, 0, sizeof *out);
    for (const char *p = text;; ++n) {
        const char *slash = strchr(p, '/');
        size_t len = slash ? (size_t)(slash - p) : strlen(p);
        if (n == 3)
            return ss_fail(ctx, SS_ERR_ARGUMENT,
                           "time range '%s' has more than three parts (START/END/STEP)", text);
        if (len == 0 || len >= sizeof part[0])
            return ss_fail(ctx, SS_ERR_ARGUMENT, "time range '%s' has an %s part", text,
                           len ? "overlong" : "empty");
        memcpy(part[n], p, len);
        part[n][len] = '\0';
        if (!slash) {
            ++n;
            break;
        }
        p = slash + 1;
    }
    ss_duration d;
    ss_status st;
    if (n == 1) {
        if (is_duration_text(part[0]))
            return ss_fail(ctx, SS_ERR_ARGUMENT,
                           "time '%s' is a duration; give an instant, or START/DURATION", text);
        st = ss_parse_instant(ctx, part[0], &out->start_unix_s);
        out->end_unix_s = out->start_unix_s;
        out->count = 1;
        return st;
    }
    if (is_duration_text(part[0]) && is_duration_text(part[1]))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "time range '%s' needs a start or an end instant, not two durations", text);
    if (is_duration_text(part[0])) {
        st = ss_parse_duration(ctx, part[0], &d);
        if (st == SS_OK)
            st = ss_parse_instant(ctx, part[1], &out->end_unix_s);
        out->start_unix_s = ss_time_add(out->end_unix_s, &d, -1);
    } else {
        st = ss_parse_instant(ctx, part[0], &out->start_unix_s);
        if (st == SS_OK && is_duration_text(part[1])) {
            st = ss_parse_duration(ctx, part[1], &d);
            out->end_unix_s = ss_time_add(out->start_unix_s, &d, 1);
        } else if (st == SS_OK) {
            st = ss_parse_instant(ctx, part[1], &out->end_unix_s);
        }
    }
    if (st != SS_OK)
        return st;
    if (!(out->end_unix_s > out->start_unix_s))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "time range '%s' %s", text,
                       out->end_unix_s == out->start_unix_s ? "is empty: it ends where it starts"
                                                            : "ends before it starts");
    if (n == 2)
        return SS_OK; /* an interval without instants: count stays 0 */
    if (!is_duration_text(part[2]))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "time range '%s': the step '%s' must be a duration (e.g. PT30M)", text,
                       part[2]);
    st = ss_parse_duration(ctx, part[2], &out->step);
    if (st != SS_OK)
        return st;
    if (is_zero(&out->step))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "time range '%s': the step must be longer than zero",
                       text);
    out->has_step = 1;
    return count_steps(ctx, text, out);
}

double ss_time_range_at(const ss_time_range *r, long long k)
{
    return ss_time_add(r->start_unix_s, &r->step, k);
}

void ss_time_range_step(const ss_time_range *r, long long k, double *mid_unix_s, double *hours)
{
    double a = ss_time_range_at(r, k), b = ss_time_range_at(r, k + 1);
    if (b > r->end_unix_s)
        b = r->end_unix_s;
    *mid_unix_s = 0.5 * (a + b);
    *hours = (b - a) / 3600.0;
}

/* ---- formatting ------------------------------------------------------------------------- */

size_t ss_format_instant(double unix_s, char *buf, size_t size)
{
    if (!(fabs(unix_s) < 9e12)) /* NAN, infinite, or microseconds beyond long long */
        return (size_t)snprintf(buf, size, "invalid");
    /* Whole microseconds first, so that rounding carries into the date. */
    long long us = llround(unix_s * 1e6);
    long long day_us = 86400LL * 1000000LL;
    long long days = floor_div(us, day_us);
    long long rem = us - days * day_us;
    long long y;
    int m, d;
    civil_from_days(days, &y, &m, &d);
    int hh = (int)(rem / 3600000000LL), mm = (int)(rem / 60000000LL % 60);
    int ss = (int)(rem / 1000000LL % 60), frac = (int)(rem % 1000000LL);
    char year[24], fraction[16] = "";
    if (y < 0 || y > 9999)
        snprintf(year, sizeof year, "%c%04lld", y < 0 ? '-' : '+', y < 0 ? -y : y);
    else
        snprintf(year, sizeof year, "%04lld", y);
    if (frac) {
        int len = snprintf(fraction, sizeof fraction, ".%06d", frac);
        while (fraction[len - 1] == '0')
            fraction[--len] = '\0';
    }
    return (size_t)snprintf(buf, size, "%s-%02d-%02dT%02d:%02d:%02d%sZ", year, m, d, hh, mm, ss,
                            fraction);
}
