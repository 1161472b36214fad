/* --slide and --fixed-patches (patch_motion.h). */
#include "patch_motion.h"

#include "cli.h"

#include <string.h>

int cli_parse_patch_list(const cli_parser *p, const cli_option *o, const char *v, void *dest)
{
    cli_patch_motion *pm = dest;
    const int k = strcmp(o->name, "--slide") != 0; /* 0 --slide, 1 --fixed-patches */
    size_t len = strlen(v);
    if (pm->used[k] + len + 1 > sizeof pm->buf[k])
        return cli_usage(p->cmd, p->usage, "%s: the list of patch names is too long", o->name);
    char *q = pm->buf[k] + pm->used[k];
    memcpy(q, v, len + 1);
    pm->used[k] += len + 1;
    while (q) {
        char *comma = strchr(q, ',');
        if (comma) *comma = 0;
        if (!*q) return cli_usage(p->cmd, p->usage, "%s: an empty patch name in '%s'", o->name, v);
        if (pm->n[k] >= CLI_MAX_PATCH_NAMES)
            return cli_usage(p->cmd, p->usage, "%s: more than %d patch names", o->name,
                             CLI_MAX_PATCH_NAMES);
        pm->names[k][pm->n[k]++] = q;
        q = comma ? comma + 1 : NULL;
    }
    return 0;
}

void cli_patch_motion_options(const cli_patch_motion *pm, cm_motion_options *opt)
{
    cm_motion_options_init(opt);
    opt->slide = pm->names[0], opt->n_slide = pm->n[0];
    opt->fixed = pm->names[1], opt->n_fixed = pm->n[1];
    opt->all_fixed = pm->all_fixed;
}
