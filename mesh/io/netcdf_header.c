/* The header of a netCDF classic file (CDF-1, CDF-2 "64-bit offset", CDF-5), walked before the
 * netCDF library opens it: the library takes every name length and element count of the
 * header as it stands and allocates it, so a 4 kB file that claims a 2 GB name costs 2 GB. Here
 * every length and count must fit in what is left of the file (a name of n bytes needs n
 * bytes, a list of n entries at least n times the smallest entry), which bounds what the
 * library can allocate by a small multiple of the file's size. Layout: the netCDF classic
 * format specification (NetCDF Users Guide, "File Format Specifications"). */
#include "netcdf_header.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

typedef struct scan {
    FILE *f;
    uint64_t pos, size; /* bytes read, file size */
    int wide;           /* CDF-5: counts, lengths and sizes are 8 bytes */
    int version;
    int bad;            /* end of file inside the header */
} scan;

static uint64_t get(scan *s, int bytes)
{
    unsigned char b[8];
    if (s->bad || fread(b, 1, (size_t)bytes, s->f) != (size_t)bytes) {
        s->bad = 1;
        return 0;
    }
    s->pos += (uint64_t)bytes;
    uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) v = v << 8 | b[i]; /* big-endian */
    return v;
}

static uint64_t left(const scan *s) { return s->size > s->pos ? s->size - s->pos : 0; }

static int skip(scan *s, uint64_t n)
{
    if (n > left(s)) return 0;
    if (fseeko(s->f, (off_t)n, SEEK_CUR) != 0) return 0;
    s->pos += n;
    return 1;
}

/* a count that needs at least `each` bytes per entry in what is left */
static int count(scan *s, uint64_t *n, uint64_t each)
{
    *n = get(s, s->wide ? 8 : 4);
    return !s->bad && *n <= left(s) / each;
}

static int name(scan *s)
{
    uint64_t n;
    return count(s, &n, 1) && skip(s, (n + 3) & ~(uint64_t)3);
}

static int type_size(uint64_t t, int wide)
{
    static const int sz[12] = {0, 1, 1, 2, 4, 4, 8, 1, 2, 4, 8, 8};
    return t >= 1 && t <= (wide ? 11u : 6u) ? sz[t] : 0;
}

/* an attribute list: ABSENT (0, 0) or NC_ATTRIBUTE nelems [name type nelems values] */
static int attributes(scan *s)
{
    const uint64_t tag = get(s, 4);
    uint64_t n;
    if (!count(s, &n, 12)) return 0;
    if (tag == 0) return n == 0;
    if (tag != 0x0C) return 0;
    for (uint64_t i = 0; i < n; ++i) {
        if (!name(s)) return 0;
        const int ts = type_size(get(s, 4), s->wide);
        uint64_t m;
        if (!ts || !count(s, &m, (uint64_t)ts)) return 0;
        if (!skip(s, (m * (uint64_t)ts + 3) & ~(uint64_t)3)) return 0;
    }
    return 1;
}

cm_status cm_netcdf_check_header(cm_context *ctx, const char *path, uint64_t file_size)
{
    FILE *f = fopen(path, "rb");
    if (!f) return cm_error(ctx, CM_ERR_IO, "cm_mesh_read: %s: %s", path, strerror(errno));
    scan s = {f, 0, file_size, 0, 0, 0};
    unsigned char magic[4];
    if (fread(magic, 1, 4, f) != 4 || memcmp(magic, "CDF", 3) != 0) {
        fclose(f);
        return CM_OK; /* not classic netCDF (HDF5-based netCDF-4): HDF5 checks its own */
    }
    s.pos = 4;
    s.version = magic[3];
    s.wide = s.version == 5;
    const char *what = "the record count";
    get(&s, s.wide ? 8 : 4); /* numrecs */
    int ok = !s.bad;
    /* dimensions: ABSENT or NC_DIMENSION nelems [name length] */
    if (ok) {
        what = "the dimension list";
        const uint64_t tag = get(&s, 4);
        uint64_t n;
        ok = count(&s, &n, 8) && (tag == 0x0A || (tag == 0 && n == 0));
        for (uint64_t i = 0; ok && i < n; ++i) ok = name(&s) && (get(&s, s.wide ? 8 : 4), !s.bad);
    }
    if (ok) {
        what = "the global attributes";
        ok = attributes(&s);
    }
    /* variables: ABSENT or NC_VARIABLE nelems [name ndims dimids attributes type vsize begin] */
    if (ok) {
        what = "the variable list";
        const uint64_t tag = get(&s, 4);
        uint64_t n;
        ok = count(&s, &n, 24) && (tag == 0x0B || (tag == 0 && n == 0));
        for (uint64_t i = 0; ok && i < n; ++i) {
            uint64_t nd;
            ok = name(&s) && count(&s, &nd, s.wide ? 8 : 4) && skip(&s, nd * (s.wide ? 8 : 4)) &&
                 attributes(&s) && type_size(get(&s, 4), s.wide) != 0;
            if (ok) {
                get(&s, s.wide ? 8 : 4);           /* vsize */
                get(&s, s.version == 1 ? 4 : 8);   /* begin */
                ok = !s.bad;
            }
        }
    }
    fclose(f);
    if (!ok)
        return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: byte %llu: corrupt netCDF header "
                        "(%s: a length or count beyond the end of the file, or a bad tag)",
                        path, (unsigned long long)s.pos, what);
    return CM_OK;
}
