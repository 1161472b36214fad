/* gmsh .msh reader, section bodies: $Entities (4.1), $Nodes and $Elements (2.2 and 4.1),
 * $NodeData / $ElementData. Binary blocks are checked against the bytes left once and then
 * decoded straight from memory. */
#include "msh_read_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* gmsh numbers its element types 1..140 (MSH_MAX_NUM); we know a subset. */
#define MSH_MAX_TYPE 140

static int cmp_key(const void *a, const void *b)
{
    const cm_msh_entity_key *x = a, *y = b;
    if (x->dim != y->dim) return x->dim < y->dim ? -1 : 1;
    return x->tag < y->tag ? -1 : x->tag > y->tag;
}

static int entity_physical(const cm_msh_reader *r, int dim, int tag)
{
    cm_msh_entity_key k = {dim, tag, 0};
    const cm_msh_entity_key *e = r->n_ents ? bsearch(&k, r->ents, r->n_ents, sizeof k, cmp_key) : NULL;
    return e ? e->physical : 0;
}

static cm_status check_int(cm_msh_reader *r, int bin, size_t at, const char *what, int64_t v)
{
    if (v >= INT32_MIN && v <= INT32_MAX) return CM_OK;
    return cm_msh_err(r, CM_ERR_FORMAT, bin, at, "expected an int %s, got %lld", what, (long long)v);
}

/* A list of n ints (physical tags, bounding entities); n already checked against the file. */
static cm_status read_ints(cm_msh_reader *r, int bin, const char *what, int64_t n, int **out)
{
    *out = NULL;
    if (n == 0) return CM_OK;
    *out = malloc((size_t)n * sizeof(int));
    if (!*out) return cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->t.path);
    for (int64_t i = 0; i < n; ++i) {
        int64_t v;
        size_t at = r->t.pos;
        cm_status s = cm_msh_int(r, bin, what, &v);
        if (s == CM_OK) s = check_int(r, bin, at, what, v);
        if (s != CM_OK) {
            free(*out);
            *out = NULL;
            return s;
        }
        (*out)[i] = (int)v;
    }
    return CM_OK;
}

cm_status cm_msh_read_entities41(cm_msh_reader *r)
{
    int bin = r->binary;
    int64_t count[4];
    cm_status s = CM_OK;
    for (int d = 0; d < 4 && s == CM_OK; ++d) s = cm_msh_count(r, bin, "number of entities", 4, &count[d]);
    if (s != CM_OK) return s;
    size_t total = (size_t)(count[0] + count[1] + count[2] + count[3]);
    free(r->ents);
    r->ents = malloc((total ? total : 1) * sizeof *r->ents);
    r->n_ents = 0;
    if (!r->ents) return cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->t.path);
    for (int d = 0; d < 4; ++d) {
        for (int64_t i = 0; i < count[d]; ++i) {
            cm_mesh_entity e;
            memset(&e, 0, sizeof e);
            e.dim = d;
            int64_t tag, np = 0, nb = 0; /* counts 0 when a read before them failed */
            size_t at = r->t.pos;
            s = cm_msh_int(r, bin, "entity tag", &tag);
            if (s == CM_OK) s = check_int(r, bin, at, "entity tag", tag);
            for (int k = 0; k < (d == 0 ? 3 : 6) && s == CM_OK; ++k)
                s = cm_msh_double(r, bin, "entity bounding box", &e.bbox[k]);
            if (d == 0) memcpy(e.bbox + 3, e.bbox, 3 * sizeof(double));
            if (s == CM_OK) s = cm_msh_count(r, bin, "number of physical tags", bin ? 4 : 2, &np);
            if (s == CM_OK) s = read_ints(r, bin, "physical tag", np, &e.physical);
            if (s == CM_OK && d > 0) s = cm_msh_count(r, bin, "number of bounding entities", bin ? 4 : 2, &nb);
            if (s == CM_OK && d > 0) s = read_ints(r, bin, "bounding entity tag", nb, &e.bounding);
            e.tag = (int)tag;
            e.n_physical = (int)np;
            e.n_bounding = (int)nb;
            if (s == CM_OK && (np > INT32_MAX || nb > INT32_MAX))
                s = cm_msh_err(r, CM_ERR_FORMAT, bin, r->t.pos, "expected fewer tags, got %lld", (long long)(np + nb));
            if (s == CM_OK) s = cm_mesh_add_entity(r->ctx, r->m, &e);
            if (s == CM_OK) r->ents[r->n_ents++] = (cm_msh_entity_key){d, e.tag, np > 0 ? e.physical[0] : 0};
            free(e.physical);
            free(e.bounding);
            if (s != CM_OK) return s;
        }
    }
    if (r->n_ents > 1) qsort(r->ents, r->n_ents, sizeof *r->ents, cmp_key); /* NULL when none */
    return cm_msh_expect(r, bin, "$EndEntities");
}

cm_status cm_msh_map_nodes(cm_msh_reader *r)
{
    size_t dup = 0;
    cm_status s = cm_msh_tagmap_build(r->ctx, r->m->node_tag, r->m->n_nodes, &r->nodes, &dup);
    if (s == CM_ERR_FORMAT)
        return cm_msh_err(r, s, 0, 0, "expected unique node tags, got tag %lld twice (in $Nodes)",
                          (long long)r->m->node_tag[dup]);
    return s;
}

static cm_status check_tag(cm_msh_reader *r, int bin, size_t at, const char *what, int64_t tag)
{
    if (tag > 0) return CM_OK;
    return cm_msh_err(r, CM_ERR_FORMAT, bin, at, "expected a positive %s, got %lld", what, (long long)tag);
}

/* ---- 4.1 ---- */

cm_status cm_msh_read_nodes41(cm_msh_reader *r)
{
    int bin = r->binary;
    size_t per = bin ? (size_t)r->dsize + 24 : 8;
    int64_t nb, nn, lo, hi;
    cm_status s = cm_msh_count(r, bin, "number of node blocks", bin ? 12 + (size_t)r->dsize : 8, &nb);
    if (s == CM_OK) s = cm_msh_count(r, bin, "number of nodes", per, &nn);
    if (s == CM_OK) s = cm_msh_size(r, bin, "minimum node tag", &lo);
    if (s == CM_OK) s = cm_msh_size(r, bin, "maximum node tag", &hi);
    if (s == CM_OK) s = cm_mesh_resize_nodes(r->ctx, r->m, (size_t)nn, 1);
    if (s != CM_OK) return s;
    int64_t done = 0;
    for (int64_t b = 0; b < nb; ++b) {
        int64_t dim, etag, param, n;
        size_t at = r->t.pos;
        s = cm_msh_int(r, bin, "node block entity dimension", &dim);
        if (s == CM_OK) s = cm_msh_int(r, bin, "node block entity tag", &etag);
        if (s == CM_OK) s = cm_msh_int(r, bin, "node block parametric flag", &param);
        if (s == CM_OK) s = cm_msh_count(r, bin, "number of nodes in the block", per, &n);
        if (s != CM_OK) return s;
        if (dim < 0 || dim > 3 || (param != 0 && param != 1))
            return cm_msh_err(r, CM_ERR_FORMAT, bin, at,
                              "expected entity dimension 0..3 and parametric flag 0/1, got %lld and %lld",
                              (long long)dim, (long long)param);
        if (n > nn - done)
            return cm_msh_err(r, CM_ERR_FORMAT, bin, at,
                              "expected at most %lld nodes in the block (numNodes %lld), got %lld",
                              (long long)(nn - done), (long long)nn, (long long)n);
        int64_t *tag = r->m->node_tag + done;
        double *xyz = r->m->xyz + 3 * done;
        int extra = param ? (int)dim : 0;
        if (bin) {
            size_t stride = (size_t)(3 + extra) * 8;
            at = r->t.pos;
            const unsigned char *p = cm_msh_bytes(r, (size_t)n * (size_t)r->dsize, "node tags");
            if (!p) return CM_ERR_FORMAT;
            for (int64_t i = 0; i < n; ++i) {
                tag[i] = cm_msh_get_size(p + (size_t)i * (size_t)r->dsize, r->dsize);
                s = check_tag(r, 1, at + (size_t)i * (size_t)r->dsize, "node tag", tag[i]);
                if (s != CM_OK) return s;
            }
            at = r->t.pos;
            p = cm_msh_bytes(r, (size_t)n * stride, "node coordinates");
            if (!p) return CM_ERR_FORMAT;
            for (int64_t i = 0; i < n; ++i) {
                memcpy(xyz + 3 * i, p + (size_t)i * stride, 24);
                for (int k = 0; k < 3; ++k)
                    if (!isfinite(xyz[3 * i + k]))
                        return cm_msh_err(r, CM_ERR_FORMAT, 1, at + (size_t)i * stride + 8 * (size_t)k,
                                          "expected a finite coordinate of node %lld, got %g",
                                          (long long)tag[i], xyz[3 * i + k]);
            }
        } else {
            for (int64_t i = 0; i < n; ++i) {
                s = cm_msh_size(r, 0, "node tag", &tag[i]);
                if (s == CM_OK) s = check_tag(r, 0, 0, "node tag", tag[i]);
                if (s != CM_OK) return s;
            }
            for (int64_t i = 0; i < n; ++i) {
                for (int k = 0; k < 3 && s == CM_OK; ++k) s = cm_msh_coord(r, 0, "node coordinate", &xyz[3 * i + k]);
                double u;
                for (int k = 0; k < extra && s == CM_OK; ++k) s = cm_msh_double(r, 0, "parametric coordinate", &u);
                if (s != CM_OK) return s;
            }
        }
        done += n;
    }
    if (done != nn)
        return cm_msh_err(r, CM_ERR_FORMAT, bin, r->t.pos, "expected %lld nodes (numNodes), got %lld in the blocks",
                          (long long)nn, (long long)done);
    s = cm_msh_expect(r, bin, "$EndNodes");
    return s == CM_OK ? cm_msh_map_nodes(r) : s;
}

/* Maps the file's node tags of one element (gmsh order) to indices in VTK order and adds it. */
static cm_status add_element(cm_msh_reader *r, cm_cell_type ct, const int64_t *ftag, int n,
                             int physical, int entity, int64_t tag, int bin, size_t at)
{
    int64_t idx[32];
    const int *perm = cm_msh_perm(ct);
    for (int k = 0; k < n; ++k) {
        int64_t v = ftag[perm ? perm[k] : k];
        int64_t i = cm_msh_tagmap_find(&r->nodes, v);
        if (i < 0)
            return cm_msh_err(r, CM_ERR_FORMAT, bin, at,
                              "expected a node tag defined in $Nodes, got %lld (element %lld)",
                              (long long)v, (long long)tag);
        idx[k] = i;
    }
    return cm_mesh_add_cell(r->ctx, r->m, ct, idx, (size_t)n, physical, entity, tag);
}

static cm_status element_type(cm_msh_reader *r, int bin, size_t at, int64_t gtype, cm_cell_type *ct)
{
    *ct = gtype > 0 && gtype <= INT32_MAX ? cm_cell_type_from_gmsh((int)gtype) : CM_CELL_TYPE_COUNT;
    if (*ct != CM_CELL_TYPE_COUNT) return CM_OK;
    if (gtype > 0 && gtype <= MSH_MAX_TYPE)
        return cm_msh_err(r, CM_ERR_UNSUPPORTED, bin, at,
                          "gmsh element type %lld is not supported (linear and quadratic points, "
                          "lines, triangles, quads, tets, hexes, prisms, pyramids are)",
                          (long long)gtype);
    return cm_msh_err(r, CM_ERR_FORMAT, bin, at, "expected a gmsh element type number, got %lld",
                      (long long)gtype);
}

cm_status cm_msh_read_elements41(cm_msh_reader *r)
{
    int bin = r->binary;
    size_t ds = (size_t)r->dsize;
    int64_t nb, ne, lo, hi;
    cm_status s = cm_msh_count(r, bin, "number of element blocks", bin ? 12 + ds : 8, &nb);
    if (s == CM_OK) s = cm_msh_count(r, bin, "number of elements", bin ? 2 * ds : 4, &ne);
    if (s == CM_OK) s = cm_msh_size(r, bin, "minimum element tag", &lo);
    if (s == CM_OK) s = cm_msh_size(r, bin, "maximum element tag", &hi);
    if (s == CM_OK) s = cm_mesh_reserve_cells(r->ctx, r->m, (size_t)ne, 0);
    if (s != CM_OK) return s;
    int64_t done = 0, ftag[32];
    for (int64_t b = 0; b < nb; ++b) {
        int64_t dim, etag, gtype, n;
        size_t at = r->t.pos;
        s = cm_msh_int(r, bin, "element block entity dimension", &dim);
        if (s == CM_OK) s = cm_msh_int(r, bin, "element block entity tag", &etag);
        if (s == CM_OK) s = check_int(r, bin, at + 4, "entity tag", etag);
        size_t at_type = r->t.pos;
        if (s == CM_OK) s = cm_msh_int(r, bin, "element type", &gtype);
        cm_cell_type ct = CM_CELL_TYPE_COUNT;
        if (s == CM_OK) s = element_type(r, bin, at_type, gtype, &ct);
        if (s != CM_OK) return s;
        int nn = cm_cell_type_info(ct)->nodes;
        s = cm_msh_count(r, bin, "number of elements in the block", bin ? (size_t)(1 + nn) * ds : (size_t)(1 + nn) * 2, &n);
        if (s != CM_OK) return s;
        if (n > ne - done)
            return cm_msh_err(r, CM_ERR_FORMAT, bin, at,
                              "expected at most %lld elements in the block (numElements %lld), got %lld",
                              (long long)(ne - done), (long long)ne, (long long)n);
        int phys = entity_physical(r, (int)dim, (int)etag);
        s = cm_mesh_reserve_cells(r->ctx, r->m, (size_t)n, (size_t)n * (size_t)nn);
        if (s != CM_OK) return s;
        if (bin) {
            size_t rec = (size_t)(1 + nn) * ds;
            at = r->t.pos;
            const unsigned char *p = cm_msh_bytes(r, (size_t)n * rec, "element records");
            if (!p) return CM_ERR_FORMAT;
            for (int64_t i = 0; i < n; ++i, p += rec, at += rec) {
                for (int k = 0; k <= nn; ++k) ftag[k] = cm_msh_get_size(p + (size_t)k * ds, r->dsize);
                s = check_tag(r, 1, at, "element tag", ftag[0]);
                if (s == CM_OK) s = add_element(r, ct, ftag + 1, nn, phys, (int)etag, ftag[0], 1, at);
                if (s != CM_OK) return s;
            }
        } else {
            for (int64_t i = 0; i < n; ++i) {
                for (int k = 0; k <= nn && s == CM_OK; ++k)
                    s = cm_msh_size(r, 0, k ? "element node tag" : "element tag", &ftag[k]);
                if (s == CM_OK) s = check_tag(r, 0, 0, "element tag", ftag[0]);
                if (s == CM_OK) s = add_element(r, ct, ftag + 1, nn, phys, (int)etag, ftag[0], 0, 0);
                if (s != CM_OK) return s;
            }
        }
        done += n;
    }
    if (done != ne)
        return cm_msh_err(r, CM_ERR_FORMAT, bin, r->t.pos,
                          "expected %lld elements (numElements), got %lld in the blocks", (long long)ne,
                          (long long)done);
    return cm_msh_expect(r, bin, "$EndElements");
}

/* ---- 2.2 ---- */

cm_status cm_msh_read_nodes22(cm_msh_reader *r)
{
    int bin = r->binary;
    int64_t nn;
    cm_status s = cm_msh_count(r, 0, "number of nodes", bin ? 28 : 8, &nn);
    if (s == CM_OK) s = cm_mesh_resize_nodes(r->ctx, r->m, (size_t)nn, 1);
    if (s != CM_OK) return s;
    if (bin) {
        cm_msh_to_binary(r);
        size_t at = r->t.pos;
        const unsigned char *p = cm_msh_bytes(r, (size_t)nn * 28, "node records");
        if (!p) return CM_ERR_FORMAT;
        for (int64_t i = 0; i < nn; ++i, p += 28, at += 28) {
            int32_t t;
            memcpy(&t, p, 4);
            memcpy(r->m->xyz + 3 * i, p + 4, 24);
            r->m->node_tag[i] = t;
            s = check_tag(r, 1, at, "node tag", t);
            if (s != CM_OK) return s;
            for (int k = 0; k < 3; ++k)
                if (!isfinite(r->m->xyz[3 * i + k]))
                    return cm_msh_err(r, CM_ERR_FORMAT, 1, at + 4 + 8 * (size_t)k,
                                      "expected a finite coordinate of node %d, got %g", t,
                                      r->m->xyz[3 * i + k]);
        }
    } else {
        for (int64_t i = 0; i < nn && s == CM_OK; ++i) {
            s = cm_msh_size(r, 0, "node tag", &r->m->node_tag[i]);
            if (s == CM_OK) s = check_tag(r, 0, 0, "node tag", r->m->node_tag[i]);
            for (int k = 0; k < 3 && s == CM_OK; ++k) s = cm_msh_coord(r, 0, "node coordinate", &r->m->xyz[3 * i + k]);
        }
        if (s != CM_OK) return s;
    }
    s = cm_msh_expect(r, bin, "$EndNodes");
    return s == CM_OK ? cm_msh_map_nodes(r) : s;
}

cm_status cm_msh_read_elements22(cm_msh_reader *r)
{
    int bin = r->binary;
    int64_t ne;
    cm_status s = cm_msh_count(r, 0, "number of elements", bin ? 12 : 8, &ne);
    if (s == CM_OK) s = cm_mesh_reserve_cells(r->ctx, r->m, (size_t)ne, 0);
    if (s != CM_OK) return s;
    int64_t ftag[32];
    if (!bin) {
        for (int64_t i = 0; i < ne; ++i) {
            int64_t tag, gtype, ntags = 0, phys = 0, ent = 0, v;
            s = cm_msh_size(r, 0, "element tag", &tag);
            if (s == CM_OK) s = check_tag(r, 0, 0, "element tag", tag);
            if (s == CM_OK) s = cm_msh_int(r, 0, "element type", &gtype);
            cm_cell_type ct = CM_CELL_TYPE_COUNT;
            if (s == CM_OK) s = element_type(r, 0, 0, gtype, &ct);
            if (s == CM_OK) s = cm_msh_count(r, 0, "number of element tags", 2, &ntags);
            for (int64_t k = 0; k < ntags && s == CM_OK; ++k) {
                s = cm_msh_int(r, 0, "element tag (physical, elementary, ...)", &v);
                if (s == CM_OK && k < 2) s = check_int(r, 0, 0, "element tag", v);
                if (k == 0) phys = v;
                if (k == 1) ent = v;
            }
            if (s != CM_OK) return s;
            int nn = cm_cell_type_info(ct)->nodes;
            for (int k = 0; k < nn && s == CM_OK; ++k) s = cm_msh_size(r, 0, "element node tag", &ftag[k]);
            if (s == CM_OK) s = add_element(r, ct, ftag, nn, (int)phys, (int)ent, tag, 0, 0);
            if (s != CM_OK) return s;
        }
        return cm_msh_expect(r, 0, "$EndElements");
    }
    cm_msh_to_binary(r);
    int64_t done = 0;
    while (done < ne) {
        int64_t gtype, n, ntags;
        size_t at = r->t.pos;
        s = cm_msh_int(r, 1, "element type", &gtype);
        cm_cell_type ct = CM_CELL_TYPE_COUNT;
        if (s == CM_OK) s = element_type(r, 1, at, gtype, &ct);
        if (s == CM_OK) s = cm_msh_int(r, 1, "number of elements that follow", &n);
        if (s == CM_OK) s = cm_msh_int(r, 1, "number of element tags", &ntags);
        if (s != CM_OK) return s;
        int nn = cm_cell_type_info(ct)->nodes;
        if (n < 0 || n > ne - done || ntags < 0 || ntags > 1000000)
            return cm_msh_err(r, CM_ERR_FORMAT, 1, at,
                              "expected at most %lld elements with a sane tag count, got %lld elements with %lld tags",
                              (long long)(ne - done), (long long)n, (long long)ntags);
        size_t rec = (size_t)(1 + ntags + nn) * 4;
        at = r->t.pos;
        if ((uint64_t)n > (r->t.size - r->t.pos) / rec)
            return cm_msh_err(r, CM_ERR_FORMAT, 1, at,
                              "expected %lld element records of %zu bytes, got %zu bytes left",
                              (long long)n, rec, r->t.size - r->t.pos);
        const unsigned char *p = cm_msh_bytes(r, (size_t)n * rec, "element records");
        for (int64_t i = 0; i < n; ++i, p += rec, at += rec) {
            int32_t v[3] = {0, 0, 0};
            memcpy(v, p, 4 * (size_t)(ntags >= 2 ? 3 : 1 + ntags));
            for (int k = 0; k < nn; ++k) {
                int32_t t;
                memcpy(&t, p + 4 * (size_t)(1 + ntags + k), 4);
                ftag[k] = t;
            }
            s = check_tag(r, 1, at, "element tag", v[0]);
            if (s == CM_OK) s = add_element(r, ct, ftag, nn, v[1], v[2], v[0], 1, at);
            if (s != CM_OK) return s;
        }
        done += n;
    }
    return cm_msh_expect(r, 1, "$EndElements");
}

/* ---- $NodeData / $ElementData ---- */

cm_status cm_msh_map_cells(cm_msh_reader *r)
{
    if (r->cells_mapped) return CM_OK;
    cm_mesh *m = r->m;
    int64_t *tags = m->cell_tag;
    int64_t *own = NULL;
    if (!tags) {
        own = malloc((m->n_cells ? m->n_cells : 1) * sizeof(int64_t));
        if (!own) return cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->t.path);
        for (size_t c = 0; c < m->n_cells; ++c) own[c] = (int64_t)c + 1;
        tags = own;
    }
    size_t dup = 0;
    cm_status s = cm_msh_tagmap_build(r->ctx, tags, m->n_cells, &r->cells, &dup);
    if (s == CM_ERR_FORMAT)
        s = cm_msh_err(r, s, 0, 0, "expected unique element tags, got tag %lld twice (in $Elements)",
                       (long long)tags[dup]);
    free(own);
    if (s == CM_OK) r->cells_mapped = 1;
    return s;
}

cm_status cm_msh_read_data(cm_msh_reader *r, cm_field_location where)
{
    const char *sec = where == CM_FIELD_NODE ? "$NodeData" : "$ElementData";
    if (!r->have_nodes || (where == CM_FIELD_CELL && !r->have_elements))
        return cm_msh_err(r, CM_ERR_FORMAT, 0, 0, "expected %s after $Nodes and $Elements", sec);
    cm_status s = where == CM_FIELD_CELL ? cm_msh_map_cells(r) : CM_OK;
    int64_t nstr = 0, nreal = 0, nint = 0, v; /* the loops test them even after a failure */
    char *name = NULL;
    double x;
    if (s == CM_OK) s = cm_msh_count(r, 0, "number of string tags", 2, &nstr);
    for (int64_t i = 0; i < nstr && s == CM_OK; ++i) {
        char *str = NULL;
        s = cm_msh_string(r, "string tag in quotes", &str);
        if (i == 0) name = str;
        else free(str);
    }
    if (s == CM_OK) s = cm_msh_count(r, 0, "number of real tags", 2, &nreal);
    for (int64_t i = 0; i < nreal && s == CM_OK; ++i) s = cm_msh_double(r, 0, "real tag", &x);
    int64_t itag[3] = {0, 0, 0};
    if (s == CM_OK) s = cm_msh_count(r, 0, "number of integer tags", 2, &nint);
    if (s == CM_OK && nint < 3)
        s = cm_msh_err(r, CM_ERR_FORMAT, 0, 0, "expected at least 3 integer tags (step, components, count), got %lld",
                       (long long)nint);
    for (int64_t i = 0; i < nint && s == CM_OK; ++i) {
        s = cm_msh_int(r, 0, "integer tag", &v);
        if (i < 3) itag[i] = v;
    }
    int comps = (int)itag[1];
    int64_t n = itag[2];
    size_t rec = r->binary ? 4 + 8 * (size_t)(comps > 0 ? comps : 1) : 2 * (size_t)(1 + (comps > 0 ? comps : 1));
    if (s == CM_OK && (itag[1] < 1 || itag[1] > 1024 || n < 0 || (uint64_t)n > (r->t.size - r->t.pos) / rec))
        s = cm_msh_err(r, CM_ERR_FORMAT, 0, 0,
                       "expected 1..1024 components and a count that fits the file, got %lld and %lld",
                       (long long)itag[1], (long long)n);
    double *data = NULL;
    if (s == CM_OK) s = cm_mesh_add_field(r->ctx, r->m, name ? name : "data", where, comps, &data);
    free(name);
    if (s != CM_OK) return s;
    const cm_msh_tagmap *map = where == CM_FIELD_NODE ? &r->nodes : &r->cells;
    if (r->binary) cm_msh_to_binary(r);
    for (int64_t i = 0; i < n; ++i) {
        int64_t tag;
        size_t at = r->t.pos;
        /* binary: an int even in 4.1, where other tags are size_t (gmsh 4.8 does so) */
        s = cm_msh_int(r, r->binary, "data tag", &tag);
        if (s != CM_OK) return s;
        int64_t idx = cm_msh_tagmap_find(map, tag);
        if (idx < 0)
            return cm_msh_err(r, CM_ERR_FORMAT, r->binary, at, "expected a %s tag in %s, got %lld",
                              where == CM_FIELD_NODE ? "node" : "element", sec, (long long)tag);
        for (int k = 0; k < comps; ++k) {
            s = cm_msh_double(r, r->binary, "data value", &data[idx * comps + k]);
            if (s != CM_OK) return s;
        }
    }
    return cm_msh_expect(r, r->binary, where == CM_FIELD_NODE ? "$EndNodeData" : "$EndElementData");
}
