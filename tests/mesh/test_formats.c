/* The registry of mesh formats (mesh/io/formats.h): every row complete and recognised by its
 * own extensions in any case, the list of formats the messages and --help texts show, and
 * the path rules (extension, directory = OpenFOAM case). */
#include "cadmorph/mesh.h"
#include "formats.h"
#include "test_util.h"

#include <ctype.h>
#include <stdio.h>
#include <string.h>

static void test_rows(void)
{
    CHECK(cm_mesh_format_row_count >= 8);
    CHECK(cm_mesh_format_row_of(CM_FORMAT_UNKNOWN) == NULL);
    for (size_t i = 0; i < cm_mesh_format_row_count; ++i) {
        const cm_mesh_format_row *r = &cm_mesh_format_rows[i];
        CHECK(r->name && r->read && r->write && r->holds);
        CHECK(cm_mesh_format_row_of(r->format) == r);
        CHECK_MSG((r->extensions != NULL) != (r->claims != NULL), "%s: an extension or a path rule", r->name);
        CHECK((r->claims != NULL) == (r->described != NULL));
        for (const char *w = r->extensions; w && *w;) {
            const char *e = strchr(w, ' ');
            const size_t len = e ? (size_t)(e - w) : strlen(w);
            char path[64], upper[64];
            snprintf(path, sizeof path, "dir.d/m.%.*s", (int)len, w);
            for (size_t k = 0; k <= strlen(path); ++k) upper[k] = (char)toupper((unsigned char)path[k]);
            /* a row with a content test owns the extension only where no default row shares it
             * (the file does not exist: the default decides) */
            cm_mesh_format want = r->format;
            if (r->sniff) want = cm_mesh_format_of_extension(path);
            CHECK_MSG(cm_mesh_format_from_path(path) == want, "%s", path);
            CHECK_MSG(cm_mesh_format_from_path(upper) == want, "%s", upper);
            /* every extension is in the list the messages show */
            char dotted[64];
            snprintf(dotted, sizeof dotted, ".%.*s", (int)len, w);
            CHECK_MSG(strstr(cm_mesh_format_list(), dotted) != NULL, "%s", dotted);
            w = e ? e + 1 : NULL;
        }
    }
}

static void test_paths(void)
{
    /* the file formats' extensions in row order, each once, then the directory formats */
    CHECK(!strncmp(cm_mesh_format_list(), ".msh .vtu .vtk .mesh .obj .off .stl", 35));
    CHECK(strstr(cm_mesh_format_list(), ", or an OpenFOAM case directory") != NULL);
    CHECK(strstr(strstr(cm_mesh_format_list(), ".msh") + 1, ".msh ") == NULL);
    CHECK(cm_mesh_format_from_path(NULL) == CM_FORMAT_UNKNOWN);
    CHECK(cm_mesh_format_from_path("") == CM_FORMAT_UNKNOWN);
    CHECK(cm_mesh_format_from_path("m.vtu") == CM_FORMAT_VTU);
    CHECK(cm_mesh_format_from_path("m.Mesh") == CM_FORMAT_MEDIT);
    CHECK(cm_mesh_format_from_path("m.step") == CM_FORMAT_UNKNOWN);
    CHECK(cm_mesh_format_from_path("m.mshx") == CM_FORMAT_UNKNOWN);
    CHECK(cm_mesh_format_from_path("m.verylongext") == CM_FORMAT_UNKNOWN);
    CHECK(cm_mesh_format_from_path("m.vtu/") == CM_FORMAT_FOAM);
    CHECK(cm_mesh_format_from_path("a.b/case") == CM_FORMAT_FOAM);
    CHECK(cm_mesh_format_from_path("a/constant/polyMesh") == CM_FORMAT_FOAM);
    CHECK(cm_mesh_format_from_path("no_such_dir.d/m.stl") == CM_FORMAT_STL);
}

int main(void)
{
    test_rows();
    test_paths();
    return TEST_REPORT();
}
