/* cm_warp_read_displacements: a valid table (spaces, CRLF, blank lines, BOM) and every kind of
 * bad row, each reported as path:line with the right status. Files go to the work dir. */
#include "cadmorph/warp.h"
#include "test_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static cm_context *ctx;
static char dir[4096];

static const char *write_file(const char *name, const char *text)
{
    static char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f) return NULL;
    fputs(text, f);
    fclose(f);
    return path;
}

static void test_valid(void)
{
    const char *p = write_file("warp_ok.csv", "\xEF\xBB\xBFNode, dx ,dy,dz\r\n"
                                              "\r\n"
                                              "2, 0.5, -1e-3, 7\r\n"
                                              "0,1,2,3\n"
                                              "   \n"
                                              "4,-0,+2.5E+1,.25");
    double d[5 * 3];
    unsigned char listed[5];
    memset(d, 0x7f, sizeof d);
    cm_status s = cm_warp_read_displacements(ctx, p, 5, d, listed);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    double want[15] = {1, 2, 3, 0, 0, 0, 0.5, -1e-3, 7, 0, 0, 0, -0.0, 25, 0.25};
    unsigned char want_listed[5] = {1, 0, 1, 0, 1};
    for (int i = 0; i < 15; ++i)
        CHECK_MSG(d[i] == want[i], "d[%d] = %g, want %g", i, d[i], want[i]);
    CHECK(!memcmp(listed, want_listed, 5));
    /* header only: nothing listed */
    p = write_file("warp_header_only.csv", "node,dx,dy,dz\n");
    CHECK(cm_warp_read_displacements(ctx, p, 5, d, NULL) == CM_OK);
    CHECK(d[0] == 0 && d[14] == 0);
}

typedef struct bad_case {
    const char *name, *text;
    cm_status status;
    int line;
    const char *words; /* a phrase the message must hold */
} bad_case;

static void test_bad(void)
{
    static const bad_case cases[] = {
        {"bad_header", "node,x,y,z\n0,1,2,3\n", CM_ERR_FORMAT, 1, "header"},
        {"bad_no_header", "0,1,2,3\n", CM_ERR_FORMAT, 1, "header"},
        {"bad_empty", "", CM_ERR_FORMAT, 1, "end of file"},
        {"bad_columns", "node,dx,dy,dz\n0,1,2,3\n1,1,2\n", CM_ERR_FORMAT, 3, "4 columns"},
        {"bad_columns5", "node,dx,dy,dz\n\n0,1,2,3,4\n", CM_ERR_FORMAT, 3, "got 5"},
        {"bad_number", "node,dx,dy,dz\n0,1,2x,3\n", CM_ERR_FORMAT, 2, "dy: expected a number"},
        {"bad_empty_field", "node,dx,dy,dz\n0,1,,3\n", CM_ERR_FORMAT, 2, "dy: expected a number"},
        {"bad_node", "node,dx,dy,dz\n1.5,1,2,3\n", CM_ERR_FORMAT, 2, "expected an integer"},
        {"bad_range", "node,dx,dy,dz\n0,0,0,0\n5,1,2,3\n", CM_ERR_MISMATCH, 3, "out of range"},
        {"bad_negative", "node,dx,dy,dz\n-1,1,2,3\n", CM_ERR_MISMATCH, 2, "out of range"},
        {"bad_duplicate", "node,dx,dy,dz\n3,1,2,3\n1,0,0,0\n3,1,2,3\n", CM_ERR_MISMATCH, 4,
         "first on line 2"},
        {"bad_nan", "node,dx,dy,dz\n0,nan,2,3\n", CM_ERR_FORMAT, 2, "not finite"},
        {"bad_inf", "node,dx,dy,dz\n0,1,2,-inf\n", CM_ERR_FORMAT, 2, "not finite"},
        {"bad_overflow", "node,dx,dy,dz\n0,1,1e999,3\n", CM_ERR_FORMAT, 2, "not finite"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; ++i) {
        char name[64];
        snprintf(name, sizeof name, "%s.csv", cases[i].name);
        const char *p = write_file(name, cases[i].text);
        double d[15];
        unsigned char listed[5];
        cm_status s = cm_warp_read_displacements(ctx, p, 5, d, listed);
        char where[4300];
        snprintf(where, sizeof where, "%s:%d: ", p, cases[i].line);
        const char *msg = cm_context_message(ctx);
        CHECK_MSG(s == cases[i].status, "%s: status %d, want %d (%s)", cases[i].name, (int)s,
                  (int)cases[i].status, msg);
        CHECK_MSG(strstr(msg, where) && strstr(msg, cases[i].words), "%s: message '%s'",
                  cases[i].name, msg);
        int clean = 1;
        for (int k = 0; k < 15; ++k)
            clean &= d[k] == 0;
        for (int k = 0; k < 5; ++k)
            clean &= listed[k] == 0;
        CHECK_MSG(clean, "%s: outputs not reset after the error", cases[i].name);
    }
    double d[3];
    char missing[4200];
    snprintf(missing, sizeof missing, "%s/no_such_file.csv", dir);
    CHECK(cm_warp_read_displacements(ctx, missing, 1, d, NULL) == CM_ERR_IO);
    CHECK(strstr(cm_context_message(ctx), "no_such_file.csv") != NULL);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: test_warp_csv DATA_DIR WORK_DIR\n");
        return 2;
    }
    snprintf(dir, sizeof dir, "%s", argv[2]);
    cm_context_create(&ctx);
    test_valid();
    test_bad();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
