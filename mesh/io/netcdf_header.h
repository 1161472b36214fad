/* The netCDF classic header check before the netCDF library opens a file (netcdf_header.c). */
#ifndef CM_NETCDF_HEADER_H
#define CM_NETCDF_HEADER_H
#include "cadmorph/core.h"

#include <stdint.h>

/* CM_OK for a file that is not classic netCDF or whose header's lengths and counts all fit in
 * file_size bytes; CM_ERR_FORMAT naming the byte and the list otherwise. */
cm_status cm_netcdf_check_header(cm_context *ctx, const char *path, uint64_t file_size);

#endif
