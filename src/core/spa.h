/* The SPA's periodic-term tables (spa_tables.c), shared by spa.c and the
 * tests that check them; the sun's public interface is skysweep_sun.h. */
#ifndef SS_SPA_H
#define SS_SPA_H

#include "skysweep_sun.h"

/* The periodic-term tables (spa_tables.c). */
typedef struct {
    double a, b, c; /* a cos(b + c * JME) */
} ss_spa_term;
typedef struct {
    const ss_spa_term *terms;
    int count;
} ss_spa_series;
typedef struct {
    signed char y[5]; /* multipliers of X0..X4 */
    double a, b, c, d;
} ss_spa_nutation_term;

#define SS_SPA_L_ORDERS 6
#define SS_SPA_B_ORDERS 2
#define SS_SPA_R_ORDERS 5
#define SS_SPA_NUTATION_TERMS 63
extern const ss_spa_series ss_spa_l_series[SS_SPA_L_ORDERS];
extern const ss_spa_series ss_spa_b_series[SS_SPA_B_ORDERS];
extern const ss_spa_series ss_spa_r_series[SS_SPA_R_ORDERS];
extern const ss_spa_nutation_term ss_spa_nutation[SS_SPA_NUTATION_TERMS];

#endif
