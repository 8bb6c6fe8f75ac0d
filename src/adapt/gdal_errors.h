/* GDAL's errors, gathered in one place: the adapters never let GDAL print.
 * One process-wide handler (installed by ss_gdal_init) keeps the first
 * failure since the last reset with the errno of that moment, so a write
 * that fails for every strip of a full disk is reported once, by its
 * cause, whichever call noticed it. */
#ifndef SS_GDAL_ERRORS_H
#define SS_GDAL_ERRORS_H

#include <gdal.h>

#ifdef __cplusplus
extern "C" {
#endif

void ss_gdal_errors_install(void);
/* Forgets the failures recorded so far (and GDAL's last error). */
void ss_gdal_errors_reset(void);
/* Whether GDAL reported a failure since the last reset. */
int ss_gdal_failed(void);
/* GDAL's last message, or "no details from GDAL". */
const char *ss_gdal_message(void);
/* The first failure since the last reset as "CAUSE (GDAL: message)" where
 * errno or the message names a cause a user can act on (no space left,
 * the file size limit, the disk quota), else GDAL's message; written into
 * buf. Call it right after the failing call: where GDAL recorded nothing,
 * errno as it is then names the cause. */
const char *ss_gdal_failure(char *buf, size_t size);
/* That cause alone, or NULL where the first failure names none. */
const char *ss_gdal_io_cause(void);
/* Whether the first failure since the last reset was an allocation's
 * (ulimit -v): the run is out of memory, not the output unwritable. */
int ss_gdal_out_of_memory(void);
/* Closes a dataset that is being thrown away without flushing its cache
 * (gdal_discard.cpp). */
void ss_gdal_close_discarding(GDALDatasetH ds);

#ifdef __cplusplus
}
#endif
#endif
