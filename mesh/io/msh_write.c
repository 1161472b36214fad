/* gmsh .msh writer: version 4.1 (default) or 2.2, ASCII or little-endian binary, through a
 * temporary file renamed on success. Cells go out in file order with their tags; fields go
 * out as $NodeData / $ElementData. */
#include "msh_internal.h"
#include "formats.h"

#include <stdlib.h>
#include <string.h>

typedef struct writer {
    cm_context *ctx;
    const cm_mesh *m;
    const char *path;
    FILE *f;
    int bin, v41;
    unsigned char buf[1 << 16]; /* binary staging, flushed to f */
    size_t len;
} writer;

/* Entity keys (dim, tag) of 4.1 blocks, with what $Entities needs to say about them. */
typedef struct ent {
    int dim, tag;
    double bbox[6];
    int n_phys, cap_phys;
    int *phys;
    const cm_mesh_entity *given; /* from mesh->entities, if it is there */
} ent;

static void flush(writer *w)
{
    if (w->len) fwrite(w->buf, 1, w->len, w->f);
    w->len = 0;
}

static void put(writer *w, const void *p, size_t n)
{
    if (w->len + n > sizeof w->buf) flush(w);
    if (n > sizeof w->buf) {
        fwrite(p, 1, n, w->f);
        return;
    }
    memcpy(w->buf + w->len, p, n);
    w->len += n;
}

static void put_i32(writer *w, int64_t v)
{
    int32_t x = (int32_t)v;
    put(w, &x, 4);
}

static void put_u64(writer *w, int64_t v)
{
    uint64_t x = (uint64_t)v;
    put(w, &x, 8);
}

static int64_t node_tag(const cm_mesh *m, size_t i)
{
    return m->node_tag ? m->node_tag[i] : (int64_t)i + 1;
}

static int64_t cell_tag(const cm_mesh *m, size_t c)
{
    return m->cell_tag ? m->cell_tag[c] : (int64_t)c + 1;
}

static int dim_of(const cm_mesh *m, size_t c)
{
    return cm_cell_type_info((cm_cell_type)m->type[c])->dim;
}

/* Nodes of cell c in gmsh order, as file tags. */
static void gmsh_nodes(const cm_mesh *m, size_t c, int64_t *out, int *n)
{
    cm_cell_type t = (cm_cell_type)m->type[c];
    const int64_t *v = m->conn + m->offset[c];
    *n = (int)(m->offset[c + 1] - m->offset[c]);
    const int *perm = cm_msh_perm(t);
    for (int k = 0; k < *n; ++k) out[perm ? perm[k] : k] = node_tag(m, (size_t)v[k]);
}

static cm_status check_mesh(cm_context *ctx, const cm_mesh *m, const char *path, int v41)
{
    for (size_t c = 0; c < m->n_cells; ++c) {
        const cm_cell_info *info = cm_cell_type_info((cm_cell_type)m->type[c]);
        if (!info || info->gmsh == 0)
            return cm_error(ctx, CM_ERR_UNSUPPORTED,
                            "%s: cell %zu (tag %lld) is a %s, which gmsh has no element type for",
                            path, c, (long long)cell_tag(m, c), info ? info->name : "cell of unknown type");
        if (m->offset[c + 1] - m->offset[c] != info->nodes)
            return cm_error(ctx, CM_ERR_ARGUMENT, "%s: cell %zu (%s) has %lld nodes", path, c,
                            info->name, (long long)(m->offset[c + 1] - m->offset[c]));
        for (int64_t k = m->offset[c]; k < m->offset[c + 1]; ++k)
            if (m->conn[k] < 0 || (size_t)m->conn[k] >= m->n_nodes)
                return cm_error(ctx, CM_ERR_ARGUMENT, "%s: cell %zu: node index %lld out of range", path,
                                c, (long long)m->conn[k]);
    }
    /* 2.2 stores tags as int; 4.1 as size_t but gmsh wants them positive. */
    int64_t max = v41 ? INT64_MAX : INT32_MAX;
    for (size_t i = 0; i < m->n_nodes; ++i)
        if (node_tag(m, i) <= 0 || node_tag(m, i) > max)
            return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: node %zu: tag %lld does not fit msh %s", path, i,
                            (long long)node_tag(m, i), v41 ? "4.1" : "2.2");
    for (size_t c = 0; c < m->n_cells; ++c)
        if (cell_tag(m, c) <= 0 || cell_tag(m, c) > max)
            return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: cell %zu: tag %lld does not fit msh %s", path, c,
                            (long long)cell_tag(m, c), v41 ? "4.1" : "2.2");
    /* $NodeData / $ElementData store tags as int in both versions */
    for (size_t f = 0; f < m->n_fields; ++f) {
        int node = m->fields[f].location == CM_FIELD_NODE;
        size_t n = node ? m->n_nodes : m->n_cells;
        for (size_t i = 0; i < n; ++i)
            if ((node ? node_tag(m, i) : cell_tag(m, i)) > INT32_MAX)
                return cm_error(ctx, CM_ERR_UNSUPPORTED,
                                "%s: field '%s': %s %zu has tag %lld, above the int that msh data sections hold",
                                path, m->fields[f].name, node ? "node" : "cell", i,
                                (long long)(node ? node_tag(m, i) : cell_tag(m, i)));
    }
    return CM_OK;
}

static void write_format(writer *w)
{
    fprintf(w->f, "$MeshFormat\n%s %d 8\n", w->v41 ? "4.1" : "2.2", w->bin);
    if (w->bin) {
        put_i32(w, 1);
        flush(w);
        fputc('\n', w->f);
    }
    fprintf(w->f, "$EndMeshFormat\n");
}

/* ---- names ---- */

/* gmsh quotes names and has no escape: a '"' or a line break in a name would end it early.
 * Such names are written with '"' as '\'' and control characters as ' ', and a warning says
 * so, so that every .msh we write is one our reader (and gmsh) accepts. */
static void put_name(writer *w, const char *what, const char *name)
{
    int changed = 0;
    fputc('"', w->f);
    for (const unsigned char *p = (const unsigned char *)name; *p; ++p) {
        int c = *p == '"' ? '\'' : *p < 0x20 || *p == 0x7f ? ' ' : *p;
        changed |= c != *p;
        fputc(c, w->f);
    }
    fputc('"', w->f);
    if (changed)
        cm_log(w->ctx, CM_LOG_WARNING, "%s: %s name '%s' holds a quote or control character: written with ' and spaces",
               w->path, what, name);
}

static void write_groups(writer *w)
{
    const cm_mesh *m = w->m;
    if (!m->n_groups) return;
    fprintf(w->f, "$PhysicalNames\n%zu\n", m->n_groups);
    for (size_t i = 0; i < m->n_groups; ++i)
    {
        fprintf(w->f, "%d %d ", m->groups[i].dim, m->groups[i].tag);
        put_name(w, "physical group", m->groups[i].name);
        fputc('\n', w->f);
    }
    fprintf(w->f, "$EndPhysicalNames\n");
}

/* ---- 2.2 ---- */

static void write_nodes22(writer *w)
{
    const cm_mesh *m = w->m;
    fprintf(w->f, "$Nodes\n%zu\n", m->n_nodes);
    for (size_t i = 0; i < m->n_nodes; ++i) {
        const double *x = m->xyz + 3 * i;
        if (w->bin) {
            put_i32(w, node_tag(m, i));
            put(w, x, 24);
        } else {
            fprintf(w->f, "%lld %.17g %.17g %.17g\n", (long long)node_tag(m, i), x[0], x[1], x[2]);
        }
    }
    flush(w);
    fprintf(w->f, "%s$EndNodes\n", w->bin ? "\n" : "");
}

static void write_elements22(writer *w)
{
    const cm_mesh *m = w->m;
    int64_t v[32];
    int n;
    fprintf(w->f, "$Elements\n%zu\n", m->n_cells);
    for (size_t c = 0; c < m->n_cells;) {
        int gtype = cm_cell_type_info((cm_cell_type)m->type[c])->gmsh;
        size_t e = c + 1;
        while (e < m->n_cells && m->type[e] == m->type[c]) ++e;
        if (w->bin) {
            put_i32(w, gtype);
            put_i32(w, (int64_t)(e - c));
            put_i32(w, 2);
        }
        for (; c < e; ++c) {
            gmsh_nodes(m, c, v, &n);
            if (w->bin) {
                put_i32(w, cell_tag(m, c));
                put_i32(w, m->physical[c]);
                put_i32(w, m->entity[c]);
                for (int k = 0; k < n; ++k) put_i32(w, v[k]);
            } else {
                fprintf(w->f, "%lld %d 2 %d %d", (long long)cell_tag(m, c), gtype, m->physical[c], m->entity[c]);
                for (int k = 0; k < n; ++k) fprintf(w->f, " %lld", (long long)v[k]);
                fputc('\n', w->f);
            }
        }
    }
    flush(w);
    fprintf(w->f, "%s$EndElements\n", w->bin ? "\n" : "");
}

/* ---- 4.1 ---- */

static int cmp_ent(const void *a, const void *b)
{
    const ent *x = a, *y = b;
    if (x->dim != y->dim) return x->dim < y->dim ? -1 : 1;
    return x->tag < y->tag ? -1 : x->tag > y->tag;
}

static ent *find_ent(ent *e, size_t n, int dim, int tag)
{
    ent k;
    k.dim = dim;
    k.tag = tag;
    return bsearch(&k, e, n, sizeof k, cmp_ent);
}

static void free_ents(ent *e, size_t n)
{
    for (size_t i = 0; e && i < n; ++i) free(e[i].phys);
    free(e);
}

/* The entities the 4.1 blocks refer to: those of mesh->entities, plus one per (dim, entity)
 * of the cells that is missing, with a bounding box of its nodes and its cells' physicals.
 * node_ent[i]: the entity of node i's block: that of the highest-dimensional cell using it
 * (nodes that no cell uses go with the first cell's entity). */
static cm_status collect_entities(writer *w, ent **out, size_t *n_out, int *node_ent)
{
    const cm_mesh *m = w->m;
    size_t cap = m->n_entities + m->n_cells + 1, n = 0;
    ent *e = calloc(cap, sizeof *e);
    if (!e) return cm_error(w->ctx, CM_ERR_NOMEM, "cm_mesh_write_msh: out of memory");
    for (size_t i = 0; i < m->n_entities; ++i) {
        e[n].dim = m->entities[i].dim;
        e[n].tag = m->entities[i].tag;
        e[n++].given = &m->entities[i];
    }
    for (size_t c = 0; c < m->n_cells; ++c)
        if (c == 0 || dim_of(m, c) != dim_of(m, c - 1) || m->entity[c] != m->entity[c - 1])
            e[n++] = (ent){.dim = dim_of(m, c), .tag = m->entity[c]};
    if (m->n_cells == 0) e[n++] = (ent){.dim = 3, .tag = 1};
    qsort(e, n, sizeof *e, cmp_ent);
    size_t u = 0;
    for (size_t i = 0; i < n; ++i) {
        if (u > 0 && cmp_ent(&e[u - 1], &e[i]) == 0) {
            if (!e[u - 1].given) e[u - 1].given = e[i].given;
            continue;
        }
        e[u++] = e[i];
    }
    n = u;
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            e[i].bbox[k] = 1e300;
            e[i].bbox[3 + k] = -1e300;
        }
    /* node -> entity of its highest-dimensional cell */
    int *best = malloc((m->n_nodes ? m->n_nodes : 1) * sizeof(int));
    if (!best) {
        free_ents(e, n);
        return cm_error(w->ctx, CM_ERR_NOMEM, "cm_mesh_write_msh: out of memory");
    }
    for (size_t i = 0; i < m->n_nodes; ++i) best[i] = -1, node_ent[i] = -1;
    int fallback = m->n_cells ? (int)(find_ent(e, n, dim_of(m, 0), m->entity[0]) - e) : 0;
    for (size_t c = 0; c < m->n_cells; ++c) {
        int d = dim_of(m, c);
        ent *x = find_ent(e, n, d, m->entity[c]);
        int xi = (int)(x - e);
        for (int64_t k = m->offset[c]; k < m->offset[c + 1]; ++k) {
            size_t v = (size_t)m->conn[k];
            const double *p = m->xyz + 3 * v;
            for (int j = 0; j < 3; ++j) {
                if (p[j] < x->bbox[j]) x->bbox[j] = p[j];
                if (p[j] > x->bbox[3 + j]) x->bbox[3 + j] = p[j];
            }
            if (d > best[v]) best[v] = d, node_ent[v] = xi;
        }
        int ph = m->physical[c];
        if (ph == 0 || x->given) continue;
        int have = 0;
        for (int j = 0; j < x->n_phys && !have; ++j) have = x->phys[j] == ph;
        if (have) continue;
        if (x->n_phys == x->cap_phys) {
            int nc = x->cap_phys ? 2 * x->cap_phys : 2;
            int *np = realloc(x->phys, (size_t)nc * sizeof(int));
            if (!np) {
                free(best);
                free_ents(e, n);
                return cm_error(w->ctx, CM_ERR_NOMEM, "cm_mesh_write_msh: out of memory");
            }
            x->phys = np;
            x->cap_phys = nc;
        }
        x->phys[x->n_phys++] = ph;
    }
    for (size_t i = 0; i < m->n_nodes; ++i) {
        if (node_ent[i] < 0) {
            node_ent[i] = fallback;
            ent *x = &e[fallback];
            for (int j = 0; j < 3; ++j) {
                if (m->xyz[3 * i + j] < x->bbox[j]) x->bbox[j] = m->xyz[3 * i + j];
                if (m->xyz[3 * i + j] > x->bbox[3 + j]) x->bbox[3 + j] = m->xyz[3 * i + j];
            }
        }
    }
    free(best);
    for (size_t i = 0; i < n; ++i)
        if (e[i].bbox[0] > e[i].bbox[3]) memset(e[i].bbox, 0, sizeof e[i].bbox);
    *out = e;
    *n_out = n;
    return CM_OK;
}

/* ASCII or binary: a size_t, an int, a double. */
static void w_size(writer *w, int64_t v, char sep)
{
    if (w->bin) put_u64(w, v);
    else fprintf(w->f, "%lld%c", (long long)v, sep);
}

static void w_int(writer *w, int64_t v, char sep)
{
    if (w->bin) put_i32(w, v);
    else fprintf(w->f, "%lld%c", (long long)v, sep);
}

static void w_double(writer *w, double v, char sep)
{
    if (w->bin) put(w, &v, 8);
    else fprintf(w->f, "%.17g%c", v, sep);
}

static void write_entities41(writer *w, const ent *e, size_t n)
{
    size_t count[4] = {0, 0, 0, 0};
    for (size_t i = 0; i < n; ++i) ++count[e[i].dim];
    fprintf(w->f, "$Entities\n");
    for (int d = 0; d < 4; ++d) w_size(w, (int64_t)count[d], d == 3 ? '\n' : ' ');
    for (size_t i = 0; i < n; ++i) {
        const cm_mesh_entity *g = e[i].given;
        const double *bb = g ? g->bbox : e[i].bbox;
        int np = g ? g->n_physical : e[i].n_phys;
        const int *ph = g ? g->physical : e[i].phys;
        w_int(w, e[i].tag, ' ');
        for (int k = 0; k < (e[i].dim == 0 ? 3 : 6); ++k) w_double(w, bb[k], ' ');
        w_size(w, np, e[i].dim == 0 && np == 0 ? '\n' : ' ');
        for (int k = 0; k < np; ++k) w_int(w, ph[k], e[i].dim == 0 && k == np - 1 ? '\n' : ' ');
        if (e[i].dim > 0) {
            int nb = g ? g->n_bounding : 0;
            w_size(w, nb, nb == 0 ? '\n' : ' ');
            for (int k = 0; k < nb; ++k) w_int(w, g->bounding[k], k == nb - 1 ? '\n' : ' ');
        }
    }
    flush(w);
    fprintf(w->f, "%s$EndEntities\n", w->bin ? "\n" : "");
}

/* "$Nodes" / "$Elements" and the 4.1 block header: blocks, count, smallest and largest tag. */
static void write_header41(writer *w, const char *section, size_t blocks, size_t count,
                           int64_t lo, int64_t hi)
{
    fprintf(w->f, "%s\n", section);
    w_size(w, (int64_t)blocks, ' ');
    w_size(w, (int64_t)count, ' ');
    w_size(w, count ? lo : 0, ' ');
    w_size(w, hi, '\n');
}

static void write_nodes41(writer *w, const ent *e, const int *node_ent)
{
    const cm_mesh *m = w->m;
    size_t nb = 0;
    int64_t lo = INT64_MAX, hi = 0;
    for (size_t i = 0; i < m->n_nodes; ++i) {
        if (i == 0 || node_ent[i] != node_ent[i - 1]) ++nb;
        if (node_tag(m, i) < lo) lo = node_tag(m, i);
        if (node_tag(m, i) > hi) hi = node_tag(m, i);
    }
    write_header41(w, "$Nodes", nb, m->n_nodes, lo, hi);
    for (size_t i = 0; i < m->n_nodes;) {
        size_t j = i + 1;
        while (j < m->n_nodes && node_ent[j] == node_ent[i]) ++j;
        const ent *x = &e[node_ent[i]];
        w_int(w, x->dim, ' ');
        w_int(w, x->tag, ' ');
        w_int(w, 0, ' ');
        w_size(w, (int64_t)(j - i), '\n');
        for (size_t k = i; k < j; ++k) w_size(w, node_tag(m, k), '\n');
        if (w->bin) {
            put(w, m->xyz + 3 * i, 24 * (j - i));
        } else {
            for (size_t k = i; k < j; ++k) {
                const double *p = m->xyz + 3 * k;
                fprintf(w->f, "%.17g %.17g %.17g\n", p[0], p[1], p[2]);
            }
        }
        i = j;
    }
    flush(w);
    fprintf(w->f, "%s$EndNodes\n", w->bin ? "\n" : "");
}

static void write_elements41(writer *w)
{
    const cm_mesh *m = w->m;
    size_t nb = 0;
    int64_t lo = INT64_MAX, hi = 0, v[32];
    int n;
    for (size_t c = 0; c < m->n_cells; ++c) {
        if (c == 0 || m->type[c] != m->type[c - 1] || m->entity[c] != m->entity[c - 1]) ++nb;
        if (cell_tag(m, c) < lo) lo = cell_tag(m, c);
        if (cell_tag(m, c) > hi) hi = cell_tag(m, c);
    }
    write_header41(w, "$Elements", nb, m->n_cells, lo, hi);
    for (size_t c = 0; c < m->n_cells;) {
        size_t e = c + 1;
        while (e < m->n_cells && m->type[e] == m->type[c] && m->entity[e] == m->entity[c]) ++e;
        w_int(w, dim_of(m, c), ' ');
        w_int(w, m->entity[c], ' ');
        w_int(w, cm_cell_type_info((cm_cell_type)m->type[c])->gmsh, ' ');
        w_size(w, (int64_t)(e - c), '\n');
        for (; c < e; ++c) {
            gmsh_nodes(m, c, v, &n);
            w_size(w, cell_tag(m, c), ' ');
            for (int k = 0; k < n; ++k) w_size(w, v[k], k == n - 1 ? '\n' : ' ');
        }
    }
    flush(w);
    fprintf(w->f, "%s$EndElements\n", w->bin ? "\n" : "");
}

/* ---- fields ---- */

static void write_field(writer *w, const cm_field *f)
{
    const cm_mesh *m = w->m;
    int node = f->location == CM_FIELD_NODE;
    size_t n = node ? m->n_nodes : m->n_cells;
    const char *sec = node ? "NodeData" : "ElementData";
    fprintf(w->f, "$%s\n1\n", sec);
    put_name(w, "field", f->name);
    fprintf(w->f, "\n1\n0\n3\n0\n%d\n%zu\n", f->components, n);
    for (size_t i = 0; i < n; ++i) {
        int64_t tag = node ? node_tag(m, i) : cell_tag(m, i);
        const double *d = f->data + i * (size_t)f->components;
        if (w->bin) {
            put_i32(w, tag); /* an int in both versions (gmsh 4.8 writes and reads it so) */
            put(w, d, 8 * (size_t)f->components);
        } else {
            fprintf(w->f, "%lld", (long long)tag);
            for (int k = 0; k < f->components; ++k) fprintf(w->f, " %.17g", d[k]);
            fputc('\n', w->f);
        }
    }
    flush(w);
    fprintf(w->f, "%s$End%s\n", w->bin ? "\n" : "", sec);
}

cm_status cm_mesh_write_msh(cm_context *ctx, const cm_mesh *mesh, const char *path,
                            const cm_mesh_write_options *opt)
{
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write_msh: NULL argument");
    cm_mesh_write_options defaults;
    cm_mesh_write_options_init(&defaults);
    if (!opt) opt = &defaults;
    if (opt->msh_version != 41 && opt->msh_version != 22)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write_msh: msh_version %d (expected 22 or 41)",
                        opt->msh_version);
    if (opt->binary && !cm_host_little_endian())
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: binary .msh is written on little-endian hosts only", path);
    int v41 = opt->msh_version == 41;
    cm_status s = check_mesh(ctx, mesh, path, v41);
    if (s != CM_OK) return s;
    writer *w = calloc(1, sizeof *w);
    ent *e = NULL;
    size_t n_ent = 0;
    int *node_ent = malloc((mesh->n_nodes ? mesh->n_nodes : 1) * sizeof(int));
    if (!w || !node_ent) {
        free(w);
        free(node_ent);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write_msh: out of memory");
    }
    w->ctx = ctx;
    w->m = mesh;
    w->path = path;
    w->bin = opt->binary != 0;
    w->v41 = v41;
    if (v41) s = collect_entities(w, &e, &n_ent, node_ent);
    cm_outfile out;
    memset(&out, 0, sizeof out);
    if (s == CM_OK) s = cm_outfile_open(ctx, path, &out);
    if (s == CM_OK) {
        w->f = out.f;
        write_format(w);
        write_groups(w);
        if (v41) {
            write_entities41(w, e, n_ent);
            write_nodes41(w, e, node_ent);
            write_elements41(w);
        } else {
            write_nodes22(w);
            write_elements22(w);
        }
        for (size_t i = 0; i < mesh->n_fields; ++i) write_field(w, &mesh->fields[i]);
        s = cm_outfile_commit(ctx, &out);
    }
    free_ents(e, n_ent);
    free(node_ent);
    free(w);
    return s;
}
