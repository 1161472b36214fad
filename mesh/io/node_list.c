/* Node lists: the header `node` and one 0-based index per line (mesh.h). */
#include "cadmorph/mesh.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

cm_status cm_mesh_read_node_list(cm_context *ctx, const char *path, size_t n, unsigned char *mark)
{
    char *data = NULL;
    size_t size = 0;
    cm_status s = cm_file_read(ctx, path, &data, &size);
    if (s < 0) return s;
    char *p = data;
    long line = 0;
    int header = 0;
    while (p && *p) {
        char *e = strchr(p, '\n');
        if (e) *e = 0;
        ++line;
        size_t len = strlen(p);
        while (len && (p[len - 1] == '\r' || p[len - 1] == ' ')) p[--len] = 0;
        if (len) {
            if (!header) {
                if (strcmp(p, "node")) {
                    s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected the header 'node'", path, line);
                    break;
                }
                header = 1;
            } else {
                char *end;
                errno = 0;
                long long v = strtoll(p, &end, 10);
                if (errno || *end || end == p) {
                    s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: '%s' is not a node index", path, line, p);
                    break;
                }
                if (v < 0 || (unsigned long long)v >= n) {
                    s = cm_error(ctx, CM_ERR_MISMATCH, "%s:%ld: node %lld out of range (%zu nodes)",
                                 path, line, v, n);
                    break;
                }
                mark[v] = 1;
            }
        }
        p = e ? e + 1 : NULL;
    }
    if (s >= 0 && !header) s = cm_error(ctx, CM_ERR_FORMAT, "%s: empty (expected the header 'node')", path);
    free(data);
    return s;
}
