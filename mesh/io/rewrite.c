/* Writing a mesh back into the files it was read from, coordinates only (rewrite.h). */
#define _POSIX_C_SOURCE 200809L
#include "rewrite.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#ifdef _OPENMP
#include <omp.h>
#endif

cm_rewrite_source *cm_rewrite_source_new(void)
{
    return calloc(1, sizeof(cm_rewrite_source));
}

void cm_rewrite_source_free(void *source)
{
    cm_rewrite_source *src = source;
    if (!src) return;
    for (size_t i = 0; i < src->n_files; ++i) {
        free(src->files[i].path);
        free(src->files[i].name);
        free(src->files[i].spans);
    }
    free(src->files);
    if (src->free_format) src->free_format(src->format);
    free(src);
}

static char *dup_text(const char *s)
{
    if (!s) return NULL;
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d) memcpy(d, s, n);
    return d;
}

cm_status cm_file_stamp_take(cm_context *ctx, const char *path, cm_file_stamp *stamp)
{
    struct stat st;
    if (stat(path, &st) != 0) return cm_error(ctx, CM_ERR_IO, "%s: cannot stat: %s", path, strerror(errno));
    stamp->size = (int64_t)st.st_size;
    stamp->sec = (int64_t)st.st_mtim.tv_sec;
    stamp->nsec = (int64_t)st.st_mtim.tv_nsec;
    return CM_OK;
}

/* CM_OK when path still has its stamp, else the error that says why nothing is written. */
static cm_status check_stamp(cm_context *ctx, const char *path, const cm_file_stamp *was)
{
    cm_file_stamp now;
    struct stat st;
    if (stat(path, &st) == 0) {
        now = (cm_file_stamp){(int64_t)st.st_size, (int64_t)st.st_mtim.tv_sec, (int64_t)st.st_mtim.tv_nsec};
        if (now.size == was->size && now.sec == was->sec && now.nsec == was->nsec) return CM_OK;
    }
    return cm_error(ctx, CM_ERR_IO, "%s: the file the mesh was read from has changed or gone since; "
                                    "read it again before writing the mesh back into it", path);
}

cm_status cm_rewrite_add_file(cm_context *ctx, cm_rewrite_source *src, const char *path,
                              const char *name, size_t *index)
{
    cm_rewrite_file *files = realloc(src->files, (src->n_files + 1) * sizeof *files);
    if (!files) return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", path);
    src->files = files;
    cm_rewrite_file *f = &files[src->n_files];
    memset(f, 0, sizeof *f);
    f->path = dup_text(path);
    f->name = dup_text(name);
    if (!f->path || (name && !f->name)) {
        free(f->path);
        free(f->name);
        return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", path);
    }
    cm_status s = cm_file_stamp_take(ctx, path, &f->stamp);
    if (s != CM_OK) {
        free(f->path);
        free(f->name);
        return s;
    }
    if (index) *index = src->n_files;
    ++src->n_files;
    return CM_OK;
}

cm_status cm_rewrite_add_span(cm_context *ctx, cm_rewrite_source *src, size_t file, int64_t offset,
                              int64_t length, int64_t node, int64_t aux)
{
    cm_rewrite_file *f = &src->files[file];
    const cm_rewrite_span *last = f->n_spans ? &f->spans[f->n_spans - 1] : NULL;
    if (offset < 0 || length < 0 || offset + length > f->stamp.size || (last && offset < last->offset + last->length))
        return cm_error(ctx, CM_ERR_INTERNAL, "%s: coordinate span at byte %lld out of order", f->path,
                        (long long)offset);
    if (f->n_spans == f->cap_spans) {
        size_t cap = f->cap_spans ? 2 * f->cap_spans : 1024;
        cm_rewrite_span *spans = realloc(f->spans, cap * sizeof *spans);
        if (!spans) return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory for %zu coordinate places", f->path, cap);
        f->spans = spans;
        f->cap_spans = cap;
    }
    f->spans[f->n_spans++] = (cm_rewrite_span){offset, length, node, aux};
    return CM_OK;
}

void cm_rewrite_put(cm_rewrite_buf *b, const void *s, size_t n)
{
    if (b->fail) return;
    if (b->n + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 256;
        while (b->n + n + 1 > cap) cap *= 2;
        char *d = realloc(b->d, cap);
        if (!d) {
            b->fail = 1;
            return;
        }
        b->d = d;
        b->cap = cap;
    }
    memcpy(b->d + b->n, s, n);
    b->n += n;
    b->d[b->n] = '\0';
}

void cm_rewrite_putf(cm_rewrite_buf *b, const char *fmt, ...)
{
    char small[256];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(small, sizeof small, fmt, ap);
    va_end(ap);
    if (n < 0) {
        b->fail = 1;
        return;
    }
    if ((size_t)n < sizeof small) {
        cm_rewrite_put(b, small, (size_t)n);
        return;
    }
    char *big = malloc((size_t)n + 1);
    if (!big) {
        b->fail = 1;
        return;
    }
    va_start(ap, fmt);
    vsnprintf(big, (size_t)n + 1, fmt, ap);
    va_end(ap);
    cm_rewrite_put(b, big, (size_t)n);
    free(big);
}

int cm_rewrite_number(char *out, size_t cap, double v, const char *original, size_t n)
{
    if (original && n > 0 && n < cap) {
        /* the original must be a number and nothing else (no Fortran exponent, no blank) */
        memcpy(out, original, n);
        out[n] = '\0';
        char *end = NULL;
        const double was = strtod(out, &end);
        if (end == out + n && was == v && (v != 0 || signbit(was) == signbit(v))) return (int)n;
    }
    int len = 0;
    for (int digits = 15; digits <= 17; ++digits) {
        len = snprintf(out, cap, "%.*g", digits, v);
        if (strtod(out, NULL) == v) break;
    }
    return len;
}

/* The output path of file f of a rewrite whose main output is path: path itself, or the
 * included file's name beside it. */
static char *target_of(const cm_rewrite_file *f, const char *path)
{
    if (!f->name) return dup_text(path);
    if (f->name[0] == '/') return dup_text(f->name);
    const char *slash = strrchr(path, '/');
    const size_t dir = slash ? (size_t)(slash - path) + 1 : 0, n = strlen(f->name);
    char *t = malloc(dir + n + 1);
    if (!t) return NULL;
    memcpy(t, path, dir);
    memcpy(t + dir, f->name, n + 1);
    return t;
}

static int same_file(const char *a, const char *b)
{
    struct stat x, y;
    return stat(a, &x) == 0 && stat(b, &y) == 0 && x.st_dev == y.st_dev && x.st_ino == y.st_ino;
}

/* Copies n bytes of in to out (n < 0: to the end), through buf. */
static int copy_bytes(FILE *in, FILE *out, int64_t n, char *buf, size_t cap)
{
    while (n != 0) {
        const size_t want = n < 0 || (uint64_t)n > cap ? cap : (size_t)n;
        const size_t got = fread(buf, 1, want, in);
        if (got && fwrite(buf, 1, got, out) != got) return -1;
        if (n > 0) n -= (int64_t)got;
        if (got < want) return n > 0 || ferror(in) ? -1 : 0;
    }
    return 0;
}

/* The spans are written in batches: the bytes from the end of the last batch to the end of
 * this one's last span are read at once (a bounded region), the spans' new texts are made in
 * parallel (each thread a contiguous run of spans, into its own buffer: formatting numbers is
 * most of a write back's time), then region and texts go out in file order. */
enum { REGION_BYTES = 8 << 20, COPY_CHUNK = 1 << 16 };

typedef struct span_out {
    size_t at, n; /* its new text in its thread's buffer */
} span_out;

/* Makes the texts of spans [i0, i1) of f whose bytes are in region (which starts at byte
 * base of the file). Returns the first span that failed, or i1; nomem is set when a buffer
 * could not grow. */
static size_t emit_batch(const cm_rewrite_source *src, const cm_rewrite_file *f, const cm_mesh *mesh,
                         cm_rewrite_emit_fn emit, const char *region, int64_t base, size_t i0, size_t i1,
                         span_out *outs, cm_rewrite_buf *bufs, int threads, int *nomem)
{
    size_t failed = i1;
#pragma omp parallel num_threads(threads) reduction(min : failed)
    {
        int t = 0, nt = 1;
#ifdef _OPENMP
        t = omp_get_thread_num();
        nt = omp_get_num_threads();
#endif
        const size_t per = (i1 - i0 + (size_t)nt - 1) / (size_t)nt;
        const size_t a = i0 + (size_t)t * per, b = a + per < i1 ? a + per : i1;
        cm_rewrite_buf *out = &bufs[t], text = {0};
        out->n = 0;
        size_t mine = i1; /* this thread's first failure */
        cm_context *quiet = NULL; /* the message is made again on one thread, below */
        cm_context_create(&quiet);
        for (size_t i = a; i < b && mine == i1; ++i) {
            const cm_rewrite_span *sp = &f->spans[i];
            text.n = 0;
            cm_rewrite_put(&text, region + (sp->offset - base), (size_t)sp->length); /* NUL-terminated */
            outs[i - i0].at = out->n;
            if (!quiet || text.fail || emit(quiet, src, f, sp, text.d, mesh->xyz + 3 * sp->node, out) != CM_OK || out->fail)
                mine = i;
            outs[i - i0].n = out->n - outs[i - i0].at;
        }
        failed = mine;
        if (text.fail || out->fail || !quiet)
#pragma omp atomic write
            *nomem = 1;
        cm_context_destroy(&quiet);
        free(text.d);
    }
    return failed;
}

static cm_status rewrite_one(cm_context *ctx, const cm_rewrite_source *src, const cm_rewrite_file *f,
                             const cm_mesh *mesh, FILE *out, cm_rewrite_emit_fn emit)
{
    cm_status s = check_stamp(ctx, f->path, &f->stamp);
    if (s != CM_OK) return s;
    for (size_t i = 0; i < f->n_spans; ++i)
        if (f->spans[i].node < 0 || (size_t)f->spans[i].node >= mesh->n_nodes)
            return cm_error(ctx, CM_ERR_INTERNAL, "%s: coordinate span of node %lld outside the mesh", f->path,
                            (long long)f->spans[i].node);
    FILE *in = NULL;
    s = cm_file_open_read(ctx, f->path, &in); /* the input rule (core.h): no FIFO, no device */
    if (s != CM_OK) return s;
    const int threads = cm_context_threads_for(ctx, f->n_spans, 4096);
    cm_rewrite_buf *bufs = calloc((size_t)threads, sizeof *bufs);
    span_out *outs = NULL;
    char *region = NULL, *chunk = malloc(COPY_CHUNK);
    size_t cap_spans = 0, cap_region = 0;
    if (!bufs || !chunk) s = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", f->path);
    int64_t at = 0; /* the file's bytes before `at` are written */
    for (size_t i0 = 0; s == CM_OK && i0 < f->n_spans;) {
        /* the batch: spans whose bytes end within REGION_BYTES of `at` (at least one) */
        size_t i1 = i0 + 1;
        while (i1 < f->n_spans && f->spans[i1].offset + f->spans[i1].length - at <= REGION_BYTES) ++i1;
        const int64_t end = f->spans[i1 - 1].offset + f->spans[i1 - 1].length;
        if ((size_t)(end - at) > cap_region) {
            free(region);
            cap_region = (size_t)(end - at);
            region = malloc(cap_region);
        }
        if (i1 - i0 > cap_spans) {
            free(outs);
            cap_spans = i1 - i0;
            outs = malloc(cap_spans * sizeof *outs);
        }
        if (!region || !outs) {
            s = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", f->path);
            break;
        }
        if (fread(region, 1, (size_t)(end - at), in) != (size_t)(end - at)) {
            s = cm_error(ctx, CM_ERR_IO, "%s: ends inside the coordinates of node %lld", f->path,
                         (long long)f->spans[i1 - 1].node + 1);
            break;
        }
        int nomem = 0;
        const size_t failed = emit_batch(src, f, mesh, emit, region, at, i0, i1, outs, bufs, threads, &nomem);
        if (failed < i1) {
            /* again on this thread, for the message in ctx */
            const cm_rewrite_span *sp = &f->spans[failed];
            cm_rewrite_buf text = {0}, once = {0};
            cm_rewrite_put(&text, region + (sp->offset - at), (size_t)sp->length);
            s = text.fail ? CM_ERR_NOMEM : emit(ctx, src, f, sp, text.d, mesh->xyz + 3 * sp->node, &once);
            free(text.d);
            free(once.d);
            if (s == CM_OK || s == CM_ERR_NOMEM) s = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", f->path);
            break;
        }
        if (nomem) {
            s = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", f->path);
            break;
        }
        /* out in file order: each thread's spans are a contiguous run, in order in its buffer */
        const size_t per = (i1 - i0 + (size_t)threads - 1) / (size_t)threads;
        int64_t from = at;
        for (size_t i = i0; s == CM_OK && i < i1; ++i) {
            const cm_rewrite_span *sp = &f->spans[i];
            const cm_rewrite_buf *b = &bufs[(i - i0) / per];
            if (fwrite(region + (from - at), 1, (size_t)(sp->offset - from), out) != (size_t)(sp->offset - from) ||
                (outs[i - i0].n && fwrite(b->d + outs[i - i0].at, 1, outs[i - i0].n, out) != outs[i - i0].n))
                s = cm_error(ctx, CM_ERR_IO, "%s: write failed", f->path);
            from = sp->offset + sp->length;
        }
        at = end;
        i0 = i1;
    }
    if (s == CM_OK && copy_bytes(in, out, -1, chunk, COPY_CHUNK) != 0)
        s = cm_error(ctx, CM_ERR_IO, "%s: read or write failed near byte %lld", f->path, (long long)at);
    for (int t = 0; bufs && t < threads; ++t) free(bufs[t].d);
    free(bufs);
    free(outs);
    free(region);
    free(chunk);
    fclose(in);
    return s;
}

cm_status cm_rewrite_write(cm_context *ctx, const cm_rewrite_source *src, const cm_mesh *mesh,
                           const char *path, cm_rewrite_emit_fn emit)
{
    /* The main file always; an included one unless it is its own target already (written
     * beside its source, or named by an absolute path), which is fine without coordinates in
     * it and refused with them. */
    cm_outfile *outs = calloc(src->n_files ? src->n_files : 1, sizeof *outs);
    if (!outs) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: out of memory");
    cm_status s = CM_OK;
    for (size_t i = 0; s == CM_OK && i < src->n_files; ++i) {
        const cm_rewrite_file *f = &src->files[i];
        char *target = target_of(f, path);
        if (!target) {
            s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: out of memory");
            break;
        }
        const int in_place = i > 0 && same_file(target, f->path);
        if (in_place && f->n_spans == 0) {
            free(target);
            continue;
        }
        if (in_place)
            s = cm_error(ctx, CM_ERR_ARGUMENT,
                         "cm_mesh_write: %s: the included file %s holds node coordinates and would be "
                         "overwritten, which changes the original deck too; write into another directory",
                         path, f->path);
        if (s == CM_OK) s = cm_outfile_open(ctx, target, &outs[i]);
        free(target);
        if (s == CM_OK) s = rewrite_one(ctx, src, f, mesh, outs[i].f, emit);
    }
    /* included files first, the main file last: a reader of the output never finds a main file
     * whose included coordinates are still the old ones */
    for (size_t k = src->n_files; s == CM_OK && k-- > 0;)
        if (outs[k].f) s = cm_outfile_commit(ctx, &outs[k]);
    for (size_t i = 0; i < src->n_files; ++i) cm_outfile_abort(&outs[i]);
    free(outs);
    return s;
}

cm_status cm_rewrite_copy_open(cm_context *ctx, const char *source, const cm_file_stamp *stamp,
                               const char *path, cm_outfile *out)
{
    cm_status s = check_stamp(ctx, source, stamp);
    if (s != CM_OK) return s;
    s = cm_outfile_open(ctx, path, out);
    if (s != CM_OK) return s;
    const char *why = NULL;
    FILE *in = cm_file_open_quiet(source, &why); /* the input rule (core.h): no FIFO, no device */
    if (!in) {
        s = cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: the file the mesh was read from, %s: %s",
                     path, source, why);
        cm_outfile_abort(out);
        return s;
    }
    enum { CHUNK = 1 << 16 };
    char *buf = malloc(CHUNK);
    const int bad = !buf || copy_bytes(in, out->f, -1, buf, CHUNK) != 0 || fflush(out->f) != 0;
    free(buf);
    fclose(in);
    if (bad) {
        s = cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: copying %s failed", path, source);
        cm_outfile_abort(out);
    }
    return s;
}
