/* Pre-scan of STEP text before OpenCASCADE sees it (internal to cad/; C, so that the fuzz
 * driver links it without OpenCASCADE). */
#ifndef CADMORPH_CAD_STEP_SCAN_H
#define CADMORPH_CAD_STEP_SCAN_H

#include "cadmorph/core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Parenthesis depth no STEP entity needs (B-spline surfaces with weights reach 4). */
#define CM_STEP_MAX_DEPTH 64

/* Checks data (size bytes, the whole file) for what OpenCASCADE cannot take safely: no
 * ISO-10303-21 header, nesting deeper than CM_STEP_MAX_DEPTH, non-finite numbers (1.E999, nan,
 * inf), an SI_UNIT outside ISO 10303-41, unclosed strings or comments. CM_ERR_FORMAT (or
 * CM_ERR_UNSUPPORTED for a unit) with "path:line: what". Linear time, constant memory. */
cm_status cm_step_scan(cm_context *ctx, const char *path, const char *data, size_t size);

#ifdef __cplusplus
}
#endif
#endif
