/* The one call of GDAL's C++ API the adapters need: a dataset being
 * thrown away is closed without writing its cached blocks out first, so
 * that an interrupted run of many bands stops at once instead of flushing
 * gigabytes into a file about to be deleted. */
#include "config.h"

#include <gdal_priv.h>

#include "gdal_errors.h"

extern "C" void ss_gdal_close_discarding(GDALDatasetH ds)
{
    GDALDataset *d = GDALDataset::FromHandle(ds);
    d->MarkSuppressOnClose();
    GDALClose(ds);
}
