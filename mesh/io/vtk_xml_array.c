/* Decoding of one VTK XML <DataArray>: ascii text, inline base64 ("binary") and appended
 * data (raw or base64), each with or without vtkZLibDataCompressor blocks. */
#include "vtk_internal.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

/* Bytes of the encoded payload, read in order: raw appended bytes or a base64 stream. */
typedef struct source {
    int base64;
    const uint8_t *raw, *raw_end;
    cm_b64 b;
} source;

static int src_read(source *s, void *dst, size_t n)
{
    if (s->base64) return cm_b64_read(&s->b, dst, n);
    if ((size_t)(s->raw_end - s->raw) < n) return -2;
    memcpy(dst, s->raw, n);
    s->raw += n;
    return 0;
}

/* Upper bound of the bytes still available. */
static size_t src_avail(const source *s)
{
    if (s->base64) return (size_t)(s->b.end - s->b.p) / 4 * 3 + 3 + (size_t)(s->b.npend - s->b.ipend);
    return (size_t)(s->raw_end - s->raw);
}

static cm_status fail(const cm_vtu_decoder *d, const cm_vtu_array *a, size_t pos, const char *fmt,
                      const char *detail)
{
    return cm_error(d->ctx, CM_ERR_FORMAT, "%s: byte offset %zu: DataArray '%s': %s%s", d->path, pos,
                    a->name ? a->name : "", fmt, detail ? detail : "");
}

static cm_status src_fail(const cm_vtu_decoder *d, const cm_vtu_array *a, size_t pos, int r)
{
    return fail(d, a, pos,
                r == -1 ? "invalid base64 data" : "data ends early (truncated file or wrong offset)",
                NULL);
}

static int read_header_int(source *s, int hdr64, uint64_t *v)
{
    if (hdr64) return src_read(s, v, 8);
    uint32_t w = 0;
    int r = src_read(s, &w, 4);
    *v = w;
    return r;
}

/* A header that declares more values than the array may hold is refused before anything is
 * allocated or inflated: a few MB of zlib data can claim gigabytes. */
static cm_status too_many(const cm_vtu_decoder *d, const cm_vtu_array *a, size_t pos, uint64_t values,
                          size_t max_values)
{
    char detail[96];
    snprintf(detail, sizeof detail, "%llu values, more than the %zu expected", (unsigned long long)values,
             max_values);
    return fail(d, a, pos, "header declares ", detail);
}

static cm_status decode_binary(const cm_vtu_decoder *d, cm_vtu_array *a, source *s, size_t pos,
                               size_t max_values)
{
    const size_t w = cm_vtk_scalar_size(a->type);
    int r;
    if (!d->compressed) {
        uint64_t nbytes;
        if ((r = read_header_int(s, d->hdr64, &nbytes))) return src_fail(d, a, pos, r);
        if (nbytes / w > max_values) return too_many(d, a, pos, nbytes / w, max_values);
        if (nbytes > src_avail(s)) return fail(d, a, pos, "data ends early (header claims more bytes than the file holds)", NULL);
        if (nbytes % w) return fail(d, a, pos, "byte count is not a multiple of the value size", NULL);
        a->bytes = malloc(nbytes ? nbytes : 1);
        if (!a->bytes) return cm_error(d->ctx, CM_ERR_NOMEM, "%s: out of memory", d->path);
        if ((r = src_read(s, a->bytes, nbytes))) return src_fail(d, a, pos, r);
        a->count = nbytes / w;
        return CM_OK;
    }
    const size_t hw = d->hdr64 ? 8 : 4;
    uint64_t nb, bs, last;
    if ((r = read_header_int(s, d->hdr64, &nb)) || (r = read_header_int(s, d->hdr64, &bs)) ||
        (r = read_header_int(s, d->hdr64, &last)))
        return src_fail(d, a, pos, r);
    if (nb > src_avail(s) / hw) return fail(d, a, pos, "compression header: block count exceeds the data", NULL);
    if (nb > 0 && (bs == 0 || last > bs || bs > UINT64_MAX / nb))
        return fail(d, a, pos, "compression header: bad block sizes", NULL);
    {
        const uint64_t declared = nb == 0 ? 0 : (nb - 1) * bs + (last ? last : bs);
        if (declared / w > max_values) return too_many(d, a, pos, declared / w, max_values);
    }
    uint64_t *cs = malloc((nb ? nb : 1) * sizeof *cs);
    size_t *coff = malloc((nb + 1) * sizeof *coff);
    if (!cs || !coff) {
        free(cs);
        free(coff);
        return cm_error(d->ctx, CM_ERR_NOMEM, "%s: out of memory", d->path);
    }
    cm_status st = CM_OK;
    uint64_t csum = 0;
    coff[0] = 0;
    for (uint64_t i = 0; i < nb && st == CM_OK; ++i) {
        if ((r = read_header_int(s, d->hdr64, &cs[i]))) st = src_fail(d, a, pos, r);
        else if (cs[i] > src_avail(s)) st = fail(d, a, pos, "compression header: block size exceeds the data", NULL);
        else {
            csum += cs[i];
            coff[i + 1] = (size_t)csum;
        }
    }
    /* zlib expands at most ~1032:1, so a header asking for more is corrupt: refuse it before
     * allocating. */
    uint64_t total = nb == 0 ? 0 : (nb - 1) * bs + (last ? last : bs);
    if (st == CM_OK && csum > src_avail(s)) st = fail(d, a, pos, "compressed blocks exceed the data", NULL);
    if (st == CM_OK && total > 1100 * csum + 1024 * nb)
        st = fail(d, a, pos, "compression header: sizes are inconsistent", NULL);
    if (st == CM_OK && total % w) st = fail(d, a, pos, "byte count is not a multiple of the value size", NULL);
    uint8_t *comp = NULL;
    if (st == CM_OK) {
        comp = malloc(csum ? csum : 1);
        a->bytes = malloc(total ? total : 1);
        if (!comp || !a->bytes) st = cm_error(d->ctx, CM_ERR_NOMEM, "%s: out of memory", d->path);
    }
    if (st == CM_OK && (r = src_read(s, comp, csum))) st = src_fail(d, a, pos, r);
    if (st == CM_OK) {
        long bad = -1;
        const long n_blocks = (long)nb;
        const int threads = cm_context_threads_for(d->ctx, nb, 1);
#pragma omp parallel for schedule(static) num_threads(threads) if (n_blocks > 8)
        for (long i = 0; i < n_blocks; ++i) {
            uLongf want = (uLongf)(i == n_blocks - 1 && last ? last : bs);
            uLongf got = want;
            int zr = uncompress(a->bytes + (size_t)i * bs, &got, comp + coff[i], (uLong)cs[i]);
            if (zr != Z_OK || got != want) {
#pragma omp critical(cm_vtu_inflate)
                if (bad < 0 || i < bad) bad = i;
            }
        }
        if (bad >= 0) {
            char detail[64];
            snprintf(detail, sizeof detail, " (block %ld of %ld)", bad + 1, n_blocks);
            st = fail(d, a, pos, "corrupt zlib data", detail);
        }
    }
    free(comp);
    free(cs);
    free(coff);
    if (st == CM_OK) a->count = (size_t)(total / w);
    return st;
}

static int is_ws(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

static cm_status decode_ascii(const cm_vtu_decoder *d, cm_vtu_array *a, size_t b, size_t e,
                              size_t max_values)
{
    const char *t = d->x->data;
    size_t n = 0;
    for (size_t p = b; p < e;) {
        while (p < e && is_ws(t[p])) ++p;
        if (p >= e) break;
        ++n;
        while (p < e && !is_ws(t[p])) ++p;
    }
    if (n > max_values)
        return cm_error(d->ctx, CM_ERR_FORMAT, "%s:%ld: DataArray '%s': %zu values, more than the %zu expected",
                        d->path, cm_xml_line(d->x, b), a->name ? a->name : "", n, max_values);
    /* Integers are kept as int64 (uint64 for UInt64), floats in their own width so that a
     * Float32 value reads as the same double VTK gets. */
    cm_vtk_scalar keep = cm_vtk_scalar_is_float(a->type) || a->type == CM_VTK_UINT64 ? a->type : CM_VTK_INT64;
    size_t w = cm_vtk_scalar_size(keep);
    a->bytes = malloc(n ? n * w : 1);
    if (!a->bytes) return cm_error(d->ctx, CM_ERR_NOMEM, "%s: out of memory", d->path);
    size_t i = 0;
    for (size_t p = b; p < e && i < n;) {
        while (p < e && is_ws(t[p])) ++p;
        size_t q = p;
        while (q < e && !is_ws(t[q])) ++q;
        char buf[64], *end;
        size_t len = q - p;
        if (len >= sizeof buf) len = sizeof buf - 1;
        memcpy(buf, t + p, len);
        buf[len] = '\0';
        errno = 0;
        int ok;
        switch (keep) {
        case CM_VTK_FLOAT32: { float v = strtof(buf, &end); memcpy(a->bytes + i * w, &v, w); ok = end != buf && !*end; break; }
        case CM_VTK_FLOAT64: { double v = strtod(buf, &end); memcpy(a->bytes + i * w, &v, w); ok = end != buf && !*end; break; }
        case CM_VTK_UINT64: { unsigned long long v = strtoull(buf, &end, 10); uint64_t u = v; memcpy(a->bytes + i * w, &u, w); ok = end != buf && !*end && !errno && buf[0] != '-'; break; }
        default: { long long v = strtoll(buf, &end, 10); int64_t s = v; memcpy(a->bytes + i * w, &s, w); ok = end != buf && !*end && !errno; break; }
        }
        if (!ok || q - p >= sizeof buf)
            return cm_error(d->ctx, CM_ERR_FORMAT, "%s:%ld: DataArray '%s': expected a number, got '%.*s'",
                            d->path, cm_xml_line(d->x, p), a->name ? a->name : "",
                            (int)(q - p > 40 ? 40 : q - p), t + p);
        ++i;
        p = q;
    }
    a->type = keep;
    a->count = n;
    return CM_OK;
}

cm_status cm_vtu_array_decode(const cm_vtu_decoder *d, int elem, size_t max_values, cm_vtu_array *a)
{
    const cm_xml *x = d->x;
    memset(a, 0, sizeof *a);
    a->name = cm_xml_get(x, elem, "Name");
    const char *type = cm_xml_get(x, elem, "type");
    const char *format = cm_xml_get(x, elem, "format");
    const char *ncomp = cm_xml_get(x, elem, "NumberOfComponents");
    const long line = cm_xml_line(x, x->elem[elem].pos);
    a->type = cm_vtk_scalar_from_xml(type);
    if (a->type == CM_VTK_SCALAR_COUNT) {
        a->unsupported_type = 1;
        return cm_error(d->ctx, CM_ERR_UNSUPPORTED, "%s:%ld: DataArray '%s': type '%s' is not numeric",
                        d->path, line, a->name ? a->name : "", type ? type : "(none)");
    }
    a->components = 1;
    if (ncomp) {
        char *end;
        long v = strtol(ncomp, &end, 10);
        if (*end || v < 1 || v > 1000)
            return cm_error(d->ctx, CM_ERR_FORMAT, "%s:%ld: DataArray '%s': bad NumberOfComponents '%s'",
                            d->path, line, a->name ? a->name : "", ncomp);
        a->components = (int)v;
    }
    const cm_xml_elem *el = &x->elem[elem];
    if (!format || !strcmp(format, "ascii")) return decode_ascii(d, a, el->text_begin, el->text_end, max_values);
    source s;
    memset(&s, 0, sizeof s);
    size_t pos;
    if (!strcmp(format, "binary")) {
        s.base64 = 1;
        cm_b64_init(&s.b, x->data + el->text_begin, x->data + el->text_end);
        pos = el->text_begin;
    } else if (!strcmp(format, "appended")) {
        const char *off = cm_xml_get(x, elem, "offset");
        char *end = NULL;
        errno = 0;
        unsigned long long o = off ? strtoull(off, &end, 10) : 0;
        if (!off || *end || errno || off[0] == '-')
            return cm_error(d->ctx, CM_ERR_FORMAT, "%s:%ld: DataArray '%s': appended data needs a valid offset",
                            d->path, line, a->name ? a->name : "");
        if (x->appended == SIZE_MAX)
            return cm_error(d->ctx, CM_ERR_FORMAT, "%s:%ld: DataArray '%s': format=\"appended\" but the file has no <AppendedData>",
                            d->path, line, a->name ? a->name : "");
        if (o > d->app_end - x->appended)
            return cm_error(d->ctx, CM_ERR_FORMAT, "%s: byte offset %zu: DataArray '%s': offset %llu is past the end of the appended data (truncated file?)",
                            d->path, x->appended, a->name ? a->name : "", o);
        pos = x->appended + (size_t)o;
        if (d->app_base64) {
            s.base64 = 1;
            cm_b64_init(&s.b, x->data + pos, x->data + d->app_end);
        } else {
            s.raw = (const uint8_t *)x->data + pos;
            s.raw_end = (const uint8_t *)x->data + d->app_end;
        }
    } else {
        return cm_error(d->ctx, CM_ERR_FORMAT, "%s:%ld: DataArray '%s': unknown format '%s'", d->path,
                        line, a->name ? a->name : "", format);
    }
    return decode_binary(d, a, &s, pos, max_values);
}

void cm_vtu_array_free(cm_vtu_array *a)
{
    free(a->bytes);
    a->bytes = NULL;
    a->count = 0;
}
