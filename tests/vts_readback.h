/* Reads a .vts file back with VTK's own vtkXMLStructuredGridReader, so the
 * render test checks the export against an independent reader. */
#ifndef SS_VTS_READBACK_H
#define SS_VTS_READBACK_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    int dims[3];
    long n_points, n_hidden; /* hidden: points flagged HIDDENPOINT in vtkGhostType */
    double bounds[6];        /* xmin, xmax, ymin, ymax, zmin, zmax */
    double *xyz;             /* 3 per point, VTK's point order (i fastest) */
    float *field;            /* the named point field, NULL if absent */
    char error[300];
} vts_data;

/* Returns 0 on success, else -1 with error set. */
int vts_read(const char *path, const char *field_name, vts_data *out);
void vts_data_free(vts_data *d);

#ifdef __cplusplus
}
#endif
#endif
