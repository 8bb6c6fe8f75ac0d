/* The measured accuracy the number of box lines per cell is chosen from
 * (doc/planner.md): the 95th percentile over cells of the geometric SVF's
 * error against an independent box-model ray march, for each tabulated
 * count, on city DSMs (doc/box_lines.md; box_lines_table.c and that page
 * are regenerated together by `make box-lines`). */
#ifndef SS_BOX_LINES_TABLE_H
#define SS_BOX_LINES_TABLE_H

#define SS_BOX_LINES_N_COUNTS 7

/* The tabulated box-line counts, ascending. */
extern const int ss_box_lines_counts[SS_BOX_LINES_N_COUNTS];

typedef struct {
    const char *grid;                  /* the city grid it was measured on */
    double p95[SS_BOX_LINES_N_COUNTS]; /* SVF error, 95th percentile over cells */
} ss_box_lines_row;

extern const ss_box_lines_row ss_box_lines_rows[];
extern const int ss_box_lines_n_rows;

/* The smallest tabulated count whose SVF error meets svf_tolerance (plan.c).
 * A count's error is the worst 95th percentile over the rows, taken as the
 * larger of its own and the next larger count's, so that a dip at one
 * count is not trusted (as ss_directions_for_tolerance does). Where none
 * meets it, the largest count. *expected_error (may be NULL) gets the
 * error of the count returned. */
int ss_box_lines_for_tolerance(double svf_tolerance, double *expected_error);

#endif
