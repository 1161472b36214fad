/* gmsh .msh reader: versions 2.2 and 4.1, ASCII and little-endian binary, parsed from memory.
 * Sections: $MeshFormat, $PhysicalNames, $Entities, $Nodes, $Elements, $NodeData and
 * $ElementData; other sections are skipped. Node order inside cells is converted to VTK's. */
#include "msh_read_internal.h"
#include "formats.h"

#include <stdlib.h>
#include <string.h>

/* ---- sections ---- */
static cm_status read_format(cm_msh_reader *r)
{
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(&r->t, &tok, &len)) return cm_msh_expected(r, 0, "msh version", NULL, 0);
    char buf[16] = {0};
    memcpy(buf, tok, len < sizeof buf - 1 ? len : sizeof buf - 1);
    char *end = NULL;
    double v = strtod(buf, &end);
    if (end == buf || *end) return cm_msh_expected(r, 0, "msh version", tok, len);
    if (v == 2.2) r->version = 22;
    else if (v == 4.1) r->version = 41;
    else
        return cm_msh_err(r, CM_ERR_UNSUPPORTED, 0, 0,
                          "msh version %.*s is not supported (versions 2.2 and 4.1 are)",
                          (int)(len > 16 ? 16 : len), tok);
    int64_t ft, ds;
    cm_status s = cm_msh_int(r, 0, "file type (0 ASCII, 1 binary)", &ft);
    if (s == CM_OK && ft != 0 && ft != 1)
        return cm_msh_err(r, CM_ERR_FORMAT, 0, 0, "expected file type 0 or 1, got %lld", (long long)ft);
    if (s == CM_OK) s = cm_msh_int(r, 0, "data size", &ds);
    if (s != CM_OK) return s;
    r->binary = (int)ft;
    if (r->version == 22 && ds != 8)
        return cm_msh_err(r, CM_ERR_UNSUPPORTED, 0, 0, "expected data size 8, got %lld", (long long)ds);
    if (r->version == 41 && ds != 4 && ds != 8)
        return cm_msh_err(r, CM_ERR_UNSUPPORTED, 0, 0, "expected data size 4 or 8, got %lld", (long long)ds);
    r->dsize = r->version == 41 ? (int)ds : 4;
    if (r->binary) {
        if (!cm_host_little_endian())
            return cm_msh_err(r, CM_ERR_UNSUPPORTED, 0, 0, "binary .msh needs a little-endian host");
        cm_msh_to_binary(r);
        size_t at = r->t.pos;
        const unsigned char *p = cm_msh_bytes(r, 4, "the integer 1 (endianness marker)");
        if (!p) return CM_ERR_FORMAT;
        uint32_t one;
        memcpy(&one, p, 4);
        if (one == 0x01000000u)
            return cm_msh_err(r, CM_ERR_UNSUPPORTED, 1, at,
                              "big-endian binary .msh is not supported (endianness marker reads "
                              "0x01000000); re-export it on a little-endian machine or as ASCII");
        if (one != 1)
            return cm_msh_err(r, CM_ERR_FORMAT, 1, at,
                              "expected the integer 1 (endianness marker), got 0x%08x", one);
    }
    return cm_msh_expect(r, r->binary, "$EndMeshFormat");
}

static cm_status read_physical_names(cm_msh_reader *r)
{
    int64_t n;
    cm_status s = cm_msh_count(r, 0, "number of physical names", 6, &n);
    for (int64_t i = 0; s == CM_OK && i < n; ++i) {
        int64_t dim = 0, tag = 0;
        char *name = NULL;
        s = cm_msh_int(r, 0, "physical dimension", &dim);
        if (s == CM_OK && (dim < 0 || dim > 3))
            s = cm_msh_err(r, CM_ERR_FORMAT, 0, 0, "expected a dimension 0..3, got %lld", (long long)dim);
        if (s == CM_OK) s = cm_msh_int(r, 0, "physical tag", &tag);
        if (s == CM_OK && (tag < INT32_MIN || tag > INT32_MAX))
            s = cm_msh_err(r, CM_ERR_FORMAT, 0, 0, "expected an int physical tag, got %lld", (long long)tag);
        if (s == CM_OK) s = cm_msh_string(r, "physical name in quotes", &name);
        if (s == CM_OK) s = cm_mesh_add_group(r->ctx, r->m, (int)dim, (int)tag, name);
        free(name);
    }
    return s == CM_OK ? cm_msh_expect(r, 0, "$EndPhysicalNames") : s;
}

/* Looks for "\n$End<name>" from the current position (binary-safe), counting lines. */
static cm_status skip_section(cm_msh_reader *r, const char *tok, size_t len)
{
    char end[80];
    if (len > 60) len = 60;
    int n = snprintf(end, sizeof end, "$End%.*s", (int)(len - 1), tok + 1);
    const char *p = r->t.data + r->t.pos, *stop = r->t.data + r->t.size;
    long line = r->t.line;
    for (; p + n <= stop; ++p) {
        if (*p == '\n') {
            ++line;
            if (p + 1 + n <= stop && memcmp(p + 1, end, (size_t)n) == 0) {
                r->t.pos = (size_t)(p + 1 - r->t.data);
                r->t.line = line;
                return cm_msh_expect(r, 0, end);
            }
        }
    }
    return cm_msh_err(r, CM_ERR_FORMAT, 0, 0, "expected %s to close %.*s, got end of file", end,
                      (int)len, tok);
}

static int word_is(const char *tok, size_t len, const char *word)
{
    return len == strlen(word) && memcmp(tok, word, len) == 0;
}

static cm_status read_sections(cm_msh_reader *r)
{
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(&r->t, &tok, &len) || !word_is(tok, len, "$MeshFormat"))
        return cm_msh_expected(r, 0, "$MeshFormat (a gmsh .msh file)", tok, len);
    cm_status s = read_format(r);
    while (s == CM_OK && cm_text_token(&r->t, &tok, &len)) {
        if (word_is(tok, len, "$PhysicalNames")) {
            s = read_physical_names(r);
        } else if (word_is(tok, len, "$Entities") && r->version == 41) {
            if (r->binary) cm_msh_to_binary(r);
            s = cm_msh_read_entities41(r);
        } else if (word_is(tok, len, "$Nodes")) {
            if (r->have_nodes) return cm_msh_err(r, CM_ERR_UNSUPPORTED, 0, 0, "a second $Nodes section");
            if (r->binary && r->version == 41) cm_msh_to_binary(r);
            s = r->version == 41 ? cm_msh_read_nodes41(r) : cm_msh_read_nodes22(r);
            r->have_nodes = 1;
        } else if (word_is(tok, len, "$Elements")) {
            if (!r->have_nodes) return cm_msh_err(r, CM_ERR_FORMAT, 0, 0, "expected $Nodes before $Elements");
            if (r->have_elements)
                return cm_msh_err(r, CM_ERR_UNSUPPORTED, 0, 0, "a second $Elements section");
            if (r->binary && r->version == 41) cm_msh_to_binary(r);
            s = r->version == 41 ? cm_msh_read_elements41(r) : cm_msh_read_elements22(r);
            if (s == CM_OK) s = cm_msh_map_cells(r);
            r->have_elements = 1;
        } else if (word_is(tok, len, "$NodeData") || word_is(tok, len, "$ElementData")) {
            s = cm_msh_read_data(r, word_is(tok, len, "$NodeData") ? CM_FIELD_NODE : CM_FIELD_CELL);
        } else if (word_is(tok, len, "$PartitionedEntities")) {
            return cm_msh_err(r, CM_ERR_UNSUPPORTED, 0, 0,
                              "partitioned meshes ($PartitionedEntities) are not supported; "
                              "save the mesh unpartitioned");
        } else if (len > 1 && tok[0] == '$' && !(len >= 4 && memcmp(tok, "$End", 4) == 0)) {
            s = skip_section(r, tok, len);
        } else {
            return cm_msh_expected(r, 0, "a section such as $Nodes", tok, len);
        }
    }
    if (s != CM_OK) return s;
    if (!r->have_nodes) return cm_error(r->ctx, CM_ERR_FORMAT, "%s: expected a $Nodes section, got none", r->t.path);
    if (!r->have_elements)
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s: expected an $Elements section, got none", r->t.path);
    return CM_OK;
}

cm_status cm_mesh_read_msh(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    if (!mesh) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_read_msh: mesh is NULL");
    *mesh = NULL;
    if (!path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_read_msh: path is NULL");
    char *data = NULL;
    size_t size = 0;
    cm_status s = cm_file_read(ctx, path, &data, &size);
    if (s != CM_OK) return s;
    cm_msh_reader r;
    memset(&r, 0, sizeof r);
    r.ctx = ctx;
    cm_text_init(&r.t, path, data, size);
    s = cm_mesh_create(ctx, &r.m);
    if (s == CM_OK) s = read_sections(&r);
    cm_msh_tagmap_free(&r.nodes);
    cm_msh_tagmap_free(&r.cells);
    free(r.ents);
    free(data);
    if (s != CM_OK) {
        cm_mesh_destroy(&r.m);
        return s;
    }
    *mesh = r.m;
    return CM_OK;
}
