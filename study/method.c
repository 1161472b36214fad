/* Study methods by name (study.h): a few named pairs that the sweeps have always compared, and
 * a rule for every other pair, so that a warp method added to warp.h's table is a study method
 * at once ("femwarp", "rbf-s-femwarp"). */
#include "cadmorph/study.h"

#include <stdio.h>
#include <string.h>

/* The named methods, in the order of the sweeps' table (their plot colours follow it). */
static const struct named {
    const char *name;
    cm_surface_method surface;
    cm_warp_method warp;
} named[] = {
    {"rbf-s", CM_SURFACE_RBF, CM_WARP_RBF},
    {"project", CM_SURFACE_PROJECT, CM_WARP_RBF},
    {"rbf-s-biharmonic", CM_SURFACE_RBF, CM_WARP_RBF_BIHARMONIC},
};
enum { N_NAMED = sizeof named / sizeof *named };

/* Surface prefixes of "<surface>-<warp>"; no prefix means the closest-point surface, so that a
 * bare warp name compares warps on the same boundary motion. */
static const struct prefix {
    const char *text;
    cm_surface_method surface;
} prefixes[] = {{"rbf-s-", CM_SURFACE_RBF}, {"project-", CM_SURFACE_PROJECT}};

const char *cm_study_mode_name(int mode)
{
    return mode == CM_STUDY_ABSOLUTE ? "absolute" : mode == CM_STUDY_RELATIVE ? "relative" : "?";
}

static void set(cm_study_method *out, const char *name, cm_surface_method surface, int warp)
{
    memset(out, 0, sizeof *out);
    snprintf(out->name, sizeof out->name, "%s", name);
    cm_morph_method_init(&out->method);
    out->method.surface = surface;
    out->method.warp.method = (cm_warp_method)warp;
}

void cm_study_method_help(char *buf, size_t size)
{
    int k = 0;
    for (int i = 0; i < N_NAMED; ++i)
        k += snprintf(buf + k, k < (int)size ? size - k : 0, "%s, ", named[i].name);
    snprintf(buf + k, k < (int)size ? size - k : 0,
             "<warp>, rbf-s-<warp>, project-<warp> (<warp>: %s)", cm_warp_method_list());
}

cm_status cm_study_method_parse(cm_context *ctx, const char *name, cm_study_method *out)
{
    if (!name || !out) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_study_method_parse: NULL input");
    if (strlen(name) >= CM_STUDY_METHOD_NAME)
        return cm_error(ctx, CM_ERR_ARGUMENT, "method name too long: '%.40s...'", name);
    for (int i = 0; i < N_NAMED; ++i)
        if (!strcmp(name, named[i].name)) {
            set(out, name, named[i].surface, named[i].warp);
            return CM_OK;
        }
    int warp = cm_warp_method_from_name(name);
    if (warp >= 0) {
        set(out, name, CM_SURFACE_PROJECT, warp);
        return CM_OK;
    }
    for (size_t p = 0; p < sizeof prefixes / sizeof *prefixes; ++p) {
        size_t len = strlen(prefixes[p].text);
        if (strncmp(name, prefixes[p].text, len)) continue;
        warp = cm_warp_method_from_name(name + len);
        if (warp >= 0) {
            set(out, name, prefixes[p].surface, warp);
            return CM_OK;
        }
    }
    char help[512];
    cm_study_method_help(help, sizeof help);
    return cm_error(ctx, CM_ERR_ARGUMENT, "unknown method '%s' (known: %s)", name, help);
}

cm_status cm_study_methods_parse(cm_context *ctx, const char *list, cm_study_method *out,
                                 size_t cap, size_t *n)
{
    if (!list || !out || !n) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_study_methods_parse: NULL input");
    *n = 0;
    for (const char *p = list;;) {
        const char *end = strchr(p, ',');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        char name[CM_STUDY_METHOD_NAME + 1];
        if (len == 0) return cm_error(ctx, CM_ERR_ARGUMENT, "empty method name in '%s'", list);
        if (len > CM_STUDY_METHOD_NAME) len = CM_STUDY_METHOD_NAME; /* parse reports it */
        memcpy(name, p, len);
        name[len] = 0;
        if (*n == cap) return cm_error(ctx, CM_ERR_ARGUMENT, "more than %zu methods", cap);
        cm_status s = cm_study_method_parse(ctx, name, &out[*n]);
        if (s < 0) return s;
        for (size_t k = 0; k < *n; ++k)
            if (!strcmp(out[k].name, name))
                return cm_error(ctx, CM_ERR_ARGUMENT, "method '%s' given twice", name);
        ++*n;
        if (!end) return CM_OK;
        p = end + 1;
    }
}

size_t cm_study_default_methods(cm_study_method *out, size_t cap)
{
    size_t n = cap < N_NAMED ? cap : N_NAMED;
    for (size_t i = 0; i < n; ++i)
        set(&out[i], named[i].name, named[i].surface, named[i].warp);
    return n;
}

int cm_study_method_slot(const cm_study_method *m, size_t k)
{
    for (int i = 0; i < N_NAMED; ++i)
        if (!strcmp(m->name, named[i].name)) return i;
    return N_NAMED + (int)k;
}
