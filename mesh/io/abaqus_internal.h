/* Abaqus input decks (.inp), shared by the reader (abaqus_lex.c: lines, fields, keywords,
 * sets; abaqus_read.c: the keywords' data), the model builder (abaqus_build.c: parts
 * instanced, sets and surfaces as groups) and the writer (abaqus_write.c: back into the deck,
 * or a plain new deck). Not public. */
#ifndef CADMORPH_MESH_IO_ABAQUS_INTERNAL_H
#define CADMORPH_MESH_IO_ABAQUS_INTERNAL_H

#include "formats.h"
#include "rewrite.h"
#include "text.h"

#include <sys/types.h>

enum { ABQ_MAX_DEPTH = 16 };

/* An instance's placement: global = r local + c (translation first, then the rotation about
 * the axis a->b, as the *INSTANCE data lines give them). */
typedef struct abq_xform {
    double r[9], c[3];
} abq_xform;

typedef struct abq_inst {
    char *name;
    int part;
    abq_xform x;
    int moved;               /* not the identity */
    size_t node_base, cell_base; /* the instance's first node and cell in the mesh (built) */
} abq_inst;

/* The writer's record (the rewrite source's format): what a span's aux names. */
typedef struct abq_record {
    size_t n_insts;
    abq_inst *insts;         /* placements, parts, bases and names */
    size_t n_parts;
    size_t *part_nodes;      /* nodes of each part's template */
} abq_record;

typedef struct abq_part {
    char *name;
    size_t node0, node1, cell0, cell1; /* the template's ranges in the mesh */
    int used;                /* has nodes or cells */
    size_t n_inst;
    int ended;
    size_t skipped;          /* elements of unknown types */
} abq_part;

enum { ABQ_NSET = 0, ABQ_ELSET = 1, ABQ_SURFACE = 2 };

typedef struct abq_set {
    char *name;
    int kind;                /* ABQ_NSET, ABQ_ELSET, ABQ_SURFACE */
    int part;                /* defined in part (0: the model or the assembly) */
    size_t n, cap;
    int64_t *inst;           /* per member: instance (-1: the set's own scope) */
    int64_t *id;             /* node or element id */
    unsigned char *face;     /* surfaces: face 1..6, 7 SPOS, 8 SNEG, 0 a node surface */
} abq_set;

typedef struct abq_reader {
    cm_context *ctx;
    cm_mesh *m;
    cm_rewrite_source *src;
    size_t nn;               /* nodes read (m->n_nodes is the capacity while reading) */
    abq_part *parts;         /* parts[0]: the model (a flat deck) or the assembly level */
    size_t n_parts;
    int cur;                 /* the scope being read */
    int in_assembly, in_instance, any_part, assembled;
    abq_inst *insts;
    size_t n_insts;
    abq_set *sets;
    size_t n_sets;
    int *set_slots;          /* a hash of (part, kind, name ignoring case) -> set, -1 empty */
    size_t set_mask;
    int depth;
    dev_t dev[ABQ_MAX_DEPTH];
    ino_t ino[ABQ_MAX_DEPTH];
    size_t members;          /* set members in all: bounded (abaqus_read.c) */
    size_t skipped;          /* elements of unknown types */
    char skipped_type[32];
} abq_reader;

/* One cell type: its node count, the mesh type and the permutation vtk[i] = abaqus[perm[i]]
 * (NULL: the same order). */
typedef struct abq_type {
    int nodes;
    cm_cell_type type;
    const int *perm;
} abq_type;

/* The type of an Abaqus element name (upper-case); 0 when cadmorph has no such cell. */
int abq_element_type(const char *name, abq_type *t);
/* Abaqus-order nodes of face f (1..6) of a solid of n nodes, outward; returns the node count
 * (3, 4, 6, 8) or 0 for no such face; *type the face's cell type. */
int abq_face_nodes(int n_nodes, int f, int local[8], cm_cell_type *type);

int abq_name_eq(const char *a, const char *b);
cm_status abq_set_add(abq_reader *r, abq_set *s, int64_t inst, int64_t id, int face);
/* The set named name (case-insensitive) of kind in scope part, or "inst.name" from the
 * assembly; -1 when none. *inst receives the instance of a qualified name (else -1). */
int abq_find_set(const abq_reader *r, int part, int kind, const char *name, int64_t *inst);

/* ---- lines, fields, numbers, keywords (abaqus_lex.c) ---- */

typedef struct abq_file {
    const char *path;
    const char *d;
    size_t n, pos;
    long line;      /* of the line last taken */
    size_t index;   /* in the rewrite source */
    const char *name; /* relative to the main file's directory (NULL: the main file) */
} abq_file;

enum { KW_MAX_PARAMS = 24, KW_VALUE = 1024 };

typedef struct abq_keyword {
    char key[48]; /* upper case, blanks removed, without '*' */
    int n;
    char name[KW_MAX_PARAMS][32];
    char value[KW_MAX_PARAMS][KW_VALUE];
    int has_value[KW_MAX_PARAMS];
} abq_keyword;

int abq_next_line(abq_file *f, const char **b, const char **e);
int abq_blank(char c);
/* The next comma-separated field of [*p, e), trimmed: 0 when none is left. A trailing comma
 * ends the fields (it continues the line). */
int abq_next_field(const char **p, const char *e, const char **fb, const char **fe);
int abq_ends_with_comma(const char *b, const char *e);
/* "cm_mesh_read: FILE:LINE: message", CM_ERR_FORMAT. */
cm_status abq_err(abq_reader *r, const abq_file *f, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
int abq_parse_coord(const char *b, const char *e, double *v);
const char *abq_show(const char *b, const char *e, char *buf, size_t cap);
void abq_upper(char *dst, size_t cap, const char *b, const char *e);
cm_status abq_parse_keyword(abq_reader *r, abq_file *f, const char *b, const char *e, abq_keyword *kw);
/* A parameter's value ("" without one), NULL when absent. */
const char *abq_param(const abq_keyword *kw, const char *name);
char *abq_dup(const char *s);
void *abq_grow(void *a, size_t n, size_t size);
cm_status abq_get_set(abq_reader *r, abq_file *f, int part, int kind, const char *name, int *index);
cm_status abq_copy_set(abq_reader *r, abq_file *f, int to, int from, int64_t inst, int face);

/* After the last line: instances placed, ids resolved, groups made; the origin hung. */
cm_status abq_build(abq_reader *r, const char *path);
void abq_reader_free(abq_reader *r);
void abq_record_free(void *record);

#endif
