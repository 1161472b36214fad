/* A decomposed OpenFOAM case (processor0..N-1, each with constant/polyMesh as decomposePar
 * writes it) read as one mesh. Each piece is read whole and kept (the writer puts each
 * piece's points back in place); the merged record numbers points, cells and faces as
 * reconstructPar does, through the pieces' pointProcAddressing, cellProcAddressing,
 * faceProcAddressing (+-(global face + 1), negative where the piece sees the face from its
 * neighbour side) and boundaryProcAddressing (global patch, -1 for a processor patch). So the
 * processor faces become internal faces, patches and zones are merged by their global index
 * and name, and checkMesh's metrics run on the reconstructed addressing. */
#define _POSIX_C_SOURCE 200809L
#include "foam_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static int is_dir(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

static cm_status read_map(cm_context *ctx, const char *dir, const char *name, int64_t expect, int64_t **v)
{
    cm_foam_file f;
    cm_status s = cm_foam_file_load(ctx, dir, name, 0, &f);
    if (s != CM_OK) return s;
    cm_foam_lex lx;
    cm_foam_lex_init(&lx, &f, f.body);
    int64_t n = 0;
    s = cm_foam_label_list(ctx, &lx, name, v, &n);
    if (s == CM_OK && n != expect)
        s = cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: %lld entries, expected %lld", f.path, (long long)n,
                     (long long)expect);
    cm_foam_file_free(&f);
    return s;
}

typedef struct piece_maps {
    int64_t *cell, *face, *patch;
} piece_maps;

typedef struct zone_item {
    int64_t id;
    uint8_t flip;
} zone_item;

static int cmp_item(const void *a, const void *b)
{
    const zone_item *x = a, *y = b;
    return x->id < y->id ? -1 : x->id > y->id;
}

/* Zones merged by kind and name, labels made global, sorted, each once. */
static cm_status merge_zones(cm_context *ctx, cm_foam_poly *p, piece_maps *maps)
{
    for (size_t i = 0; i < p->n_pieces; ++i) {
        const cm_foam_poly *q = p->pieces[i];
        for (size_t z = 0; z < q->n_zones; ++z) {
            const cm_foam_zone *zq = &q->zones[z];
            size_t k = 0;
            while (k < p->n_zones && !(p->zones[k].kind == zq->kind && !strcmp(p->zones[k].name, zq->name))) ++k;
            if (k == p->n_zones) {
                cm_foam_zone *g = realloc(p->zones, (p->n_zones + 1) * sizeof *g);
                if (!g) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
                p->zones = g;
                memset(&g[k], 0, sizeof g[k]);
                g[k].kind = zq->kind;
                ++p->n_zones;
                if (!(g[k].name = strdup(zq->name))) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
            }
            cm_foam_zone *zg = &p->zones[k];
            if (!zq->n) continue;
            int64_t *ids = realloc(zg->ids, (size_t)(zg->n + zq->n) * sizeof *ids);
            if (ids) zg->ids = ids;
            uint8_t *fl = NULL;
            if (ids && zq->kind == CM_FOAM_FACE_ZONE) {
                fl = realloc(zg->flip, (size_t)(zg->n + zq->n));
                if (fl) zg->flip = fl;
            }
            if (!ids || (zq->kind == CM_FOAM_FACE_ZONE && !fl))
                return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
            for (int64_t j = 0; j < zq->n; ++j) {
                int64_t l = zq->ids[j], gid;
                uint8_t flip = 0;
                if (zq->kind == CM_FOAM_CELL_ZONE) {
                    gid = maps[i].cell[l];
                } else if (zq->kind == CM_FOAM_POINT_ZONE) {
                    gid = p->piece_points[i][l];
                } else {
                    int64_t a = maps[i].face[l];
                    gid = (a < 0 ? -a : a) - 1;
                    flip = (uint8_t)((zq->flip ? zq->flip[j] : 0) ^ (a < 0));
                }
                zg->ids[zg->n] = gid;
                if (zg->flip) zg->flip[zg->n] = flip;
                ++zg->n;
            }
        }
    }
    for (size_t k = 0; k < p->n_zones; ++k) {
        cm_foam_zone *zg = &p->zones[k];
        if (zg->n < 2) continue;
        zone_item *it = malloc((size_t)zg->n * sizeof *it);
        if (!it) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
        for (int64_t j = 0; j < zg->n; ++j) it[j] = (zone_item){zg->ids[j], zg->flip ? zg->flip[j] : 0};
        qsort(it, (size_t)zg->n, sizeof *it, cmp_item);
        int64_t m = 0;
        for (int64_t j = 0; j < zg->n; ++j)
            if (!m || it[j].id != it[m - 1].id) it[m++] = it[j];
        for (int64_t j = 0; j < m; ++j) {
            zg->ids[j] = it[j].id;
            if (zg->flip) zg->flip[j] = it[j].flip;
        }
        zg->n = m;
        free(it);
    }
    return CM_OK;
}

/* A processorCyclic patch holds faces of the cyclic patch its referPatch entry names: their
 * global patch is that one's (a processor patch proper has none: -1). */
static int64_t refer_patch(const cm_foam_poly *q, size_t lp, const int64_t *patch_map)
{
    const cm_foam_patch *pt = &q->patches[lp];
    if (!pt->type || strcmp(pt->type, "processorCyclic") || !pt->dict) return -1;
    const char *r = strstr(pt->dict, "referPatch");
    if (!r) return -1;
    r += 10;
    while (*r == ' ' || *r == '\t' || *r == '\n' || *r == '\r') ++r;
    size_t l = strcspn(r, " \t\n\r;");
    for (size_t k = 0; k < q->n_patches; ++k)
        if (strlen(q->patches[k].name) == l && !memcmp(q->patches[k].name, r, l)) return patch_map[k];
    return -1;
}

static cm_status bad(cm_context *ctx, const char *case_dir, const char *what)
{
    return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: the processor pieces do not form one mesh: %s", case_dir, what);
}

/* The merged addressing from the pieces and their maps. */
static cm_status merge(cm_context *ctx, const char *case_dir, cm_foam_poly *p, piece_maps *maps)
{
    int64_t np = 0, nc = 0, nf = 0, npt = 0;
    for (size_t i = 0; i < p->n_pieces; ++i) {
        const cm_foam_poly *q = p->pieces[i];
        for (int64_t k = 0; k < q->n_points; ++k) np = p->piece_points[i][k] + 1 > np ? p->piece_points[i][k] + 1 : np;
        for (int64_t k = 0; k < q->n_cells; ++k) nc = maps[i].cell[k] + 1 > nc ? maps[i].cell[k] + 1 : nc;
        for (int64_t k = 0; k < q->n_faces; ++k) {
            int64_t a = maps[i].face[k] < 0 ? -maps[i].face[k] : maps[i].face[k];
            if (a == 0) return bad(ctx, case_dir, "faceProcAddressing holds 0");
            nf = a > nf ? a : nf;
        }
        for (size_t k = 0; k < q->n_patches; ++k) npt = maps[i].patch[k] + 1 > npt ? maps[i].patch[k] + 1 : npt;
        for (int64_t k = 0; k < q->n_points; ++k)
            if (p->piece_points[i][k] < 0) return bad(ctx, case_dir, "a negative point label");
        for (int64_t k = 0; k < q->n_cells; ++k)
            if (maps[i].cell[k] < 0) return bad(ctx, case_dir, "a negative cell label");
    }
    cm_status s = CM_OK;
    int64_t *len = calloc((size_t)nf + 1, sizeof *len), *own = malloc(((size_t)nf + 1) * sizeof *own),
            *nei = malloc(((size_t)nf + 1) * sizeof *nei), *patch = malloc(((size_t)nf + 1) * sizeof *patch);
    const cm_foam_poly **src = calloc((size_t)nf + 1, sizeof *src);
    int64_t *src_face = malloc(((size_t)nf + 1) * sizeof *src_face);
    size_t *src_piece = malloc(((size_t)nf + 1) * sizeof *src_piece);
    uint8_t *seen = calloc((size_t)(np > nc ? np : nc) + 1, 1);
    p->xyz0 = malloc(((size_t)np * 3 + 1) * sizeof *p->xyz0);
    if (!len || !own || !nei || !patch || !src || !src_face || !src_piece || !seen || !p->xyz0) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory merging the processor pieces");
        goto done;
    }
    for (int64_t g = 0; g < nf; ++g) own[g] = nei[g] = patch[g] = -1;
    for (size_t i = 0; i < p->n_pieces && s == CM_OK; ++i) {
        const cm_foam_poly *q = p->pieces[i];
        for (int64_t k = 0; k < q->n_points; ++k) {
            int64_t g = p->piece_points[i][k];
            memcpy(p->xyz0 + 3 * g, q->xyz0 + 3 * k, 3 * sizeof(double));
            seen[g] = 1;
        }
        /* local patch of each boundary face */
        size_t lp = 0;
        for (int64_t f = 0; f < q->n_faces; ++f) {
            int64_t a = maps[i].face[f], g = (a < 0 ? -a : a) - 1, lo = q->owner[f];
            int64_t ln = f < q->n_internal ? q->neighbour[f] : -1;
            int64_t gpatch = -1;
            if (f >= q->n_internal) {
                while (lp < q->n_patches && f >= q->patches[lp].start + q->patches[lp].n) ++lp;
                gpatch = lp < q->n_patches ? maps[i].patch[lp] : -1;
                if (gpatch < 0 && lp < q->n_patches) gpatch = refer_patch(q, lp, maps[i].patch);
            }
            if (f >= q->n_internal && gpatch >= 0) patch[g] = gpatch;
            if (a > 0) {
                own[g] = maps[i].cell[lo];
                if (ln >= 0) nei[g] = maps[i].cell[ln];
                src[g] = q;
                src_face[g] = f;
                src_piece[g] = i;
                len[g] = q->face_off[f + 1] - q->face_off[f];
            } else if (ln >= 0) {
                s = bad(ctx, case_dir, "an internal face of a piece flipped in faceProcAddressing");
                break;
            } else if (gpatch >= 0) {
                s = bad(ctx, case_dir, "a boundary face flipped in faceProcAddressing");
                break;
            } else {
                nei[g] = maps[i].cell[lo]; /* a processor face seen from the neighbour's side */
            }
        }
    }
    for (int64_t g = 0; s == CM_OK && g < np; ++g)
        if (!seen[g]) s = bad(ctx, case_dir, "a point in no piece");
    int64_t n_int = 0;
    while (s == CM_OK && n_int < nf && nei[n_int] >= 0) ++n_int;
    for (int64_t g = 0; s == CM_OK && g < nf; ++g) {
        if (!src[g]) s = bad(ctx, case_dir, "a face no piece owns");
        else if (g >= n_int && nei[g] >= 0) s = bad(ctx, case_dir, "internal faces after boundary faces");
        else if (g >= n_int && patch[g] < 0) s = bad(ctx, case_dir, "a processor face with one side only");
        else if (g > n_int && patch[g] < patch[g - 1]) s = bad(ctx, case_dir, "patches out of order");
    }
    if (s != CM_OK) goto done;
    p->n_points = np;
    p->n_cells = nc;
    p->n_faces = nf;
    p->n_internal = n_int;
    p->face_off = malloc(((size_t)nf + 1) * sizeof *p->face_off);
    p->owner = own;
    p->neighbour = nei;
    own = nei = NULL;
    if (!p->face_off) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
        goto done;
    }
    p->face_off[0] = 0;
    for (int64_t g = 0; g < nf; ++g) p->face_off[g + 1] = p->face_off[g] + len[g];
    p->face_nodes = malloc(((size_t)p->face_off[nf] + 1) * sizeof *p->face_nodes);
    p->patches = calloc((size_t)npt + 1, sizeof *p->patches);
    if (!p->face_nodes || !p->patches) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
        goto done;
    }
    for (int64_t g = 0; g < nf; ++g) {
        const cm_foam_poly *q = src[g];
        int64_t f = src_face[g];
        for (int64_t k = 0; k < len[g]; ++k)
            p->face_nodes[p->face_off[g] + k] = p->piece_points[src_piece[g]][q->face_nodes[q->face_off[f] + k]];
    }
    /* patches: names and dictionaries from the first piece that has them, faces counted */
    p->n_patches = (size_t)npt;
    for (size_t i = 0; i < p->n_pieces && s == CM_OK; ++i)
        for (size_t k = 0; k < p->pieces[i]->n_patches && s == CM_OK; ++k) {
            int64_t g = maps[i].patch[k];
            const cm_foam_patch *lq = &p->pieces[i]->patches[k];
            if (g < 0 || p->patches[g].name) continue;
            p->patches[g].name = strdup(lq->name);
            p->patches[g].type = strdup(lq->type ? lq->type : "patch");
            p->patches[g].dict = strdup(lq->dict ? lq->dict : "");
            if (!p->patches[g].name || !p->patches[g].type || !p->patches[g].dict)
                s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
        }
    int64_t at = n_int;
    for (int64_t k = 0; s == CM_OK && k < npt; ++k) {
        if (!p->patches[k].name) {
            s = bad(ctx, case_dir, "a patch that no piece names");
            break;
        }
        p->patches[k].start = at;
        while (at < nf && patch[at] == k) ++at;
        p->patches[k].n = at - p->patches[k].start;
    }
    if (s == CM_OK && at != nf) s = bad(ctx, case_dir, "boundary faces outside the patches");
    for (int64_t c = 0; c < nc; ++c) seen[c] = 0;
    for (size_t i = 0; s == CM_OK && i < p->n_pieces; ++i)
        for (int64_t k = 0; k < p->pieces[i]->n_cells; ++k) seen[maps[i].cell[k]] = 1;
    for (int64_t c = 0; s == CM_OK && c < nc; ++c)
        if (!seen[c]) s = bad(ctx, case_dir, "a cell in no piece");
    if (s == CM_OK) s = merge_zones(ctx, p, maps);
done:
    free(len);
    free(own);
    free(nei);
    free(patch);
    free(src);
    free(src_face);
    free(src_piece);
    free(seen);
    return s;
}

cm_status cm_foam_read_decomposed(cm_context *ctx, const char *case_dir, cm_foam_poly *p)
{
    char dir[4200];
    size_t n = 0;
    for (;;) {
        snprintf(dir, sizeof dir, "%s/processor%zu/constant/polyMesh", case_dir, n);
        if (!is_dir(dir)) break;
        ++n;
    }
    if (n == 0)
        return cm_error(ctx, CM_ERR_IO, "cm_mesh_read: %s: no processor0/constant/polyMesh (a decomposed case)", case_dir);
    p->pieces = calloc(n, sizeof *p->pieces);
    p->piece_points = calloc(n, sizeof *p->piece_points);
    piece_maps *maps = calloc(n, sizeof *maps);
    if (!p->pieces || !p->piece_points || !maps) {
        free(maps);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    }
    p->n_pieces = n;
    cm_status s = CM_OK;
    for (size_t i = 0; s == CM_OK && i < n; ++i) {
        snprintf(dir, sizeof dir, "%s/processor%zu/constant/polyMesh", case_dir, i);
        if (!(p->pieces[i] = cm_foam_poly_new())) {
            s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
            break;
        }
        cm_foam_poly *q = p->pieces[i];
        s = cm_foam_read_poly(ctx, dir, q);
        if (s == CM_OK) s = read_map(ctx, dir, "pointProcAddressing", q->n_points, &p->piece_points[i]);
        if (s == CM_OK) s = read_map(ctx, dir, "cellProcAddressing", q->n_cells, &maps[i].cell);
        if (s == CM_OK) s = read_map(ctx, dir, "faceProcAddressing", q->n_faces, &maps[i].face);
        if (s == CM_OK) s = read_map(ctx, dir, "boundaryProcAddressing", (int64_t)q->n_patches, &maps[i].patch);
    }
    if (s == CM_OK) s = merge(ctx, case_dir, p, maps);
    for (size_t i = 0; i < n; ++i) {
        free(maps[i].cell);
        free(maps[i].face);
        free(maps[i].patch);
    }
    free(maps);
    return s;
}
