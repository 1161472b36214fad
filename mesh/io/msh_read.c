/* gmsh .msh reader: versions 2.2 and 4.1, ASCII and little-endian binary, parsed from memory.
 * Sections: $MeshFormat, $PhysicalNames, $Entities, $Nodes, $Elements, $NodeData and
 * $ElementData; other sections are skipped. Node order inside cells is converted to VTK's. */
#include "msh_read_internal.h"
#include "formats.h"

#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

/* ---- messages ---- */

cm_status cm_msh_err(cm_msh_reader *r, cm_status code, int bin, size_t at, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (bin) return cm_error(r->ctx, code, "%s: byte %zu: %s", r->t.path, at, msg);
    return cm_error(r->ctx, code, "%s:%ld: %s", r->t.path, r->t.line, msg);
}

/* "expected <what>, got '<token>'" at the current line / byte. */
static cm_status expected(cm_msh_reader *r, int bin, const char *what, const char *tok, size_t len)
{
    if (bin) {
        return cm_msh_err(r, CM_ERR_FORMAT, 1, r->t.pos, "expected %s, got end of file (%zu bytes left)",
                          what, r->t.size - r->t.pos);
    }
    if (!tok) return cm_msh_err(r, CM_ERR_FORMAT, 0, 0, "expected %s, got end of file", what);
    return cm_msh_err(r, CM_ERR_FORMAT, 0, 0, "expected %s, got '%.*s'", what,
                      (int)(len > 40 ? 40 : len), tok);
}

/* ---- values: an ASCII token, or raw little-endian bytes when bin ---- */

static int parse_i64(const char *s, size_t len, int64_t *v)
{
    size_t i = 0;
    int neg = 0;
    if (len > 0 && (s[0] == '-' || s[0] == '+')) {
        neg = s[0] == '-';
        i = 1;
    }
    if (i == len) return 0;
    uint64_t x = 0;
    for (; i < len; ++i) {
        unsigned d = (unsigned)(unsigned char)s[i] - '0';
        if (d > 9 || x > (UINT64_MAX - d) / 10) return 0;
        x = x * 10 + d;
    }
    if (x > (uint64_t)INT64_MAX + (uint64_t)neg) return 0;
    *v = neg ? (x == 0 ? 0 : -(int64_t)(x - 1) - 1) : (int64_t)x;
    return 1;
}

const unsigned char *cm_msh_bytes(cm_msh_reader *r, size_t n, const char *what)
{
    if (r->t.size - r->t.pos < n) {
        expected(r, 1, what, NULL, 0);
        return NULL;
    }
    const unsigned char *p = (const unsigned char *)r->t.data + r->t.pos;
    r->t.pos += n;
    return p;
}

int64_t cm_msh_get_size(const unsigned char *p, int dsize)
{
    if (dsize == 4) {
        uint32_t v;
        memcpy(&v, p, 4);
        return (int64_t)v;
    }
    uint64_t v;
    memcpy(&v, p, 8);
    return v > (uint64_t)INT64_MAX ? -1 : (int64_t)v;
}

cm_status cm_msh_int(cm_msh_reader *r, int bin, const char *what, int64_t *v)
{
    if (bin) {
        const unsigned char *p = cm_msh_bytes(r, 4, what);
        if (!p) return CM_ERR_FORMAT;
        int32_t x;
        memcpy(&x, p, 4);
        *v = x;
        return CM_OK;
    }
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(&r->t, &tok, &len) || !parse_i64(tok, len, v))
        return expected(r, 0, what, tok, len);
    return CM_OK;
}

/* A count or tag (size_t in binary 4.1): never negative. */
cm_status cm_msh_size(cm_msh_reader *r, int bin, const char *what, int64_t *v)
{
    size_t at = r->t.pos;
    if (bin) {
        const unsigned char *p = cm_msh_bytes(r, (size_t)r->dsize, what);
        if (!p) return CM_ERR_FORMAT;
        *v = cm_msh_get_size(p, r->dsize);
        if (*v < 0) return cm_msh_err(r, CM_ERR_FORMAT, 1, at, "expected %s, got a value above 2^63", what);
        return CM_OK;
    }
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(&r->t, &tok, &len) || !parse_i64(tok, len, v) || *v < 0)
        return expected(r, 0, what, tok, len);
    return CM_OK;
}

cm_status cm_msh_double(cm_msh_reader *r, int bin, const char *what, double *v)
{
    if (bin) {
        const unsigned char *p = cm_msh_bytes(r, 8, what);
        if (!p) return CM_ERR_FORMAT;
        memcpy(v, p, 8);
        return CM_OK;
    }
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(&r->t, &tok, &len)) return expected(r, 0, what, NULL, 0);
    /* The data is NUL-terminated and tokens end at white space, so strtod stays inside. */
    char *end = NULL;
    *v = strtod(tok, &end);
    if (end != tok + len) return expected(r, 0, what, tok, len);
    return CM_OK;
}

/* A coordinate: like cm_msh_double but NaN and infinities are errors. */
cm_status cm_msh_coord(cm_msh_reader *r, int bin, const char *what, double *v)
{
    size_t at = r->t.pos;
    long line = r->t.line;
    cm_status s = cm_msh_double(r, bin, what, v);
    if (s != CM_OK) return s;
    if (!isfinite(*v)) {
        if (bin) return cm_msh_err(r, CM_ERR_FORMAT, 1, at, "expected a finite %s, got %g", what, *v);
        r->t.line = line;
        return cm_msh_err(r, CM_ERR_FORMAT, 0, 0, "expected a finite %s, got %g", what, *v);
    }
    return CM_OK;
}

/* Count read from the file, checked against the bytes left before anything is allocated:
 * each item takes at least min_bytes, so a larger count cannot be honest. */
cm_status cm_msh_count(cm_msh_reader *r, int bin, const char *what, size_t min_bytes, int64_t *v)
{
    size_t at = r->t.pos;
    long line = r->t.line;
    cm_status s = cm_msh_size(r, bin, what, v);
    if (s != CM_OK) return s;
    size_t left = r->t.size - r->t.pos;
    if (min_bytes > 0 && (uint64_t)*v > left / min_bytes) {
        if (bin)
            return cm_msh_err(r, CM_ERR_FORMAT, 1, at,
                              "expected %s that fits the %zu bytes left, got %lld", what, left,
                              (long long)*v);
        r->t.line = line;
        return cm_msh_err(r, CM_ERR_FORMAT, 0, 0, "expected %s that fits the %zu bytes left, got %lld",
                          what, left, (long long)*v);
    }
    return CM_OK;
}

cm_status cm_msh_expect(cm_msh_reader *r, int bin, const char *word)
{
    const char *tok = NULL;
    size_t len = 0;
    size_t at = r->t.pos;
    if (!cm_text_token(&r->t, &tok, &len)) {
        if (bin) return cm_msh_err(r, CM_ERR_FORMAT, 1, at, "expected %s, got end of file", word);
        return expected(r, 0, word, NULL, 0);
    }
    if (len == strlen(word) && memcmp(tok, word, len) == 0) return CM_OK;
    if (bin)
        return cm_msh_err(r, CM_ERR_FORMAT, 1, (size_t)(tok - r->t.data),
                          "expected %s (are the counts right?), got '%.*s'", word,
                          (int)(len > 40 ? 40 : len), tok);
    return expected(r, 0, word, tok, len);
}

/* Binary data starts right after the newline that ends the header line. */
void cm_msh_to_binary(cm_msh_reader *r)
{
    cm_text_next_line(&r->t);
}

/* A name in double quotes (may hold spaces), or a bare token. Caller frees. */
cm_status cm_msh_string(cm_msh_reader *r, const char *what, char **out)
{
    *out = NULL;
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_skip_space(&r->t)) return expected(r, 0, what, NULL, 0);
    const char *s = r->t.data + r->t.pos;
    if (*s == '"') {
        const char *e = s + 1;
        const char *end = r->t.data + r->t.size;
        while (e < end && *e != '"' && *e != '\n') ++e;
        if (e >= end || *e != '"') return expected(r, 0, what, s, (size_t)(e - s));
        tok = s + 1;
        len = (size_t)(e - s - 1);
        r->t.pos = (size_t)(e + 1 - r->t.data);
    } else if (!cm_text_token(&r->t, &tok, &len)) {
        return expected(r, 0, what, NULL, 0);
    }
    *out = malloc(len + 1);
    if (!*out) return cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->t.path);
    memcpy(*out, tok, len);
    (*out)[len] = '\0';
    return CM_OK;
}

/* ---- sections ---- */

static cm_status read_format(cm_msh_reader *r)
{
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(&r->t, &tok, &len)) return expected(r, 0, "msh version", NULL, 0);
    char buf[16] = {0};
    memcpy(buf, tok, len < sizeof buf - 1 ? len : sizeof buf - 1);
    char *end = NULL;
    double v = strtod(buf, &end);
    if (end == buf || *end) return expected(r, 0, "msh version", tok, len);
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
        return expected(r, 0, "$MeshFormat (a gmsh .msh file)", tok, len);
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
            return expected(r, 0, "a section such as $Nodes", tok, len);
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
