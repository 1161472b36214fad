/* --slide PATCH,... and --fixed-patches PATCH,... of warp, deform, morph and study: the user's choice of how
 * boundary patches move (motion.h; docs/DESIGN.md, "Boundary motion by patch kind"). The
 * names are only parsed here; the library checks them against the mesh. */
#ifndef CADMORPH_CLI_PATCH_MOTION_H
#define CADMORPH_CLI_PATCH_MOTION_H

#include "options.h"

#include "cadmorph/motion.h"

#define CLI_MAX_PATCH_NAMES 256

typedef struct cli_patch_motion {
    char buf[2][8192]; /* the values, split in place at the commas */
    size_t used[2];
    const char *names[2][CLI_MAX_PATCH_NAMES]; /* [0] slide, [1] fixed */
    size_t n[2];
    int all_fixed; /* --no-slide */
} cli_patch_motion;

/* A comma list of patch names appended to a list (repeatable option). */
int cli_parse_patch_list(const cli_parser *p, const cli_option *o, const char *value, void *dest);

/* The motion options of the parsed lists (opt borrows pm's names). */
void cli_patch_motion_options(const cli_patch_motion *pm, cm_motion_options *opt);

/* The help text on the defaults, shared by warp and deform. */
#define CLI_PATCH_MOTION_DEFAULTS                                                               \
    "Boundary motion by patch kind (OpenFOAM patch types; CGNS symmetry planes):\n"            \
    "  symmetryPlane/symmetry, empty, wedge and cyclic patches slide on their plane\n"         \
    "  (a curved one on its own surface); other patches are fixed unless listed;\n"            \
    "  processor patches are no boundary. A node on two sliding planes slides on\n"            \
    "  their common line, on three it is fixed; listed beats fixed beats slide.\n"            \
    "  A one-cell-thick mesh between two empty planes is morphed exactly 2-D, a\n"             \
    "  wedge in its (r, z) half-plane; motion out of the plane is dropped with a warning.\n"

/* The help text on the defaults for morph and study (the nodes off the CAD model). */
#define CLI_PATCH_MOTION_OFF_CAD                                                                      \
    "With --off-cad fixed, the boundary nodes off G0 move by the kinds of their patches\n"      \
    "(OpenFOAM patch types; CGNS symmetry planes): symmetryPlane/symmetry, empty, wedge and\n"  \
    "cyclic patches slide on their plane (a curved one on its own surface), other patches\n"   \
    "are fixed; a node on two sliding planes slides along their common line, on three or on\n" \
    "a fixed patch it is fixed. The nodes on G0 follow the CAD whatever their patch. A .msh,\n" \
    "VTK or other mesh without patch types has nothing that slides unless --slide names its\n" \
    "groups. No 2-D or wedge reduction here (the morphed body is 3-D).\n"

#define CLI_PATCH_MOTION_OPTIONS(pm)                                                           \
    {.name = "--slide", .kind = CLI_CUSTOM, .takes_value = 1, .parse = cli_parse_patch_list,  \
     .dest = &(pm), .label = "--slide P,..",                                             \
     .help = "comma list: these patches slide too (on their plane when\n"                           \
             "flat, else on their initial surface by closest point)"},                               \
    {.name = "--fixed-patches", .kind = CLI_CUSTOM, .takes_value = 1,                          \
     .parse = cli_parse_patch_list, .dest = &(pm), .label = "--fixed-patches P",      \
     .help = "comma list: these patches are fixed even if their type slides"},                             \
    {.name = "--no-slide", .kind = CLI_FLAG, .dest = &(pm).all_fixed, .label = "--no-slide",   \
     .help = "every unlisted boundary node fixed, no 2-D/wedge reduction\n"                   \
             "(the motion before patch kinds)"}

#endif
