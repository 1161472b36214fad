/* Nastran bulk data (not public): the line and field splitter that the reader and the
 * write-back share, Nastran's real numbers both ways, and the record a read deck keeps.
 *
 * A card is a first line and its continuations. A line is free field when its text before
 * any '$' holds a comma, else fixed: small field (10 fields of 8 columns) or large field
 * (8, 4 x 16, 8 columns) when the card name ends in '*' or a continuation line starts with
 * '*'. Fixed lines honour tabs (a tab moves to the next multiple of 8 columns). Field 1 of a
 * continuation and the last field of every line (the continuation marker) carry no data; a
 * small line holds 8 data fields, a large one 4, so that a card's data fields are numbered
 * as in the small-field form whatever lines hold them. */
#ifndef CADMORPH_MESH_IO_NASTRAN_INTERNAL_H
#define CADMORPH_MESH_IO_NASTRAN_INTERNAL_H

#include "cadmorph/mesh.h"

#include <stddef.h>

enum { NAS_SMALL = 0, NAS_LARGE = 1, NAS_FREE = 2 };

/* A data field: bytes [b, e) of the buffer (spaces and tabs included; b == e for a field the
 * line does not reach), the line it is on (an index into the card's lines) and its width in
 * columns (8 or 16; 16 for free field, whose fields have no columns). */
typedef struct nas_field {
    size_t b, e;
    int line;
    int width;
    int col; /* fixed field: its first column (tabs expanded) */
    int pad; /* free field: not on the line (after its last comma) */
} nas_field;

typedef struct nas_line {
    size_t b, e;   /* text without the line end */
    size_t next;   /* the start of the next line */
    int kind;      /* NAS_SMALL, NAS_LARGE, NAS_FREE */
    int slots;     /* data fields it holds: 8, or 4 for a large line (fixed or free) */
    int tabs;      /* a fixed line with tabs */
    long number;   /* line number in the file */
} nas_line;

/* One card: its name (upper case, without '*', at most 8 characters) and data fields. The
 * arrays grow and are reused from card to card; nas_card_free releases them. */
typedef struct nas_card {
    char name[9];
    size_t n_fields, cap_fields;
    nas_field *f;
    size_t n_lines, cap_lines;
    nas_line *lines; /* the card's lines (comment lines between them are skipped) */
    int too_many;    /* a free line with more fields than its kind holds */
} nas_card;

void nas_card_free(nas_card *c);

/* The line at pos of data[0, size): its text range, next start, kind as a first line or as
 * a continuation. */
void nas_line_at(const char *data, size_t size, size_t pos, nas_line *l);
/* Whether a line is blank or a comment ('$' as its first non-blank character). */
int nas_line_is_comment(const char *data, const nas_line *l);
/* Whether line l continues the card before it. */
int nas_line_is_continuation(const char *data, const nas_line *l);
/* Splits the card that starts at pos (a line that is neither a comment nor a continuation)
 * and returns where the next card starts. line: the line number of pos; *line receives the
 * number of the next card's line. Out of memory: returns (size_t)-1. */
size_t nas_card_split(const char *data, size_t size, size_t pos, long *line, nas_card *c);

/* Field i's text without surrounding blanks (tabs and spaces); *n its length. A field the card
 * does not have is blank. */
const char *nas_field_text(const char *data, const nas_card *c, size_t i, size_t *n);
int nas_field_blank(const char *data, const nas_card *c, size_t i);

/* Nastran's real forms: "1.5", "-.5", "1.5E-3", "1.5-3", "1.+2", "1.5D-3"; integers are
 * accepted too (gmsh writes them). Returns 0 and *v (finite), or -1. */
int nas_parse_real(const char *s, size_t n, double *v);
/* An integer of at most 18 digits: 0 and *v, or -1. */
int nas_parse_int(const char *s, size_t n, int64_t *v);
/* The significant digits of a real's text (leading zeros of the mantissa not counted; a zero
 * counts its digits): the precision the deck gave the value. */
int nas_text_digits(const char *s, size_t n);
/* v in Nastran's shortest form with `digits` significant digits (a decimal point always;
 * "1.5-3" rather than "1.5E-3"); writes out (cap >= 32) and returns the length. */
int nas_format_digits(char *out, size_t cap, double v, int digits);
/* The most precise text of v that fits in width characters and has at least min_digits
 * significant digits (the shortest that reads back as v when one fits). Returns its length,
 * or 0 when no text of min_digits fits. */
int nas_format_fit(char *out, size_t cap, double v, int width, int min_digits);

/* A coordinate system: CORD2R/C/S after resolution: origin and axes in the basic system. */
typedef struct nas_coord {
    int64_t id;
    char type;   /* 'R', 'C', 'S' */
    int form;    /* 2: CORD2x (points), 1: CORD1x (grid points: not supported) */
    int64_t rid; /* the system A, B, C are given in */
    double abc[9];
    double o[3], e[3][3];
    int state;   /* 0 unresolved, 1 resolving, 2 resolved */
    size_t file;
    long line;
} nas_coord;

/* Local coordinates in system c to basic, and back. */
void nas_coord_to_basic(const nas_coord *c, const double local[3], double basic[3]);
void nas_coord_from_basic(const nas_coord *c, const double basic[3], double local[3]);

/* What a deck read keeps for writing back: the systems of the GRIDs that have one, and the
 * coordinates as read (a node that did not move keeps all its bytes). */
typedef struct nas_record {
    size_t n_coords;
    nas_coord *coords;  /* resolved; a span's aux is 2 (1 + the index of its GRID's system, or 0
                           for the basic system) + 1 when the file's lines end in CR LF */
    double *xyz;        /* #nodes x 3, basic, as read */
} nas_record;

void nas_record_free(void *record);

#endif
