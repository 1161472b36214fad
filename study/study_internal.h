/* Helpers shared by the study module's files (not public). */
#ifndef CADMORPH_STUDY_INTERNAL_H
#define CADMORPH_STUDY_INTERNAL_H

#include <stdio.h>

/* Writes s as one CSV field, quoted when it holds a comma, quote or line break (RFC 4180):
 * csv.c. */
void cm_csv_field(FILE *f, const char *s);

/* NULL for a readable regular file, else the reason ("not a regular file (a directory)",
 * "cannot open: <strerror>"), found without blocking on a FIFO: readable.c. */
const char *cm_study_unreadable(const char *path);

#endif
