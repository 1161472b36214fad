/* Design tables (study.h): which rows difference each parameter relative to a base row -
 * central on a symmetric pair even when a nearer row has no partner, one-sided (forward,
 * backward) otherwise, rows changing several parameters ignored, a parameter no row changes
 * alone skipped with a warning naming it, no parameter at all an error - and the reader's
 * handling of a byte order mark and quoted names. The rows name one STEP fixture: only their
 * values matter here. */
#include "cadmorph/study.h"
#include "test_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static cm_design_table *table(cm_context *ctx, const char *dir, const char *data,
                              const char *text)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/design_table.csv", dir);
    FILE *f = fopen(path, "w");
    if (!f) return NULL;
    fputs(text, f);
    fclose(f);
    /* rows name x.step next to the table: a copy of a fixture */
    char step[4096], src[4096];
    snprintf(step, sizeof step, "%s/x.step", dir);
    snprintf(src, sizeof src, "%s/cad/bore_a.step", data);
    char *buf = NULL;
    size_t n = 0;
    if (cm_file_read(ctx, src, &buf, &n) < 0) return NULL;
    f = fopen(step, "wb");
    if (f) fwrite(buf, 1, n, f), fclose(f);
    free(buf);
    cm_design_table *t = NULL;
    cm_status s = cm_design_table_read(ctx, path, &t);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    return t;
}

int main(int argc, char **argv)
{
    const char *data = argc > 1 ? argv[1] : "tests/data", *dir = argc > 2 ? argv[2] : ".";
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    /* a: symmetric pair 0.2 (central, although 0.1 is nearer above); b: only above;
     * c: only below; d: only in a row that also changes a: skipped */
    cm_design_table *t = table(ctx, dir, data,
                               "\xEF\xBB\xBFstep,\"a\",b,c,\"d, mm\"\r\n"
                               "x.step,1,5,7,0\r\n"
                               "\r\n"
                               "x.step,1.1,5,7,0\n"
                               "x.step,1.2,5,7,0\n"
                               "x.step,0.8,5,7,0\n"
                               "x.step,1,5.5,7,0\n"
                               "x.step,1,5,6,0\n"
                               "x.step,1.3,5,7,1\n");
    if (t) {
        CHECK(cm_design_table_n_parameters(t) == 4 && cm_design_table_n_rows(t) == 7);
        CHECK(!strcmp(cm_design_table_parameter(t, 0), "a"));
        CHECK(!strcmp(cm_design_table_parameter(t, 3), "d, mm"));
        CHECK(cm_design_table_line(t, 1) == 4);
        cm_design_difference d[4];
        cm_status s = cm_design_plan(ctx, t, 0, d);
        CHECK_MSG(s == CM_WARNING && strstr(cm_context_message(ctx), "d, mm"), "%d %s", s,
                  cm_context_message(ctx));
        CHECK(d[0].scheme == CM_DESIGN_CENTRAL && d[0].plus == 2 && d[0].minus == 3);
        CHECK_NEAR(d[0].dp_plus, 0.2, 1e-15);
        CHECK_NEAR(d[0].dp_minus, -0.2, 1e-15);
        CHECK(d[1].scheme == CM_DESIGN_FORWARD && d[1].plus == 4);
        CHECK_NEAR(d[1].dp_plus, 0.5, 1e-15);
        CHECK(d[2].scheme == CM_DESIGN_BACKWARD && d[2].plus == 5 && d[2].dp_plus == -1);
        CHECK(d[3].scheme == CM_DESIGN_NONE);
        CHECK(!strcmp(cm_design_scheme_name(d[2].scheme), "backward"));
        /* from another base: row 1 (a = 1.1) sees row 0 as a change of a alone */
        s = cm_design_plan(ctx, t, 1, d);
        CHECK(s == CM_WARNING && d[0].scheme == CM_DESIGN_CENTRAL);
        CHECK(cm_design_plan(ctx, t, 99, d) == CM_ERR_ARGUMENT);
    }
    cm_design_table_destroy(&t);
    cm_design_table_destroy(&t);
    /* no row changes one parameter alone: an error */
    t = table(ctx, dir, data, "step,a,b\nx.step,1,1\nx.step,2,2\n");
    if (t) {
        cm_design_difference d[2];
        cm_status s = cm_design_plan(ctx, t, 0, d);
        CHECK_MSG(s == CM_ERR_FORMAT && strstr(cm_context_message(ctx), "nothing to differentiate"),
                  "%s", cm_context_message(ctx));
    }
    cm_design_table_destroy(&t);
    /* an unterminated quote is named at its line */
    char path[4096];
    snprintf(path, sizeof path, "%s/design_bad.csv", dir);
    FILE *f = fopen(path, "w");
    if (f) fputs("step,a\n\"x.step,1\n", f), fclose(f);
    CHECK(cm_design_table_read(ctx, path, &t) == CM_ERR_FORMAT && !t);
    CHECK_MSG(strstr(cm_context_message(ctx), ":2: a quoted field is not closed"), "%s",
              cm_context_message(ctx));
    CHECK(cm_design_table_detect(path) == 1);
    snprintf(path, sizeof path, "%s/cad/bore_a.step", data);
    CHECK(cm_design_table_detect(path) == 0);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
