/* Node lists (cm_mesh_read_node_list): the header, CRLF and blank lines, and each refusal
 * naming the file and line. */
#include "cadmorph/mesh.h"
#include "test_util.h"

#include <stdio.h>
#include <string.h>

static cm_context *ctx;
static char work[2048];

/* Writes text to <work>/<name> and reads it as a node list of n nodes into mark. */
static cm_status read_text(const char *name, const char *text, size_t n, unsigned char *mark,
                           char *path, size_t len)
{
    snprintf(path, len, "%s/%s", work, name);
    FILE *f = fopen(path, "wb");
    if (!f) return CM_ERR_IO;
    fputs(text, f);
    fclose(f);
    memset(mark, 0, n);
    return cm_mesh_read_node_list(ctx, path, n, mark);
}

static void refused(const char *name, const char *text, cm_status expected, const char *where)
{
    unsigned char mark[8];
    char path[2300], want[2400];
    CHECK(read_text(name, text, sizeof mark, mark, path, sizeof path) == expected);
    snprintf(want, sizeof want, "%s%s", path, where);
    CHECK_MSG(strstr(cm_context_message(ctx), want), "%s: '%s' lacks '%s'", name,
              cm_context_message(ctx), want);
}

int main(int argc, char **argv)
{
    snprintf(work, sizeof work, "%s", argc > 2 ? argv[2] : ".");
    cm_context_create(&ctx);
    unsigned char mark[8];
    char path[2300];
    CHECK(read_text("nodes_ok.csv", "node\r\n3\r\n\r\n0 \n7\n", 8, mark, path, sizeof path) ==
          CM_OK);
    CHECK(mark[0] && mark[3] && mark[7]);
    CHECK(!mark[1] && !mark[2] && !mark[4] && !mark[5] && !mark[6]);
    refused("nodes_header.csv", "index\n1\n", CM_ERR_FORMAT, ":1: expected the header 'node'");
    refused("nodes_token.csv", "node\n1\n2x\n", CM_ERR_FORMAT, ":3: '2x' is not a node index");
    refused("nodes_range.csv", "node\n8\n", CM_ERR_MISMATCH, ":2: node 8 out of range");
    refused("nodes_negative.csv", "node\n-1\n", CM_ERR_MISMATCH, ":2: node -1 out of range");
    refused("nodes_empty.csv", "\n\n", CM_ERR_FORMAT, ": empty");
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
