/* Off-CAD boundary nodes kept fixed: a wind tunnel around a body is a boundary component of
 * its own, none of whose nodes is on the body's CAD model. A component with some nodes on G
 * and some off is a body touching the fixed surface (a car on the tunnel's floor) - or a mesh
 * that is partly not of G (a missing face, a tolerance too tight for a snapped surface). The
 * nodes off G stay; the contact nodes (on G, on a boundary face with a node off G) may follow
 * the CAD only within the fixed surface around them (its plane where it is flat), so the
 * first case morphs and the second, whose contact nodes sit on curved faces, is refused as
 * soon as the edit moves them. */
#include "off_cad.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void cm_off_cad_contact_free(cm_off_cad_contact *c)
{
    if (!c) return;
    free(c->index), free(c->normal), free(c->tol);
    memset(c, 0, sizeof *c);
}

/* Newell's normal of face f (not normalised: its length is twice the area). */
static void face_normal(const cm_mesh *mesh, const cm_mesh_boundary *b, size_t f, double n[3])
{
    int64_t a = b->face_offset[f], e = b->face_offset[f + 1];
    n[0] = n[1] = n[2] = 0;
    for (int64_t k = a; k < e; ++k) {
        const double *p = mesh->xyz + 3 * b->face_nodes[k];
        const double *q = mesh->xyz + 3 * b->face_nodes[k + 1 < e ? k + 1 : a];
        n[0] += (p[1] - q[1]) * (p[2] + q[2]);
        n[1] += (p[2] - q[2]) * (p[0] + q[0]);
        n[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
}

/* 1 if boundary face f has a node off G (state 2) */
static int face_has_off(const cm_mesh_boundary *b, const unsigned char *state, size_t f)
{
    for (int64_t k = b->face_offset[f]; k < b->face_offset[f + 1]; ++k)
        if ((state[b->face_nodes[k]] & 3) == 2) return 1;
    return 0;
}

/* distance of nodes v and w */
static double node_dist(const cm_mesh *mesh, int64_t v, int64_t w)
{
    const double *p = mesh->xyz + 3 * v, *q = mesh->xyz + 3 * w;
    return sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                (p[2] - q[2]) * (p[2] - q[2]));
}

/* The contact nodes and the fixed surface around each (state: 1 on G, 2 off G, per node;
 * at: index into nodes->node, per node). */
static cm_status find_contact(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                              const unsigned char *state, const int64_t *at,
                              cm_off_cad_contact *c)
{
    size_t nn = mesh->n_nodes;
    int64_t *slot = malloc((nn ? nn : 1) * sizeof *slot);
    if (!slot) return cm_error(ctx, CM_ERR_NOMEM, "off-CAD check: out of memory");
    for (size_t i = 0; i < nn; ++i)
        slot[i] = -1;
    /* faces with a node off G and one on G: their on nodes are contact nodes */
    for (size_t f = 0; f < b->n_faces; ++f) {
        int64_t a = b->face_offset[f], e = b->face_offset[f + 1];
        const int has_off = face_has_off(b, state, f);
        if (!has_off) continue;
        for (int64_t k = a; k < e; ++k) {
            int64_t v = b->face_nodes[k];
            if ((state[v] & 3) == 1 && slot[v] < 0) slot[v] = (int64_t)c->n++;
        }
    }
    c->index = malloc((c->n ? c->n : 1) * sizeof *c->index);
    c->normal = calloc((c->n ? c->n : 1) * 3, sizeof *c->normal);
    c->tol = malloc((c->n ? c->n : 1) * sizeof *c->tol);
    unsigned char *curved = calloc(c->n ? c->n : 1, 1);
    if (!c->index || !c->normal || !c->tol || !curved) {
        free(slot), free(curved);
        cm_off_cad_contact_free(c);
        return cm_error(ctx, CM_ERR_NOMEM, "off-CAD check: out of memory");
    }
    for (size_t i = 0; i < nn; ++i)
        if (slot[i] >= 0) c->index[slot[i]] = (size_t)at[i], c->tol[slot[i]] = INFINITY;
    /* pass 1: the area-weighted normal of the faces with an off node around each contact node,
     * and its shortest boundary edge */
    for (size_t f = 0; f < b->n_faces; ++f) {
        int64_t a = b->face_offset[f], e = b->face_offset[f + 1];
        const int has_off = face_has_off(b, state, f);
        double n[3] = {0, 0, 0};
        if (has_off) face_normal(mesh, b, f, n);
        for (int64_t k = a; k < e; ++k) {
            int64_t v = b->face_nodes[k], s = slot[v];
            if (s < 0) continue;
            /* the shorter of its two edges in this face */
            const int64_t nb[2] = {b->face_nodes[k + 1 < e ? k + 1 : a],
                                   b->face_nodes[k > a ? k - 1 : e - 1]};
            for (int t = 0; t < 2; ++t) {
                const double len = node_dist(mesh, v, nb[t]);
                if (len > 0 && 1e-3 * len < c->tol[s]) c->tol[s] = 1e-3 * len;
            }
            if (has_off)
                for (int d = 0; d < 3; ++d)
                    c->normal[3 * s + d] += n[d];
        }
    }
    for (size_t s = 0; s < c->n; ++s) {
        double *n = c->normal + 3 * s, l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(c->tol[s] < INFINITY)) c->tol[s] = 0;
        if (l > 0)
            n[0] /= l, n[1] /= l, n[2] /= l;
        else
            curved[s] = 1;
    }
    /* pass 2: flat means every node of those faces within tol of the plane */
    for (size_t f = 0; f < b->n_faces; ++f) {
        int64_t a = b->face_offset[f], e = b->face_offset[f + 1];
        const int has_off = face_has_off(b, state, f);
        if (!has_off) continue;
        for (int64_t k = a; k < e; ++k) {
            int64_t v = b->face_nodes[k], s = slot[v];
            if (s < 0 || curved[s]) continue;
            const double *n = c->normal + 3 * s, *p = mesh->xyz + 3 * v;
            for (int64_t j = a; j < e; ++j) {
                const double *q = mesh->xyz + 3 * b->face_nodes[j];
                double h = n[0] * (q[0] - p[0]) + n[1] * (q[1] - p[1]) + n[2] * (q[2] - p[2]);
                if (fabs(h) > c->tol[s]) curved[s] = 1;
            }
        }
    }
    for (size_t s = 0; s < c->n; ++s)
        if (curved[s]) c->normal[3 * s] = c->normal[3 * s + 1] = c->normal[3 * s + 2] = 0;
    free(slot), free(curved);
    return CM_OK;
}

cm_status cm_morph_off_cad_contact_check(cm_context *ctx, const cm_mesh *mesh,
                                         const cm_surface_nodes *nodes,
                                         const cm_off_cad_contact *c, const double *bnew)
{
    for (size_t s = 0; s < c->n; ++s) {
        size_t i = c->index[s];
        int64_t v = nodes->node[i];
        const double *p = mesh->xyz + 3 * v, *q = bnew + 3 * i, *n = c->normal + 3 * s;
        double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        int flat = n[0] != 0 || n[1] != 0 || n[2] != 0;
        double off = flat ? fabs(n[0] * d[0] + n[1] * d[1] + n[2] * d[2])
                          : sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (off > c->tol[s])
            return cm_error(ctx, CM_ERR_MISMATCH,
                            "node %lld is on the CAD model and touches the fixed surface off it "
                            "(%zu such contact nodes), and the edit moves it %s by %.6g (allowed "
                            "%.3g): --off-cad fixed lets a body touching the fixed surface slide "
                            "only along it where it is flat (if the nodes off the model are the "
                            "body's own, e.g. a mesh snapped onto an STL, raise --cad-tol)",
                            (long long)v, c->n, flat ? "off that surface's plane" : "(that surface is not flat there)",
                            off, c->tol[s]);
    }
    return CM_OK;
}

static int64_t find(int64_t *parent, int64_t i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]]; /* path halving */
        i = parent[i];
    }
    return i;
}

cm_status cm_morph_off_cad_check(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                                 const cm_surface_nodes *nodes, size_t *n_components,
                                 size_t *n_partial, cm_off_cad_contact *contact)
{
    *n_components = *n_partial = 0;
    memset(contact, 0, sizeof *contact);
    if (!nodes->n_off) return CM_OK;
    size_t nn = mesh->n_nodes;
    /* parent over mesh nodes (only boundary ones are used); state: 1 on G, 2 off G */
    int64_t *parent = malloc((nn ? nn : 1) * sizeof *parent);
    unsigned char *state = calloc(nn ? nn : 1, 1);
    size_t *on = calloc(nn ? nn : 1, sizeof *on), *off = calloc(nn ? nn : 1, sizeof *off);
    int64_t *far = malloc((nn ? nn : 1) * sizeof *far); /* per root: farthest off node (index) */
    if (!parent || !state || !on || !off || !far) {
        free(parent), free(state), free(on), free(off), free(far);
        return cm_error(ctx, CM_ERR_NOMEM, "off-CAD check: out of memory for %zu nodes", nn);
    }
    for (size_t i = 0; i < nn; ++i)
        parent[i] = (int64_t)i, far[i] = -1;
    for (size_t f = 0; f < b->n_faces; ++f) {
        int64_t a = b->face_offset[f], e = b->face_offset[f + 1];
        for (int64_t k = a + 1; k < e; ++k) {
            int64_t p = find(parent, b->face_nodes[a]), q = find(parent, b->face_nodes[k]);
            if (p != q) parent[q] = p;
        }
    }
    for (size_t i = 0; i < nodes->n; ++i)
        state[nodes->node[i]] = 1;
    for (size_t i = 0; i < nodes->n_off; ++i)
        state[nodes->off[i]] = 2;
    for (size_t i = 0; i < nodes->n; ++i)
        ++on[find(parent, nodes->node[i])];
    for (size_t i = 0; i < nodes->n_off; ++i) {
        int64_t r = find(parent, nodes->off[i]);
        ++off[r];
        if (far[r] < 0 || nodes->off_dist[i] > nodes->off_dist[far[r]]) far[r] = (int64_t)i;
    }
    /* components in the order of their smallest boundary node (b->nodes is ascending) */
    cm_status s = CM_OK;
    for (size_t j = 0; j < b->n_nodes; ++j) {
        int64_t r = find(parent, b->nodes[j]);
        if (state[r] & 4) continue; /* seen */
        state[r] |= 4;
        if (off[r] && !on[r]) ++*n_components;
        if (off[r] && on[r]) ++*n_partial;
    }
    if (*n_partial) {
        for (size_t i = 0; i < nodes->n; ++i)
            far[nodes->node[i]] = (int64_t)i; /* reused: index into nodes->node */
        s = find_contact(ctx, mesh, b, state, far, contact);
    }
    free(parent), free(state), free(on), free(off), free(far);
    return s;
}
