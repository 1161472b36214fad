/* Abaqus input decks (.inp): lines, keywords and their data (abaqus_internal.h). Keywords and
 * parameters are case-insensitive, "**" starts a comment line, blank lines are skipped, a line
 * ending in ',' continues a keyword line or an element's node list. *INCLUDE (and INPUT= on
 * *NODE and *ELEMENT) is transparent: the included lines continue the keyword block they are
 * read in, so a *NODE block may take its data lines from another file. What the deck says
 * beyond the mesh (materials, steps, loads) is skipped here and kept byte for byte by the
 * writer. */
#define _POSIX_C_SOURCE 200809L
#include "abaqus_internal.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

/* ---- the reader's state between lines ---- */

enum { B_NONE, B_NODE, B_ELEMENT, B_NSET, B_ELSET, B_SURFACE, B_INSTANCE, B_SKIP_ELEMENT };

typedef struct abq_block {
    int kind;
    int set;              /* NSET= of *NODE, ELSET= of *ELEMENT, the set of a set or surface block */
    int generate;
    int64_t inst;         /* INSTANCE= of a set: the instance its ids are in (-1: own) */
    int node_surface;     /* *SURFACE, TYPE=NODE */
    abq_type type;
    char type_name[32];
    int64_t vals[21];     /* an element being read: id and nodes */
    int have;
    int inst_lines;       /* data lines of *INSTANCE taken */
} abq_block;

static cm_status parse_file(abq_reader *r, abq_block *blk, const char *path, const char *name);

static cm_status touch_nodes(abq_reader *r, abq_file *f)
{
    abq_part *p = &r->parts[r->cur];
    if (!p->used || p->node1 == p->node0) {
        if (p->node1 == p->node0) p->node0 = p->node1 = r->nn;
    } else if (p->node1 != r->nn)
        return abq_err(r, f, "expected the nodes of %s in one stretch of the deck (parts first, then the assembly)",
                   r->cur ? p->name : "the model");
    if (r->cur == 0 && r->any_part && !r->in_assembly)
        return abq_err(r, f, "expected *NODE inside *PART or *ASSEMBLY in a deck with parts");
    p->used = 1;
    return CM_OK;
}

static cm_status touch_cells(abq_reader *r, abq_file *f)
{
    abq_part *p = &r->parts[r->cur];
    if (p->cell1 == p->cell0) p->cell0 = p->cell1 = r->m->n_cells;
    else if (p->cell1 != r->m->n_cells)
        return abq_err(r, f, "expected the elements of %s in one stretch of the deck (parts first, then the assembly)",
                   r->cur ? p->name : "the model");
    if (r->cur == 0 && r->any_part && !r->in_assembly)
        return abq_err(r, f, "expected *ELEMENT inside *PART or *ASSEMBLY in a deck with parts");
    p->used = 1;
    return CM_OK;
}

static cm_status node_line(abq_reader *r, abq_file *f, abq_block *blk, const char *b, const char *e)
{
    const char *p = b, *fb, *fe;
    char show_buf[48];
    int64_t id;
    if (!abq_next_field(&p, e, &fb, &fe) || !cm_text_parse_int(fb, fe, &id))
        return abq_err(r, f, "expected a node id, got '%s'", abq_show(b, e, show_buf, sizeof show_buf));
    if (id < 1) return abq_err(r, f, "expected a node id >= 1, got %lld", (long long)id);
    const char *span = p;
    if (span > e) span = e;
    double x[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k) {
        const char *q = p;
        if (!abq_next_field(&q, e, &fb, &fe)) break;
        if (!abq_parse_coord(fb, fe, &x[k]))
            return abq_err(r, f, "expected a finite coordinate of node %lld, got '%s'", (long long)id, abq_show(fb, fe, show_buf, sizeof show_buf));
        p = q;
    }
    cm_status s = touch_nodes(r, f);
    if (s != CM_OK) return s;
    cm_mesh *m = r->m;
    if (r->nn == m->n_nodes) {
        s = cm_mesh_resize_nodes(r->ctx, m, m->n_nodes < 1024 ? 1024 : 2 * m->n_nodes, 1);
        if (s != CM_OK) return s;
    }
    memcpy(m->xyz + 3 * r->nn, x, sizeof x);
    m->node_tag[r->nn] = id;
    s = cm_rewrite_add_span(r->ctx, r->src, f->index, span - f->d, e - span, (int64_t)r->nn, -1);
    if (s == CM_OK && blk->set >= 0) s = abq_set_add(r, &r->sets[blk->set], -1, id, 0);
    ++r->nn;
    r->parts[r->cur].node1 = r->nn;
    return s;
}

static cm_status finish_element(abq_reader *r, abq_file *f, abq_block *blk)
{
    int64_t v[20];
    for (int k = 0; k < blk->type.nodes; ++k) v[k] = blk->vals[1 + (blk->type.perm ? blk->type.perm[k] : k)];
    cm_status s = touch_cells(r, f);
    if (s == CM_OK) s = cm_mesh_add_cell(r->ctx, r->m, blk->type.type, v, (size_t)blk->type.nodes, 0, 0, blk->vals[0]);
    if (s == CM_OK && blk->set >= 0) s = abq_set_add(r, &r->sets[blk->set], -1, blk->vals[0], 0);
    r->parts[r->cur].cell1 = r->m->n_cells;
    blk->have = 0;
    return s;
}

static cm_status element_line(abq_reader *r, abq_file *f, abq_block *blk, const char *b, const char *e)
{
    const char *p = b, *fb, *fe;
    char show_buf[48];
    const int want = blk->type.nodes + 1;
    while (abq_next_field(&p, e, &fb, &fe)) {
        int64_t v;
        if (blk->have == want)
            return abq_err(r, f, "expected %d nodes for element %lld of type %s, got more", want - 1,
                       (long long)blk->vals[0], blk->type_name);
        if (!cm_text_parse_int(fb, fe, &v))
            return abq_err(r, f, "expected an %s, got '%s'", blk->have ? "element's node id" : "element id",
                       abq_show(fb, fe, show_buf, sizeof show_buf));
        if (v < 1) return abq_err(r, f, "expected an id >= 1, got %lld", (long long)v);
        blk->vals[blk->have++] = v;
    }
    if (blk->have == want) return finish_element(r, f, blk);
    return CM_OK; /* the node list continues on the next line */
}

static cm_status set_line(abq_reader *r, abq_file *f, abq_block *blk, const char *b, const char *e)
{
    const char *p = b, *fb, *fe;
    char show_buf[48];
    abq_set *s = &r->sets[blk->set];
    const int kind = s->kind;
    if (blk->generate) {
        int64_t v[3] = {0, 0, 1};
        int k = 0;
        while (abq_next_field(&p, e, &fb, &fe)) {
            if (k == 3 || !cm_text_parse_int(fb, fe, &v[k]))
                return abq_err(r, f, "expected 'first, last[, increment]' of GENERATE, got '%s'", abq_show(b, e, show_buf, sizeof show_buf));
            ++k;
        }
        if (k < 2) return abq_err(r, f, "expected 'first, last[, increment]' of GENERATE");
        if (v[0] < 1 || v[1] < v[0] || v[2] < 1)
            return abq_err(r, f, "expected 1 <= first <= last and an increment >= 1, got %lld, %lld, %lld",
                       (long long)v[0], (long long)v[1], (long long)v[2]);
        const uint64_t count = (uint64_t)(v[1] - v[0]) / (uint64_t)v[2] + 1;
        const size_t bound = 16 * (r->nn + r->m->n_cells) + 65536;
        if (count > bound || r->members > bound - count)
            return abq_err(r, f, "expected a GENERATE range within the deck's ids, got %llu members", (unsigned long long)count);
        r->members += count;
        for (uint64_t i = 0; i < count; ++i) {
            cm_status st = abq_set_add(r, &r->sets[blk->set], blk->inst, v[0] + (int64_t)i * v[2], 0);
            if (st != CM_OK) return st;
        }
        return CM_OK;
    }
    while (abq_next_field(&p, e, &fb, &fe)) {
        int64_t v;
        if (fb == fe) continue;
        if (cm_text_parse_int(fb, fe, &v)) {
            if (v < 1) return abq_err(r, f, "expected an id >= 1, got %lld", (long long)v);
            cm_status st = abq_set_add(r, &r->sets[blk->set], blk->inst, v, 0);
            if (st != CM_OK) return st;
            ++r->members;
            continue;
        }
        char name[256];
        abq_show(fb, fe, name, sizeof name);
        int64_t inst = -1;
        const int part = blk->inst >= 0 ? r->insts[blk->inst].part : r->cur;
        const int from = abq_find_set(r, part, kind, name, &inst);
        if (from < 0 || from == blk->set)
            return abq_err(r, f, "expected a %s id or the name of a set defined before, got '%s'",
                       kind == ABQ_NSET ? "node" : "element", abq_show(fb, fe, show_buf, sizeof show_buf));
        cm_status st = abq_copy_set(r, f, blk->set, from, inst >= 0 ? inst : blk->inst, -1);
        if (st != CM_OK) return st;
    }
    return CM_OK;
}

static cm_status surface_line(abq_reader *r, abq_file *f, abq_block *blk, const char *b, const char *e)
{
    const char *p = b, *fb, *fe;
    char show_buf[48], name[256];
    if (!abq_next_field(&p, e, &fb, &fe)) return CM_OK;
    abq_show(fb, fe, name, sizeof name);
    int face = 0;
    if (!blk->node_surface) {
        const char *lb, *le;
        char label[16];
        face = 7; /* a shell's own side when no label */
        if (abq_next_field(&p, e, &lb, &le)) {
            abq_upper(label, sizeof label, lb, le);
            if (label[0] == 'S' && label[1] >= '1' && label[1] <= '6' && !label[2]) face = label[1] - '0';
            else if (!strcmp(label, "SPOS")) face = 7;
            else if (!strcmp(label, "SNEG")) face = 8;
            else return abq_err(r, f, "expected a face label S1..S6, SPOS or SNEG, got '%s'", abq_show(lb, le, show_buf, sizeof show_buf));
        }
    }
    int64_t v;
    if (cm_text_parse_int(fb, fe, &v)) {
        if (v < 1) return abq_err(r, f, "expected an id >= 1, got %lld", (long long)v);
        ++r->members;
        return abq_set_add(r, &r->sets[blk->set], -1, v, face);
    }
    int64_t inst = -1;
    const int from = abq_find_set(r, r->cur, blk->node_surface ? ABQ_NSET : ABQ_ELSET, name, &inst);
    if (from < 0)
        return abq_err(r, f, "expected an %s id or the name of a set defined before, got '%s'",
                   blk->node_surface ? "node" : "element", abq_show(fb, fe, show_buf, sizeof show_buf));
    return abq_copy_set(r, f, blk->set, from, inst, face);
}

/* Translation, then the rotation about a->b by an angle in degrees. */
static cm_status instance_line(abq_reader *r, abq_file *f, abq_block *blk, const char *b, const char *e)
{
    const char *p = b, *fb, *fe;
    double v[7] = {0};
    int k = 0;
    char show_buf[48];
    const int want = blk->inst_lines == 0 ? 3 : 7;
    if (blk->inst_lines >= 2) return abq_err(r, f, "expected at most two data lines of *INSTANCE");
    while (abq_next_field(&p, e, &fb, &fe)) {
        if (k == want || !abq_parse_coord(fb, fe, &v[k]))
            return abq_err(r, f, "expected %d numbers on this *INSTANCE line, got '%s'", want, abq_show(b, e, show_buf, sizeof show_buf));
        ++k;
    }
    abq_xform *x = &r->insts[r->n_insts - 1].x;
    if (blk->inst_lines++ == 0) {
        for (int i = 0; i < 3; ++i) x->c[i] += v[i];
    } else {
        double a[3] = {v[0], v[1], v[2]}, d[3] = {v[3] - v[0], v[4] - v[1], v[5] - v[2]};
        const double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(len > 0)) return abq_err(r, f, "expected two distinct points on the rotation axis");
        for (int i = 0; i < 3; ++i) d[i] /= len;
        const double th = v[6] * acos(-1.0) / 180.0, cs = cos(th), sn = sin(th), t = 1 - cs;
        const double R[9] = {cs + d[0] * d[0] * t, d[0] * d[1] * t - d[2] * sn, d[0] * d[2] * t + d[1] * sn,
                             d[1] * d[0] * t + d[2] * sn, cs + d[1] * d[1] * t, d[1] * d[2] * t - d[0] * sn,
                             d[2] * d[0] * t - d[1] * sn, d[2] * d[1] * t + d[0] * sn, cs + d[2] * d[2] * t};
        /* global = a + R (r local + c - a) */
        double nr[9], nc[3];
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j)
                nr[3 * i + j] = R[3 * i] * x->r[j] + R[3 * i + 1] * x->r[3 + j] + R[3 * i + 2] * x->r[6 + j];
            nc[i] = a[i] + R[3 * i] * (x->c[0] - a[0]) + R[3 * i + 1] * (x->c[1] - a[1]) + R[3 * i + 2] * (x->c[2] - a[2]);
        }
        memcpy(x->r, nr, sizeof nr);
        memcpy(x->c, nc, sizeof nc);
    }
    r->insts[r->n_insts - 1].moved = 1;
    return CM_OK;
}

/* A block left when the next keyword (or the end) comes. */
static cm_status end_block(abq_reader *r, abq_file *f, abq_block *blk)
{
    if (blk->kind == B_ELEMENT && blk->have)
        return abq_err(r, f, "expected %d nodes for element %lld of type %s, got %d (truncated?)", blk->type.nodes,
                   (long long)blk->vals[0], blk->type_name, blk->have - 1);
    return CM_OK;
}

/* The file named by INPUT=, relative to the directory of the file that names it; *full and
 * *rel (relative to the main file's directory, or absolute) are allocated. */
static cm_status include_path(abq_reader *r, abq_file *f, const char *input, char **full, char **rel)
{
    *full = *rel = NULL;
    if (!*input) return abq_err(r, f, "expected INPUT=<file>");
    const char *ref[2] = {f->path, f->name ? f->name : ""};
    char *out[2] = {NULL, NULL};
    for (int k = 0; k < 2; ++k) {
        const char *slash = strrchr(ref[k], '/');
        const size_t dir = input[0] == '/' || !slash ? 0 : (size_t)(slash - ref[k]) + 1;
        out[k] = malloc(dir + strlen(input) + 1);
        if (!out[k]) {
            free(out[0]);
            return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
        }
        memcpy(out[k], ref[k], dir);
        strcpy(out[k] + dir, input);
    }
    *full = out[0];
    *rel = out[1];
    return CM_OK;
}

static cm_status include(abq_reader *r, abq_file *f, abq_block *blk, const char *input)
{
    char *full, *rel;
    cm_status s = include_path(r, f, input, &full, &rel);
    if (s != CM_OK) return s;
    struct stat st;
    if (stat(full, &st) != 0) s = abq_err(r, f, "cannot open the included file %s: %s", full, strerror(errno));
    for (int k = 0; s == CM_OK && k < r->depth; ++k)
        if (r->dev[k] == st.st_dev && r->ino[k] == st.st_ino) s = abq_err(r, f, "the included file %s includes itself", full);
    if (s == CM_OK && r->depth >= ABQ_MAX_DEPTH) s = abq_err(r, f, "expected *INCLUDE nested at most %d deep", ABQ_MAX_DEPTH);
    if (s == CM_OK) s = parse_file(r, blk, full, rel);
    free(full);
    free(rel);
    return s;
}

static int find_part(const abq_reader *r, const char *name)
{
    for (size_t i = 1; i < r->n_parts; ++i)
        if (abq_name_eq(r->parts[i].name, name)) return (int)i;
    return -1;
}

static cm_status keyword_line(abq_reader *r, abq_file *f, abq_block *blk, const char *b, const char *e)
{
    abq_keyword *kw = malloc(sizeof *kw);
    if (!kw) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    cm_status s = abq_parse_keyword(r, f, b, e, kw);
    const char *k = kw->key;
    const int mesh_kw = !strcmp(k, "NODE") || !strcmp(k, "ELEMENT") || !strcmp(k, "NSET") ||
                        !strcmp(k, "ELSET") || !strcmp(k, "SURFACE");
    if (s == CM_OK && strcmp(k, "INCLUDE")) {
        s = end_block(r, f, blk);
        blk->kind = B_NONE;
        blk->set = -1;
        blk->inst = -1;
    }
    if (s != CM_OK) goto done;
    if (mesh_kw && r->in_instance) {
        s = abq_err(r, f, "expected *END INSTANCE before *%s (nodes and elements belong to a part)", k);
        goto done;
    }
    if (!strcmp(k, "INCLUDE")) {
        const char *in = abq_param(kw, "INPUT");
        s = include(r, f, blk, in ? in : "");
    } else if (!strcmp(k, "NODE")) {
        const char *sys = abq_param(kw, "SYSTEM");
        if (sys && strcasecmp(sys, "R")) {
            s = abq_err(r, f, "*NODE, SYSTEM=%s is not supported (rectangular coordinates only)", sys);
            goto done;
        }
        blk->kind = B_NODE;
        const char *ns = abq_param(kw, "NSET");
        if (ns) s = abq_get_set(r, f, r->cur, ABQ_NSET, ns, &blk->set);
        const char *in = abq_param(kw, "INPUT");
        if (s == CM_OK && in) s = include(r, f, blk, in);
    } else if (!strcmp(k, "ELEMENT")) {
        const char *type = abq_param(kw, "TYPE");
        if (!type || !*type) {
            s = abq_err(r, f, "expected TYPE= on *ELEMENT");
            goto done;
        }
        abq_upper(blk->type_name, sizeof blk->type_name, type, type + strlen(type));
        blk->have = 0;
        if (abq_element_type(blk->type_name, &blk->type)) {
            blk->kind = B_ELEMENT;
            const char *es = abq_param(kw, "ELSET");
            if (es) s = abq_get_set(r, f, r->cur, ABQ_ELSET, es, &blk->set);
        } else {
            blk->kind = B_SKIP_ELEMENT;
            if (!r->skipped) snprintf(r->skipped_type, sizeof r->skipped_type, "%s", blk->type_name);
            r->parts[r->cur].skipped = 1;
        }
        const char *in = abq_param(kw, "INPUT");
        if (s == CM_OK && in) s = include(r, f, blk, in);
    } else if (!strcmp(k, "NSET") || !strcmp(k, "ELSET")) {
        const int kind = k[0] == 'N' ? ABQ_NSET : ABQ_ELSET;
        const char *name = abq_param(kw, kind == ABQ_NSET ? "NSET" : "ELSET");
        if (!name) {
            s = abq_err(r, f, "expected %s= on *%s", k, k);
            goto done;
        }
        if (kind == ABQ_NSET && abq_param(kw, "ELSET")) {
            s = abq_err(r, f, "*NSET, ELSET= is not supported (list the nodes)");
            goto done;
        }
        blk->kind = kind == ABQ_NSET ? B_NSET : B_ELSET;
        blk->generate = abq_param(kw, "GENERATE") != NULL;
        const char *in = abq_param(kw, "INSTANCE");
        if (in) {
            int found = -1;
            for (size_t i = 0; i < r->n_insts; ++i)
                if (abq_name_eq(r->insts[i].name, in)) found = (int)i;
            if (found < 0 || r->cur != 0) {
                s = abq_err(r, f, "expected INSTANCE= to name an instance of the assembly, got '%s'", in);
                goto done;
            }
            blk->inst = found;
        }
        s = abq_get_set(r, f, r->cur, kind, name, &blk->set);
    } else if (!strcmp(k, "SURFACE")) {
        const char *name = abq_param(kw, "NAME"), *type = abq_param(kw, "TYPE");
        if (!name) {
            s = abq_err(r, f, "expected NAME= on *SURFACE");
            goto done;
        }
        if (type && strcasecmp(type, "ELEMENT") && strcasecmp(type, "NODE")) {
            blk->kind = B_NONE; /* analytical and cutting surfaces have no faces of the mesh */
            goto done;
        }
        blk->kind = B_SURFACE;
        blk->node_surface = type && !strcasecmp(type, "NODE");
        s = abq_get_set(r, f, r->cur, ABQ_SURFACE, name, &blk->set);
    } else if (!strcmp(k, "PART")) {
        const char *name = abq_param(kw, "NAME");
        if (!name || !*name) s = abq_err(r, f, "expected NAME= on *PART");
        else if (r->cur != 0 || r->in_assembly) s = abq_err(r, f, "expected *END PART (or *END ASSEMBLY) before *PART");
        else if (r->assembled) s = abq_err(r, f, "expected every *PART before *ASSEMBLY");
        else if (find_part(r, name) >= 0) s = abq_err(r, f, "part %s defined twice", name);
        else if (r->parts[0].used && !r->any_part) s = abq_err(r, f, "expected *PART before any *NODE or *ELEMENT of the model");
        if (s != CM_OK) goto done;
        abq_part *parts = abq_grow(r->parts, r->n_parts, sizeof *parts);
        if (!parts) {
            s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
            goto done;
        }
        r->parts = parts;
        memset(&parts[r->n_parts], 0, sizeof *parts);
        parts[r->n_parts].name = abq_dup(name);
        if (!parts[r->n_parts].name) {
            s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
            goto done;
        }
        r->cur = (int)r->n_parts++;
        r->any_part = 1;
    } else if (!strcmp(k, "ENDPART")) {
        if (r->cur == 0) s = abq_err(r, f, "*END PART without *PART");
        r->parts[r->cur].ended = 1;
        r->cur = 0;
    } else if (!strcmp(k, "ASSEMBLY")) {
        if (r->cur != 0 || r->in_assembly) s = abq_err(r, f, "expected *END PART before *ASSEMBLY");
        r->in_assembly = r->assembled = 1;
    } else if (!strcmp(k, "ENDASSEMBLY")) {
        if (r->in_instance) s = abq_err(r, f, "expected *END INSTANCE before *END ASSEMBLY");
        r->in_assembly = 0;
    } else if (!strcmp(k, "INSTANCE")) {
        const char *name = abq_param(kw, "NAME"), *part = abq_param(kw, "PART");
        if (!r->in_assembly || r->in_instance) {
            s = abq_err(r, f, "expected *INSTANCE inside *ASSEMBLY (and after *END INSTANCE)");
            goto done;
        }
        const int p = part ? find_part(r, part) : -1;
        if (!name || !*name || p < 0) {
            s = abq_err(r, f, "expected NAME= and PART= naming a part defined before, on *INSTANCE");
            goto done;
        }
        for (size_t i = 0; i < r->n_insts; ++i)
            if (abq_name_eq(r->insts[i].name, name)) {
                s = abq_err(r, f, "instance %s defined twice", name);
                goto done;
            }
        abq_inst *insts = abq_grow(r->insts, r->n_insts, sizeof *insts);
        if (!insts) {
            s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
            goto done;
        }
        r->insts = insts;
        abq_inst *in = &insts[r->n_insts];
        memset(in, 0, sizeof *in);
        in->name = abq_dup(name);
        if (!in->name) {
            s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
            goto done;
        }
        in->part = p;
        in->x.r[0] = in->x.r[4] = in->x.r[8] = 1.0;
        ++r->n_insts;
        r->parts[p].n_inst++;
        r->in_instance = 1;
        blk->kind = B_INSTANCE;
        blk->inst_lines = 0;
    } else if (!strcmp(k, "ENDINSTANCE")) {
        if (!r->in_instance) s = abq_err(r, f, "*END INSTANCE without *INSTANCE");
        r->in_instance = 0;
    }
done:
    free(kw);
    return s;
}

static cm_status data_line(abq_reader *r, abq_file *f, abq_block *blk, const char *b, const char *e)
{
    switch (blk->kind) {
    case B_NODE: return node_line(r, f, blk, b, e);
    case B_ELEMENT: return element_line(r, f, blk, b, e);
    case B_SKIP_ELEMENT:
        /* one element per line unless the line ends with a comma */
        if (!abq_ends_with_comma(b, e)) {
            ++r->skipped;
            r->parts[r->cur].skipped = 1;
        }
        return CM_OK;
    case B_NSET:
    case B_ELSET: return set_line(r, f, blk, b, e);
    case B_SURFACE: return surface_line(r, f, blk, b, e);
    case B_INSTANCE: return instance_line(r, f, blk, b, e);
    default: return CM_OK;
    }
}

static cm_status parse_file(abq_reader *r, abq_block *blk, const char *path, const char *name)
{
    char *data = NULL;
    size_t size = 0;
    cm_status s = cm_file_read(r->ctx, path, &data, &size);
    if (s != CM_OK) return s;
    abq_file f = {path, data, size, 0, 0, 0, name};
    s = cm_rewrite_add_file(r->ctx, r->src, path, name, &f.index);
    struct stat st;
    if (s == CM_OK && stat(path, &st) == 0) {
        r->dev[r->depth] = st.st_dev;
        r->ino[r->depth] = st.st_ino;
    }
    ++r->depth;
    const char *b, *e;
    while (s == CM_OK && abq_next_line(&f, &b, &e)) {
        const char *p = b;
        while (p < e && abq_blank(*p)) ++p;
        if (p == e) continue;
        if (p[0] == '*' && p + 1 < e && p[1] == '*') continue;
        if (p[0] == '*') s = keyword_line(r, &f, blk, p, e);
        else s = data_line(r, &f, blk, b, e);
    }
    --r->depth;
    if (s == CM_OK && r->depth == 0) s = end_block(r, &f, blk);
    free(data);
    return s;
}

void abq_reader_free(abq_reader *r)
{
    for (size_t i = 0; i < r->n_parts; ++i) free(r->parts[i].name);
    free(r->parts);
    for (size_t i = 0; i < r->n_insts; ++i) free(r->insts[i].name);
    free(r->insts);
    for (size_t i = 0; i < r->n_sets; ++i) {
        free(r->sets[i].name);
        free(r->sets[i].inst);
        free(r->sets[i].id);
        free(r->sets[i].face);
    }
    free(r->sets);
    free(r->set_slots);
    cm_rewrite_source_free(r->src);
}

cm_status cm_mesh_read_abaqus(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_read_abaqus: NULL argument");
    *mesh = NULL;
    abq_reader r;
    memset(&r, 0, sizeof r);
    r.ctx = ctx;
    cm_status s = cm_mesh_create(ctx, &r.m);
    if (s != CM_OK) return s;
    r.src = cm_rewrite_source_new();
    r.parts = calloc(1, sizeof *r.parts);
    if (!r.src || !r.parts) s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    r.n_parts = 1;
    abq_block blk;
    memset(&blk, 0, sizeof blk);
    blk.set = -1;
    blk.inst = -1;
    /* the deck is read file by file (each with the files it includes), not whole first */
    if (s == CM_OK) s = parse_file(&r, &blk, path, NULL);
    if (s == CM_OK && (r.cur != 0 || r.in_instance))
        s = cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: expected *END %s before the end of the deck (truncated?)",
                     path, r.in_instance ? "INSTANCE" : "PART");
    if (s == CM_OK) s = cm_mesh_resize_nodes(ctx, r.m, r.nn, 1);
    if (s == CM_OK) s = abq_build(&r, path);
    abq_reader_free(&r);
    if (s < 0) {
        cm_mesh_destroy(&r.m);
        return s;
    }
    *mesh = r.m;
    return s;
}
