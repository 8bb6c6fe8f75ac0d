/* ISO 8601 instants, durations and ranges: what is accepted and what it
 * means, round trips through the formatter, calendar arithmetic, and every
 * refusal with its one-line message. */
#include "config.h"

#include <math.h>
#include <string.h>

#include "skysweep_sun.h"
#include "tap.h"

static ss_ctx *ctx;

static double utc(long long y, int mo, int d, int h, int mi, double s)
{
    return ss_unix_from_civil(y, mo, d, h, mi, s);
}

static void instant_is(const char *text, double want)
{
    double got = NAN;
    ss_status st = ss_parse_instant(ctx, text, &got);
    char label[160];
    snprintf(label, sizeof label, "'%s'%s%s", text, st ? ": " : "", st ? ss_ctx_message(ctx) : "");
    tap_close(got, want, 1e-6, label);
}

static void instant_fails(const char *text, const char *phrase)
{
    double t;
    ss_status st = ss_parse_instant(ctx, text, &t);
    const char *msg = st ? ss_ctx_message(ctx) : "(accepted)";
    tap_ok(st == SS_ERR_ARGUMENT && strstr(msg, phrase) && strstr(msg, text) && !strchr(msg, '\n'),
           "refuses '%s': \"%s\"", text, msg);
}

static void formats_as(double t, const char *want)
{
    char buf[64];
    size_t n = ss_format_instant(t, buf, sizeof buf);
    tap_ok(strcmp(buf, want) == 0 && n == strlen(want), "format %.6f -> '%s' (want '%s')", t, buf,
           want);
}

static void instants(void)
{
    double t = utc(2026, 6, 21, 10, 0, 0);
    instant_is("2026-06-21T10:00:00Z", t);
    instant_is("2026-06-21T10:00Z", t);
    instant_is("2026-06-21t10:00z", t);
    instant_is("2026-06-21 10:00:00Z", t);
    instant_is("2026-06-21T10:00:00.25Z", t + 0.25);
    instant_is("2026-06-21T10:00:00,5Z", t + 0.5);
    instant_is("2026-06-21T20:00:00+10:00", t);
    instant_is("2026-06-21T04:30:00-05:30", t);
    instant_is("2026-06-21T15:30:00+0530", t);
    instant_is("2026-06-21T15:00:00+05", t);
    instant_is("2026-06-21T10:00:00-00:00", t);
    instant_is("2026-06-21", utc(2026, 6, 21, 0, 0, 0));
    instant_is("2026-06-21T24:00:00Z", utc(2026, 6, 22, 0, 0, 0));
    instant_is("2026-06-21T24:00Z", utc(2026, 6, 22, 0, 0, 0));
    instant_is("1970-01-01T00:00:00Z", 0);
    instant_is("2024-02-29", utc(2024, 2, 29, 0, 0, 0));
    instant_is("2000-02-29T12:00Z", 951825600);
    /* Before 1582-10-15 the Julian calendar: 1500 and -1000 are leap years. */
    instant_is("1500-02-29", utc(1500, 2, 29, 0, 0, 0));
    instant_is("-1000-02-29T00:00:00Z", (1355866.5 - 2440587.5) * 86400.0);
    instant_is("0837-04-10T07:12Z", utc(837, 4, 10, 7, 12, 0));
    instant_is("+10000-01-01", utc(10000, 1, 1, 0, 0, 0));
    double a, b;
    ss_parse_instant(ctx, "1582-10-04T12:00Z", &a);
    ss_parse_instant(ctx, "1582-10-15T12:00Z", &b);
    tap_close(b - a, 86400, 0, "1582-10-15 follows 1582-10-04 (the Gregorian reform)");

    instant_fails("2026-06-21T10:00:00", "needs a time zone: add Z or +-hh:mm");
    instant_fails("2026-06-21T10:00", "needs a time zone");
    instant_fails("2026-02-30", "February 2026 has 28 days, not 30");
    instant_fails("2025-02-29", "February 2025 has 28 days, not 29");
    instant_fails("1900-02-29", "February 1900 has 28 days");
    instant_fails("2026-04-31T00:00Z", "April 2026 has 30 days, not 31");
    instant_fails("2026-06-00", "has 30 days, not 0");
    instant_fails("2026-13-01", "month 13 does not exist");
    instant_fails("2026-00-10", "month 0 does not exist");
    instant_fails("2026-06-21T24:00:01Z", "hour 24 is allowed only as 24:00:00");
    instant_fails("2026-06-21T24:30Z", "hour 24 is allowed only");
    instant_fails("2026-06-21T25:00Z", "hour 25 does not exist");
    instant_fails("2026-06-21T10:60Z", "minute 60 does not exist");
    instant_fails("2026-06-21T10:00:61Z", "second 61 does not exist");
    instant_fails("2016-12-31T23:59:60Z", "leap second");
    instant_fails("1582-10-10", "do not exist");
    instant_fails("2026-06-21T10:00+19:00", "zone offset +19:00 is outside");
    instant_fails("2026-06-21T10:00+05:60", "zone offset +05:60");
    instant_fails("2026-06-21T10:00Zjunk", "unexpected 'junk'");
    instant_fails("2026-06-21T10:00:00.Z", "digits after the decimal sign");
    instant_fails("2026-6-21", "expected a date YYYY-MM-DD");
    instant_fails("26-06-21", "expected a date");
    instant_fails("20260621", "expected a date");
    instant_fails("2026-06-21X10:00Z", "expected 'T'");
    instant_fails("2026-06-21T1000Z", "hh:mm");
    instant_fails("", "expected a date");
}

static void formatting(void)
{
    formats_as(utc(2026, 6, 21, 10, 0, 0), "2026-06-21T10:00:00Z");
    formats_as(utc(2026, 6, 21, 10, 0, 0.25), "2026-06-21T10:00:00.25Z");
    formats_as(utc(2026, 6, 21, 10, 0, 0.000001), "2026-06-21T10:00:00.000001Z");
    formats_as(utc(2026, 6, 21, 23, 59, 59.9999996), "2026-06-22T00:00:00Z");
    formats_as(-0.5, "1969-12-31T23:59:59.5Z");
    formats_as(utc(-1000, 2, 29, 0, 0, 0), "-1000-02-29T00:00:00Z");
    formats_as(utc(837, 4, 10, 7, 12, 0), "0837-04-10T07:12:00Z");
    formats_as(utc(1582, 10, 4, 0, 0, 0) + 86400, "1582-10-15T00:00:00Z");
    formats_as(utc(10000, 1, 1, 0, 0, 0), "+10000-01-01T00:00:00Z");
    formats_as(NAN, "invalid");
    formats_as(1e13, "invalid");
    char small[8];
    size_t n = ss_format_instant(0, small, sizeof small);
    tap_ok(n == 20 && strlen(small) == 7, "format reports the length needed (%zu) and truncates",
           n);

    /* Round trips over 8000 years, and the civil fields agree, to the
     * microsecond or a few units of the double's last place (15 us at
     * 1e11 s). */
    int ok = 1;
    unsigned s = 2026;
    for (int i = 0; i < 20000 && ok; ++i) {
        s = s * 1103515245u + 12345u;
        double t = (double)(s % 2000000) * 126227.0 - 1.3e11 + (s >> 20) % 1000 * 0.001;
        char buf[64];
        double back = NAN;
        ss_format_instant(t, buf, sizeof buf);
        double tol = 1e-6 + 4 * fabs(t) * 2.2e-16;
        ok = ss_parse_instant(ctx, buf, &back) == SS_OK && fabs(back - t) <= tol;
        if (!ok)
            tap_diag("round trip of %.6f: '%s' -> %.6f", t, buf, back);
        ss_civil_time c;
        ss_civil_from_unix(t, &c);
        ok = ok && fabs(utc(c.year, c.month, c.day, c.hour, c.minute, c.second) - t) <= tol;
    }
    tap_ok(ok, "20000 instants from -2150 to 6000: format -> parse and civil -> Unix round trip");
}

static void duration_is(const char *text, long long years, long long months, double seconds)
{
    ss_duration d = {-1, -1, -1};
    ss_status st = ss_parse_duration(ctx, text, &d);
    tap_ok(st == SS_OK && d.years == years && d.months == months &&
               fabs(d.seconds - seconds) < 1e-9,
           "duration '%s' = %lld y %lld mo %.6g s (%s)", text, d.years, d.months, d.seconds,
           st ? ss_ctx_message(ctx) : "ok");
}

static void duration_fails(const char *text, const char *phrase)
{
    ss_duration d;
    ss_status st = ss_parse_duration(ctx, text, &d);
    const char *msg = st ? ss_ctx_message(ctx) : "(accepted)";
    tap_ok(st == SS_ERR_ARGUMENT && strstr(msg, phrase) && strstr(msg, text),
           "refuses duration '%s': \"%s\"", text, msg);
}

static void durations(void)
{
    duration_is("P1W", 0, 0, 604800);
    duration_is("P2.5W", 0, 0, 2.5 * 604800);
    duration_is("P1D", 0, 0, 86400);
    duration_is("PT30M", 0, 0, 1800);
    duration_is("PT1.5H", 0, 0, 5400);
    duration_is("PT0,5S", 0, 0, 0.5);
    duration_is("P0.5D", 0, 0, 43200);
    duration_is("P1Y2M10DT2H30M", 1, 2, 10 * 86400 + 2 * 3600 + 30 * 60);
    duration_is("P1Y", 1, 0, 0);
    duration_is("P18M", 0, 18, 0);
    duration_is("PT36H", 0, 0, 129600);
    duration_is("P1DT12H", 0, 0, 129600);
    duration_is("PT1M30.25S", 0, 0, 90.25);

    duration_fails("1D", "must start with P");
    duration_fails("P", "has no value");
    duration_fails("PT", "T must be followed");
    duration_fails("P1DT", "T must be followed");
    duration_fails("P1.5Y", "a fraction of a year or month");
    duration_fails("P1.5M", "a fraction of a year or month");
    duration_fails("P1.5DT1H", "only the last (smallest) unit may have a fraction");
    duration_fails("P1W2D", "weeks cannot be combined");
    duration_fails("P1M1Y", "largest first");
    duration_fails("P1D1D", "once each");
    duration_fails("P1H", "T before hours");
    duration_fails("PT1D", "H, M or S after T");
    duration_fails("P-1D", "expected a number");
    duration_fails("P1", "expected a unit");
    duration_fails("PT20 S", "expected a unit"); /* found by fuzzing: ' ' read as the end */
    duration_fails("P1234567890D", "1 to 9 digits");
}

static void calendar_arithmetic(void)
{
    ss_duration month = {0, 1, 0}, year = {1, 0, 0}, month_day = {0, 1, 86400};
    double jan31 = utc(2026, 1, 31, 6, 0, 0);
    tap_close(ss_time_add(jan31, &month, 1), utc(2026, 2, 28, 6, 0, 0), 0,
              "2026-01-31 + P1M = 2026-02-28 (clamped to the month's end)");
    tap_close(ss_time_add(jan31, &month, 2), utc(2026, 3, 31, 6, 0, 0), 0,
              "2026-01-31 + 2 x P1M = 2026-03-31 (from the start, not step by step)");
    tap_close(ss_time_add(utc(2024, 1, 31, 0, 0, 0), &month, 1), utc(2024, 2, 29, 0, 0, 0), 0,
              "2024-01-31 + P1M = 2024-02-29 (leap year)");
    tap_close(ss_time_add(utc(2024, 2, 29, 0, 0, 0), &year, 1), utc(2025, 2, 28, 0, 0, 0), 0,
              "2024-02-29 + P1Y = 2025-02-28");
    tap_close(ss_time_add(utc(2024, 2, 29, 0, 0, 0), &year, 4), utc(2028, 2, 29, 0, 0, 0), 0,
              "2024-02-29 + 4 x P1Y = 2028-02-29");
    tap_close(ss_time_add(jan31, &month_day, 1), utc(2026, 3, 1, 6, 0, 0), 0,
              "2026-01-31 + P1M1D = 2026-03-01 (months first, then days)");
    tap_close(ss_time_add(utc(2026, 3, 31, 0, 0, 0), &month, -1), utc(2026, 2, 28, 0, 0, 0), 0,
              "2026-03-31 - P1M = 2026-02-28");
    tap_close(ss_time_add(utc(2026, 12, 15, 0, 0, 0), &month, 1), utc(2027, 1, 15, 0, 0, 0), 0,
              "2026-12-15 + P1M crosses into 2027");
    tap_close(ss_time_add(utc(1582, 9, 10, 0, 0, 0), &month, 1), utc(1582, 10, 15, 0, 0, 0), 0,
              "1582-09-10 + P1M lands in the reform's gap and moves to 1582-10-15");
    ss_duration day = {0, 0, 86400};
    tap_close(ss_time_add(utc(2026, 3, 28, 12, 0, 0), &day, 3), utc(2026, 3, 31, 12, 0, 0), 0,
              "days are exact 86400 s in UTC (no daylight saving)");
}

static void range_is(const char *text, double start, double end, long long count, double last)
{
    ss_time_range r;
    memset(&r, 0, sizeof r);
    ss_status st = ss_parse_time_range(ctx, text, &r);
    double got_last = r.count > 0 ? ss_time_range_at(&r, r.count - 1) : NAN;
    tap_ok(st == SS_OK && r.start_unix_s == start && r.end_unix_s == end && r.count == count &&
               (count == 0 || fabs(got_last - last) < 1e-6),
           "range '%s': %lld instants%s%s", text, r.count, st ? ": " : "",
           st ? ss_ctx_message(ctx) : "");
}

static void range_fails(const char *text, const char *phrase)
{
    ss_time_range r;
    ss_status st = ss_parse_time_range(ctx, text, &r);
    const char *msg = st ? ss_ctx_message(ctx) : "(accepted)";
    tap_ok(st == SS_ERR_ARGUMENT && strstr(msg, phrase), "refuses range '%s': \"%s\"", text, msg);
}

static void ranges(void)
{
    double d21 = utc(2026, 6, 21, 0, 0, 0), d22 = utc(2026, 6, 22, 0, 0, 0);
    range_is("2026-06-21T00:00Z/P1D/PT30M", d21, d22, 48, d22 - 1800);
    range_is("2026-06-21T00:00Z/2026-06-22T00:00Z/PT1H", d21, d22, 24, d22 - 3600);
    range_is("P1D/2026-06-22T00:00Z/PT1H", d21, d22, 24, d22 - 3600);
    range_is("2026-06-21T10:00+10:00/PT1H/PT25M", d21, d21 + 3600, 3, d21 + 3000);
    range_is("2026-06-21T00:00Z/PT1H/PT1H", d21, d21 + 3600, 1, d21);
    range_is("2026-06-21T00:00Z", d21, d21, 1, d21);
    range_is("2026-06-21T00:00Z/2026-06-22T00:00Z", d21, d22, 0, NAN);
    range_is("2026-01-31T00:00Z/P1Y/P1M", utc(2026, 1, 31, 0, 0, 0), utc(2027, 1, 31, 0, 0, 0), 12,
             utc(2026, 12, 31, 0, 0, 0));
    range_is("2026-01-01/P100D/PT1S", utc(2026, 1, 1, 0, 0, 0), utc(2026, 4, 11, 0, 0, 0), 8640000,
             utc(2026, 4, 10, 23, 59, 59));
    ss_time_range r;
    ss_parse_time_range(ctx, "2026-01-31T00:00Z/P1Y/P1M", &r);
    tap_ok(ss_time_range_at(&r, 1) == utc(2026, 2, 28, 0, 0, 0) &&
               ss_time_range_at(&r, 2) == utc(2026, 3, 31, 0, 0, 0),
           "monthly steps from the 31st: 02-28, then back to 03-31");

    range_fails("2026-06-22T00:00Z/2026-06-21T00:00Z", "ends before it starts");
    range_fails("2026-06-21T00:00Z/2026-06-21T00:00Z", "is empty");
    range_fails("2026-06-21T00:00Z/P0D", "is empty");
    range_fails("2026-06-21T00:00Z/P1D/PT0S", "the step must be longer than zero");
    range_fails("2026-06-21T00:00Z/P1D/2026-06-22T00:00Z", "must be a duration");
    range_fails("2026-06-21T00:00Z/P1D/PT1H/PT1H", "more than three parts");
    range_fails("P1D/PT1H", "not two durations");
    range_fails("P1D", "is a duration");
    range_fails("2026-06-21T00:00Z//PT1H", "empty part");
    range_fails("2026-06-21T00:00Z/P1D/", "empty part");
    range_fails("2026-01-01T00:00Z/P1Y/PT1S", "more than 10000000 steps");
    range_fails("2026-06-21T00:00/P1D/PT1H", "needs a time zone");
    range_fails("2026-06-21T00:00Z/P1D/PT1.5", "expected a unit");
}

int main(void)
{
    ctx = ss_ctx_new();
    instants();
    formatting();
    durations();
    calendar_arithmetic();
    ranges();
    ss_ctx_free(ctx);
    return tap_done();
}
