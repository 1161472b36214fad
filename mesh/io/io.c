/* Mesh file dispatch through the registry of formats (formats.h): the table, which format a
 * path names, cm_mesh_read (every reader's output validated) and cm_mesh_write. The frame the
 * readers and writers share is in frame.c, below this file. */
#define _POSIX_C_SOURCE 200809L
#include "formats.h"
#include "foam_internal.h"

#include <ctype.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

/* The registry: one row per format. A directory format is asked first (it claims paths by
 * what they name on disk), then the extension decides. */
const cm_mesh_format_row cm_mesh_format_rows[] = {
    {.format = CM_FORMAT_MSH, .name = "gmsh", .extensions = "msh", .read = cm_mesh_read_msh,
     .write = cm_mesh_write_msh, .holds = CM_MESH_IO_VOLUME | CM_MESH_IO_SURFACE | CM_MESH_IO_FIELDS | CM_MESH_IO_GROUPS},
    {.format = CM_FORMAT_VTU, .name = "VTK XML", .extensions = "vtu", .read = cm_mesh_read_vtu,
     .write = cm_mesh_write_vtu, .holds = CM_MESH_IO_VOLUME | CM_MESH_IO_SURFACE | CM_MESH_IO_FIELDS | CM_MESH_IO_GROUPS},
    {.format = CM_FORMAT_VTK, .name = "VTK legacy", .extensions = "vtk", .read = cm_mesh_read_vtk,
     .write = cm_mesh_write_vtk, .holds = CM_MESH_IO_VOLUME | CM_MESH_IO_SURFACE | CM_MESH_IO_FIELDS | CM_MESH_IO_GROUPS},
    {.format = CM_FORMAT_MEDIT, .name = "Medit", .extensions = "mesh", .read = cm_mesh_read_medit,
     .write = cm_mesh_write_medit, .holds = CM_MESH_IO_VOLUME | CM_MESH_IO_SURFACE | CM_MESH_IO_GROUPS},
    {.format = CM_FORMAT_OBJ, .name = "Wavefront", .extensions = "obj", .read = cm_mesh_read_obj,
     .write = cm_mesh_write_obj, .holds = CM_MESH_IO_SURFACE | CM_MESH_IO_GROUPS},
    {.format = CM_FORMAT_OFF, .name = "OFF", .extensions = "off", .read = cm_mesh_read_off,
     .write = cm_mesh_write_off, .holds = CM_MESH_IO_SURFACE},
    {.format = CM_FORMAT_STL, .name = "STL", .extensions = "stl", .read = cm_mesh_read_stl,
     .write = cm_mesh_write_stl, .holds = CM_MESH_IO_SURFACE | CM_MESH_IO_GROUPS},
    /* the solvers' own files: written back, only coordinates change (docs/DESIGN.md) */
    {.format = CM_FORMAT_CGNS, .name = "CGNS", .extensions = "cgns", .read = cm_mesh_read_cgns,
     .write = cm_mesh_write_cgns, .holds = CM_MESH_IO_VOLUME | CM_MESH_IO_SURFACE | CM_MESH_IO_GROUPS},
    {.format = CM_FORMAT_SU2, .name = "SU2", .extensions = "su2", .read = cm_mesh_read_su2,
     .write = cm_mesh_write_su2, .holds = CM_MESH_IO_VOLUME | CM_MESH_IO_SURFACE | CM_MESH_IO_GROUPS},
    /* Fluent: a .msh whose content starts with a section "(N ..." (gmsh's with $MeshFormat);
     * written only back into the file it was read from, node coordinates only */
    {.format = CM_FORMAT_FLUENT, .name = "Fluent", .extensions = "msh cas", .read = cm_mesh_read_fluent,
     .write = cm_mesh_write_fluent, .holds = CM_MESH_IO_VOLUME | CM_MESH_IO_SURFACE | CM_MESH_IO_GROUPS, .sniff = cm_fluent_sniff},
    {.format = CM_FORMAT_ABAQUS, .name = "Abaqus", .extensions = "inp", .read = cm_mesh_read_abaqus,
     .write = cm_mesh_write_abaqus, .holds = CM_MESH_IO_VOLUME | CM_MESH_IO_SURFACE | CM_MESH_IO_GROUPS},
    /* .dat is anyone's name: the content test makes Nastran the reader of a .dat only when no
     * other row takes the extension without one, or when the content is bulk data */
    {.format = CM_FORMAT_NASTRAN, .name = "Nastran bulk data", .extensions = "bdf nas dat",
     .read = cm_mesh_read_nastran, .write = cm_mesh_write_nastran, .holds = CM_MESH_IO_VOLUME | CM_MESH_IO_SURFACE | CM_MESH_IO_GROUPS, .sniff = cm_nastran_sniff},
    {.format = CM_FORMAT_EXODUS, .name = "Exodus II", .extensions = "exo e ex2 g",
     .read = cm_mesh_read_exodus, .write = cm_mesh_write_exodus, .holds = CM_MESH_IO_VOLUME | CM_MESH_IO_SURFACE | CM_MESH_IO_GROUPS},
    {.format = CM_FORMAT_FOAM, .name = "OpenFOAM polyMesh", .claims = cm_foam_is_path,
     .described = "an OpenFOAM case directory", .read = cm_mesh_read_foam, .write = cm_mesh_write_foam,
     .holds = CM_MESH_IO_VOLUME | CM_MESH_IO_GROUPS},
};
const size_t cm_mesh_format_row_count = sizeof cm_mesh_format_rows / sizeof cm_mesh_format_rows[0];

const cm_mesh_format_row *cm_mesh_format_row_of(cm_mesh_format format)
{
    for (size_t i = 0; i < cm_mesh_format_row_count; ++i)
        if (cm_mesh_format_rows[i].format == format) return &cm_mesh_format_rows[i];
    return NULL;
}

/* Whether ext (n bytes) is one of the space-separated names in list, ignoring case. */
static int in_list(const char *list, const char *ext, size_t n)
{
    for (const char *w = list; w && *w;) {
        const char *e = strchr(w, ' ');
        const size_t len = e ? (size_t)(e - w) : strlen(w);
        size_t i = 0;
        while (i < n && i < len && tolower((unsigned char)ext[i]) == w[i]) ++i;
        if (i == n && i == len) return 1;
        w = e ? e + 1 : NULL;
    }
    return 0;
}

/* Whether row i claims path's extension. */
static int has_extension(size_t i, const char *path)
{
    const char *dot = path ? strrchr(path, '.') : NULL;
    if (!dot || strchr(dot, '/')) return 0;
    return in_list(cm_mesh_format_rows[i].extensions, dot + 1, strlen(dot + 1));
}

cm_mesh_format cm_mesh_format_of_extension(const char *path)
{
    for (size_t i = 0; i < cm_mesh_format_row_count; ++i)
        if (has_extension(i, path) && !cm_mesh_format_rows[i].sniff) return cm_mesh_format_rows[i].format;
    for (size_t i = 0; i < cm_mesh_format_row_count; ++i)
        if (has_extension(i, path)) return cm_mesh_format_rows[i].format;
    return CM_FORMAT_UNKNOWN;
}

/* The format of an existing file: the first row with the extension whose content test
 * accepts the file's first bytes, else the extension's default row. A file that cannot be
 * read goes to the default row, whose reader reports why. */
static cm_mesh_format format_of_content(const char *path)
{
    char head[4097];
    size_t n = 0;
    int have = 0;
    for (size_t i = 0; i < cm_mesh_format_row_count; ++i) {
        const cm_mesh_format_row *r = &cm_mesh_format_rows[i];
        if (!r->sniff || !has_extension(i, path)) continue;
        if (!have) {
            have = 1;
            /* the input rule (core.h): opening a FIFO would block */
            FILE *f = cm_file_open_quiet(path, NULL);
            if (f) {
                n = fread(head, 1, sizeof head - 1, f);
                fclose(f);
            }
            head[n] = '\0';
        }
        if (n && r->sniff(head, n)) return r->format;
    }
    return cm_mesh_format_of_extension(path);
}

/* An OpenFOAM case or polyMesh directory: a trailing '/', or (unless the name ends in a mesh
 * file extension) an existing directory, a last component named polyMesh, or one without an
 * extension that is not an existing file. */
int cm_foam_is_path(const char *path)
{
    if (!path || !*path) return 0;
    size_t l = strlen(path);
    if (path[l - 1] == '/') return 1;
    /* a name with a file format's extension stays that format, even if it is a directory */
    if (cm_mesh_format_of_extension(path) != CM_FORMAT_UNKNOWN) return 0;
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    struct stat st;
    if (stat(path, &st) == 0) return S_ISDIR(st.st_mode);
    return strcmp(base, "polyMesh") == 0 || strchr(base, '.') == NULL;
}

cm_mesh_format cm_mesh_format_from_path(const char *path)
{
    for (size_t i = 0; i < cm_mesh_format_row_count; ++i)
        if (cm_mesh_format_rows[i].claims && cm_mesh_format_rows[i].claims(path)) return cm_mesh_format_rows[i].format;
    return format_of_content(path);
}

/* The format to write a mesh in: the format it was read from when that format claims the
 * path (so that a Fluent .msh is written back as Fluent, changing only its nodes), else the
 * path's format as for reading, without looking into an existing file of that name. */
static cm_mesh_format format_to_write(const cm_mesh *mesh, const char *path)
{
    for (size_t i = 0; i < cm_mesh_format_row_count; ++i)
        if (cm_mesh_format_rows[i].claims && cm_mesh_format_rows[i].claims(path)) return cm_mesh_format_rows[i].format;
    const cm_mesh_format origin = cm_mesh_origin_format(mesh);
    for (size_t i = 0; i < cm_mesh_format_row_count; ++i)
        if (cm_mesh_format_rows[i].format == origin && has_extension(i, path)) return origin;
    return cm_mesh_format_of_extension(path);
}

/* ".msh .vtu ... .stl, or an OpenFOAM case directory": the extensions of the rows in order,
 * each once, then the directory formats. */
static char format_list[512];
static pthread_once_t format_list_once = PTHREAD_ONCE_INIT;

static void add_text(size_t *at, const char *text, size_t n)
{
    for (size_t i = 0; i < n && *at + 1 < sizeof format_list; ++i) format_list[(*at)++] = text[i];
    format_list[*at] = '\0';
}

static void compose_format_list(void)
{
    size_t at = 0;
    for (size_t i = 0; i < cm_mesh_format_row_count; ++i)
        for (const char *w = cm_mesh_format_rows[i].extensions; w && *w;) {
            const char *e = strchr(w, ' ');
            const size_t len = e ? (size_t)(e - w) : strlen(w);
            int earlier = 0; /* an extension two formats share is named once */
            for (size_t j = 0; j < i; ++j) earlier |= in_list(cm_mesh_format_rows[j].extensions, w, len);
            if (!earlier) {
                if (at) add_text(&at, " ", 1);
                add_text(&at, ".", 1);
                add_text(&at, w, len);
            }
            w = e ? e + 1 : NULL;
        }
    for (size_t i = 0; i < cm_mesh_format_row_count; ++i)
        if (cm_mesh_format_rows[i].described) {
            add_text(&at, ", or ", 5);
            add_text(&at, cm_mesh_format_rows[i].described, strlen(cm_mesh_format_rows[i].described));
        }
}

const char *cm_mesh_format_list(void)
{
    pthread_once(&format_list_once, compose_format_list);
    return format_list;
}

static cm_status unknown_extension(cm_context *ctx, const char *fn, const char *path)
{
    return cm_error(ctx, CM_ERR_UNSUPPORTED,
                    "%s: %s: unknown mesh extension (expected one of %s)", fn,
                    path ? path : "(null)", cm_mesh_format_list());
}

cm_status cm_mesh_read(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    if (!mesh) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_read: mesh is NULL");
    *mesh = NULL;
    const cm_mesh_format_row *row = cm_mesh_format_row_of(cm_mesh_format_from_path(path));
    if (!row || !row->read) return unknown_extension(ctx, "cm_mesh_read", path);
    cm_status s = row->read(ctx, path, mesh);
    if (s < 0) return s;
    /* Every reader's output goes through the same checks, so no reader can let an out-of-range
     * index or a NaN through to the algorithms. */
    cm_status v = cm_mesh_validate(ctx, *mesh, path);
    if (v != CM_OK) {
        cm_mesh_destroy(mesh);
        return v;
    }
    return s;
}

cm_status cm_mesh_write(cm_context *ctx, const cm_mesh *mesh, const char *path,
                        const cm_mesh_write_options *opt)
{
    cm_mesh_write_options defaults;
    cm_mesh_write_options_init(&defaults);
    if (!opt) opt = &defaults;
    if (!mesh) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write: mesh is NULL");
    const cm_mesh_format_row *row = cm_mesh_format_row_of(format_to_write(mesh, path));
    if (!row || !row->write) return unknown_extension(ctx, "cm_mesh_write", path);
    /* A result with a non-finite coordinate is never written, in any format: no reader
     * (cm_mesh_read above) would take the file back. Every input is checked where it is read,
     * so such a mesh comes from a computation that overflowed: the result is rejected
     * (README, "Exit codes"), before anything is created on disk. */
    for (size_t i = 0; i < 3 * mesh->n_nodes; ++i)
        if (!isfinite(mesh->xyz[i]))
            return cm_error(ctx, CM_ERR_REJECTED,
                            "cm_mesh_write: node %zu (0-based, tag %lld) has a non-finite coordinate "
                            "(%c = %g), the result is not written: %s",
                            i / 3,
                            (long long)(mesh->node_tag ? mesh->node_tag[i / 3] : (int64_t)(i / 3) + 1),
                            "xyz"[i % 3], mesh->xyz[i], path ? path : "(null)");
    return row->write(ctx, mesh, path, opt);
}
