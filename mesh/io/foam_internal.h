/* OpenFOAM polyMesh support shared by the reader, the writer, the face addressing of any mesh
 * and checkMesh's metrics (not public). A mesh read from a polyMesh keeps the face-addressed
 * original as its origin (origin.h), so that writing it back changes `points` only and the
 * metrics run on OpenFOAM's own faces. */
#ifndef CADMORPH_MESH_IO_FOAM_INTERNAL_H
#define CADMORPH_MESH_IO_FOAM_INTERNAL_H

#include "cadmorph/mesh.h"

/* A boundary patch: the dictionary is kept whole (every entry, as text between the braces). */
typedef struct cm_foam_patch {
    char *name;
    char *type;
    int64_t start, n; /* startFace, nFaces */
    char *dict;       /* the raw entries between { and } */
} cm_foam_patch;

typedef enum cm_foam_zone_kind { CM_FOAM_CELL_ZONE, CM_FOAM_FACE_ZONE, CM_FOAM_POINT_ZONE } cm_foam_zone_kind;

typedef struct cm_foam_zone {
    cm_foam_zone_kind kind;
    char *name;
    int64_t n;
    int64_t *ids;  /* cell, face or point labels */
    uint8_t *flip; /* face zones: flipMap (NULL if absent) */
} cm_foam_zone;

/* Face addressing as OpenFOAM stores it: faces oriented from owner to neighbour, internal
 * faces first, boundary faces grouped by patch. */
typedef struct cm_foam_poly {
    int refs;                  /* shared by cm_mesh_copy (atomic count): read-only after the read */
    char *dir;                 /* the polyMesh directory it was read from (NULL if built) */
    int64_t n_points, n_faces, n_internal, n_cells;
    int64_t *face_off;         /* #faces + 1 */
    int64_t *face_nodes;
    int64_t *owner;            /* #faces */
    int64_t *neighbour;        /* #internal faces */
    size_t n_patches;
    cm_foam_patch *patches;
    size_t n_zones;
    cm_foam_zone *zones;
    /* how `points` was stored, so that it is written back the same way */
    char *points_head;         /* bytes before the list (header, banner, comments) */
    size_t points_head_len;
    char *points_tail;         /* bytes after the closing ')' */
    size_t points_tail_len;
    int points_binary, points_gz, scalar_bytes, label_bytes;
    double *xyz0;              /* the points as read: a point equal to them keeps its text */
    /* the case directory (the one holding constant/, or processorN/ pieces) when the mesh
     * was read from a case, else NULL; the case's system/controlDict writePrecision, 0 when
     * absent (ASCII points moved are then written in the shortest exact text) */
    char *case_dir;
    int write_precision;
    /* a decomposed case: the pieces as read (processor0..n_pieces-1, each with its own dir,
     * points format and xyz0) and their local-to-global point labels (pointProcAddressing);
     * this record is then the merged mesh, processor faces internal (dir NULL) */
    size_t n_pieces;
    struct cm_foam_poly **pieces;
    int64_t **piece_points;
} cm_foam_poly;

/* Reads one polyMesh directory into p (points kept as p->xyz0). */
cm_status cm_foam_read_poly(cm_context *ctx, const char *dir, cm_foam_poly *p);
/* The mesh of a read record: cells (typed where their faces allow), patches as 2D cells,
 * cell zones as groups; p becomes its origin (consumed, also on failure). where: for
 * messages. */
cm_status cm_foam_mesh_of_poly(cm_context *ctx, cm_foam_poly *p, const char *where, cm_mesh **mesh);
/* The pieces of a decomposed case (case_dir/processorN/constant/polyMesh, N = 0, 1, ...)
 * merged into p through their *ProcAddressing files, as reconstructPar numbers the mesh. */
cm_status cm_foam_read_decomposed(cm_context *ctx, const char *case_dir, cm_foam_poly *p);
/* How a mesh path reads: 1 for a decomposed case (the case directory into *case_dir), 0 for
 * a polyMesh (see cm_foam_polymesh_dir). "case/processor*" (the literal name) asks for the
 * pieces; "case/" reads case/constant/polyMesh, or the pieces when only they exist. */
int cm_foam_decomposed_path(const char *path, char **case_dir);
/* The case of a polyMesh directory "X/constant/polyMesh": X (malloc'ed), else NULL. */
char *cm_foam_case_of(const char *polymesh_dir);
/* system/controlDict's writePrecision of a case (of a piece "X/processorN" read alone: X's),
 * 0 if none is found. */
int cm_foam_write_precision(const char *case_dir);
/* Copies the file src to dst through a temporary and a rename. */
cm_status cm_foam_copy_file(cm_context *ctx, const char *src, const char *dst);
/* Copies every regular file under src to dst (same layout, each through a temporary and a
 * rename), skipping the relative paths for which skip() returns 1. */
cm_status cm_foam_copy_tree(cm_context *ctx, const char *src, const char *dst,
                            int (*skip)(const char *rel, void *arg), void *arg);
/* 1 when a and b are the same directory or one lies inside the other (links resolved; a
 * path that does not exist yet is taken as written below its existing parent). */
int cm_foam_nested(const char *a, const char *b);

cm_foam_poly *cm_foam_poly_retain(cm_foam_poly *p);
void cm_foam_poly_release(cm_foam_poly **p);
/* cm_foam_poly_release for the mesh's origin record (origin.h). */
void cm_foam_poly_free(void *p);
/* An empty one (refs 1). */
cm_foam_poly *cm_foam_poly_new(void);

/* The polyMesh directory of a mesh path: "X/polyMesh" as is, else "X/constant/polyMesh".
 * Returns a malloc'ed string or NULL (out of memory). */
char *cm_foam_polymesh_dir(const char *path);
/* True for a path that names an OpenFOAM case or polyMesh directory (see io.c). */
int cm_foam_is_path(const char *path);

/* Face addressing of the volume cells of any mesh (faces matched by their node sets,
 * upper-triangular order, boundary faces in patches by the physical group of 2D cells that
 * cover them, the rest in "defaultFaces"). On success *out has refs 1. Its messages name no
 * function: the caller (writer, quality) puts its own in front. */
cm_status cm_foam_build(cm_context *ctx, const cm_mesh *mesh, cm_foam_poly **out);

/* The addressing to use for a mesh: its own (retained) when it was read from a polyMesh with
 * the same node count, else built. Release it after use. */
cm_status cm_foam_of_mesh(cm_context *ctx, const cm_mesh *mesh, cm_foam_poly **out);

/* out = dir + "/" + name + suffix (suffix may be NULL); returns 0, or -1 if it does not fit. */
int cm_foam_join(char *out, size_t cap, const char *dir, const char *name, const char *suffix);

/* ---- files: header, tokens, lists (foam_lex.c) ---- */

typedef struct cm_foam_file {
    char *path;          /* the file actually read (may end in .gz) */
    char *data;
    size_t size;
    int gz;
    /* FoamFile header */
    int binary;
    int label_bytes, scalar_bytes;
    char cls[64];
    size_t body;         /* offset just after the header dictionary */
} cm_foam_file;

/* Reads dir/name or dir/name.gz (zlib), parses the FoamFile header. optional: a missing file
 * returns CM_OK with f->data NULL instead of an error. A compressed file is inflated within a
 * budget (foam_lex.c, read_gz): entry_bytes per entry of its first count (the list size, the
 * number of patches or zones), that count taken as at most max_count (< 0: as written);
 * cm_foam_file_load uses 1 KiB per entry and no max_count. */
cm_status cm_foam_file_load(cm_context *ctx, const char *dir, const char *name, int optional,
                            cm_foam_file *f);
cm_status cm_foam_file_load_bounded(cm_context *ctx, const char *dir, const char *name, int optional,
                                    uint64_t entry_bytes, int64_t max_count, cm_foam_file *f);
void cm_foam_file_free(cm_foam_file *f);

/* A cursor over a file's bytes: tokens skip white space and C/C++ comments. */
typedef struct cm_foam_lex {
    const cm_foam_file *f;
    size_t pos;
    long line;
} cm_foam_lex;

typedef enum cm_foam_tok_kind {
    CM_FOAM_EOF = 0,
    CM_FOAM_PUNCT,   /* one of ( ) { } [ ] ; */
    CM_FOAM_WORD,    /* words and numbers */
    CM_FOAM_STRING   /* "..." (text without the quotes) */
} cm_foam_tok_kind;

typedef struct cm_foam_tok {
    cm_foam_tok_kind kind;
    const char *s;
    size_t len;
    size_t at;       /* offset of the token */
} cm_foam_tok;

void cm_foam_lex_init(cm_foam_lex *lx, const cm_foam_file *f, size_t pos);
cm_foam_tok cm_foam_next(cm_foam_lex *lx);
cm_foam_tok cm_foam_peek(cm_foam_lex *lx);
/* "path:line" or "path: byte N" into buf, for messages. */
const char *cm_foam_where(const cm_foam_lex *lx, char *buf, size_t cap);
/* Next token must be the punctuation c. */
cm_status cm_foam_expect(cm_context *ctx, cm_foam_lex *lx, char c, const char *what);
cm_status cm_foam_label(cm_context *ctx, cm_foam_lex *lx, const char *what, int64_t *v);

/* What a list's count may be, known from the other files before anything is allocated: in
 * [lo, hi], and for a uniform list "N{v}" at most uniform_hi. expect says it in messages
 * ("as many as the 12 faces"). Independently of it, a count must fit the bytes left in the
 * file (2 per ASCII label, the exact size of a binary block). */
typedef struct cm_foam_limit {
    int64_t lo, hi, uniform_hi;
    const char *expect;
} cm_foam_limit;

/* A list at the cursor, "N(...)" or "N{v}", ASCII or binary as the header says:
 * labels (int64), scalars, or fixed-size tuples of scalars (width 3 for points).
 * *out is malloc'ed (NULL for an empty list). lim may be NULL: any count that fits the file,
 * a uniform list of at most 2^20 entries. */
cm_status cm_foam_label_list(cm_context *ctx, cm_foam_lex *lx, const char *what, int64_t **out,
                             int64_t *n);
cm_status cm_foam_label_list_in(cm_context *ctx, cm_foam_lex *lx, const char *what,
                                const cm_foam_limit *lim, int64_t **out, int64_t *n);
cm_status cm_foam_scalar_list(cm_context *ctx, cm_foam_lex *lx, const char *what, int width,
                              const cm_foam_limit *lim, double **out, int64_t *n);
/* faceList (n(a b c) ...) or faceCompactList (offsets list + nodes list). */
cm_status cm_foam_face_list(cm_context *ctx, cm_foam_lex *lx, int compact, const char *what,
                            int64_t **off, int64_t **nodes, int64_t *n);

cm_status cm_foam_bool_list(cm_context *ctx, cm_foam_lex *lx, const char *what,
                            const cm_foam_limit *lim, uint8_t **out, int64_t *n);
/* Skips an entry's value up to (not including) the ';' that ends it (ASCII content only). */
cm_status cm_foam_skip_value(cm_context *ctx, cm_foam_lex *lx, const char *what);

#endif
