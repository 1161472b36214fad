/* Writing a mesh back into the files it was read from (mesh/io/rewrite.h), with a format of
 * its own: "x y z" after each "v " in a main file and in one included file. Checks that only
 * the spans change, that a node that did not move keeps its bytes, the number texts, the rules
 * for included files and for a source that changed since it was read. */
#define _POSIX_C_SOURCE 200809L
#include "cadmorph/mesh.h"
#include "rewrite.h"
#include "test_files.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>


/* The spans of "v x y z" lines: the bytes after "v " to the end of the line. */
static void add_spans(cm_context *ctx, cm_rewrite_source *src, size_t file, const char *text, int64_t *node)
{
    for (const char *p = text; (p = strstr(p, "v ")) != NULL; ++p) {
        const char *end = strchr(p, '\n');
        CHECK(cm_rewrite_add_span(ctx, src, file, p + 2 - text, end - p - 2, (*node)++, 0) == CM_OK);
    }
}

static cm_status emit_xyz(cm_context *ctx, const cm_rewrite_source *src, const cm_rewrite_file *file,
                          const cm_rewrite_span *span, const char *original, const double xyz[3],
                          cm_rewrite_buf *out)
{
    (void)ctx, (void)src, (void)file, (void)span;
    const char *field = original;
    for (int k = 0; k < 3; ++k) {
        const char *end = strchr(field, ' ');
        if (!end) end = field + strlen(field);
        char num[40];
        int n = cm_rewrite_number(num, sizeof num, xyz[k], field, (size_t)(end - field));
        if (k) cm_rewrite_put(out, " ", 1);
        cm_rewrite_put(out, num, (size_t)n);
        field = *end ? end + 1 : end;
    }
    return CM_OK;
}

static void test_number(void)
{
    char out[40];
    CHECK(cm_rewrite_number(out, sizeof out, 1.5, "1.50", 4) == 4 && !strcmp(out, "1.50"));
    CHECK(cm_rewrite_number(out, sizeof out, 1.5, "1.25", 4) == 3 && !strcmp(out, "1.5"));
    CHECK(cm_rewrite_number(out, sizeof out, 0.1 + 0.2, NULL, 0) && !strcmp(out, "0.30000000000000004"));
    CHECK(cm_rewrite_number(out, sizeof out, 0.1, NULL, 0) && !strcmp(out, "0.1"));
    CHECK(cm_rewrite_number(out, sizeof out, -0.0, "0", 1) && !strcmp(out, "-0"));
    /* a Fortran-style exponent is not a number strtod reads whole: rewritten */
    CHECK(cm_rewrite_number(out, sizeof out, 1.5e-3, "1.5-3", 5) && !strcmp(out, "0.0015"));
}

static void test_main_and_include(cm_context *ctx)
{
    char in_dir[128], out_dir[128], main_in[160], inc_in[160], main_out[160], inc_out[160];
    snprintf(in_dir, sizeof in_dir, "%s", test_at("in"));
    snprintf(out_dir, sizeof out_dir, "%s", test_at("out"));
    mkdir(in_dir, 0777);
    mkdir(out_dir, 0777);
    snprintf(main_in, sizeof main_in, "%s/deck.txt", in_dir);
    snprintf(inc_in, sizeof inc_in, "%s/nodes.txt", in_dir);
    snprintf(main_out, sizeof main_out, "%s/deck.txt", out_dir);
    snprintf(inc_out, sizeof inc_out, "%s/nodes.txt", out_dir);
    const char *main_text = "# deck\nv 0 0 0\ninclude nodes.txt\ninclude cells.txt\nv 1.000 2 3\nend\n";
    const char *inc_text = "v 4 5 6\n  trailing text\n";
    char cells_in[160], cells_out[160];
    snprintf(cells_in, sizeof cells_in, "%s/cells.txt", in_dir);
    snprintf(cells_out, sizeof cells_out, "%s/cells.txt", out_dir);
    test_write_text(main_in, main_text);
    test_write_text(inc_in, inc_text);
    test_write_text(cells_in, "c 0 1 2\n");

    cm_rewrite_source *src = cm_rewrite_source_new();
    size_t f0 = 9, f1 = 9;
    CHECK(cm_rewrite_add_file(ctx, src, main_in, NULL, &f0) == CM_OK && f0 == 0);
    CHECK(cm_rewrite_add_file(ctx, src, inc_in, "nodes.txt", &f1) == CM_OK && f1 == 1);
    CHECK(cm_rewrite_add_file(ctx, src, cells_in, "cells.txt", NULL) == CM_OK); /* no coordinates */
    int64_t node = 0;
    add_spans(ctx, src, 0, main_text, &node);
    add_spans(ctx, src, 1, inc_text, &node);
    CHECK(node == 3);
    /* out of order */
    CHECK(cm_rewrite_add_span(ctx, src, 0, 0, 1, 0, 0) == CM_ERR_INTERNAL);

    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    CHECK(cm_mesh_resize_nodes(ctx, m, 3, 0) == CM_OK);
    const double xyz[9] = {0, 0, 0, 1, 2, 3.25, 4, 5.5, 6}; /* node 0 did not move */
    memcpy(m->xyz, xyz, sizeof xyz);

    /* beside the source, the included file would overwrite its own source: refused, nothing written */
    char beside[160];
    snprintf(beside, sizeof beside, "%s/deck2.txt", in_dir);
    CHECK(cm_rewrite_write(ctx, src, m, beside, emit_xyz) == CM_ERR_ARGUMENT);
    CHECK(strstr(cm_context_message(ctx), "nodes.txt") != NULL);
    CHECK(access(beside, F_OK) != 0);
    char *d = test_read_file(inc_in, NULL);
    CHECK(d && !strcmp(d, inc_text));
    free(d);

    CHECK(cm_rewrite_write(ctx, src, m, main_out, emit_xyz) == CM_OK);
    d = test_read_file(main_out, NULL);
    CHECK_MSG(d && !strcmp(d, "# deck\nv 0 0 0\ninclude nodes.txt\ninclude cells.txt\nv 1.000 2 3.25\nend\n"), "%s",
              d ? d : "(none)");
    free(d);
    d = test_read_file(inc_out, NULL);
    CHECK_MSG(d && !strcmp(d, "v 4 5.5 6\n  trailing text\n"), "%s", d ? d : "(none)");
    free(d);
    /* an included file without coordinates is copied too: the written deck is complete */
    d = test_read_file(cells_out, NULL);
    CHECK_MSG(d && !strcmp(d, "c 0 1 2\n"), "%s", cells_out);
    free(d);

    /* the source changed since it was read: refused */
    test_write_text(main_in, "# deck\nv 0 0 0\ninclude nodes.txt\ninclude cells.txt\nv 1.000 2 3\nend\n\n");
    CHECK(cm_rewrite_write(ctx, src, m, main_out, emit_xyz) == CM_ERR_IO);
    CHECK(strstr(cm_context_message(ctx), "changed") != NULL);
    cm_mesh_destroy(&m);
    cm_rewrite_source_free(src);
}

int main(void)
{
    if (test_work_temp("rewrite") != 0) return 1;
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    test_number();
    test_main_and_include(ctx);
    cm_context_destroy(&ctx);
    if (test_work_remove() != 0) return 1;
    return TEST_REPORT();
}
