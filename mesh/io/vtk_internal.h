/* Shared by the VTK readers and writers (.vtu, legacy .vtk; not public): base64, a small
 * XML scanner, VTK scalar types and the conversion of VTK cell arrays into a cm_mesh. */
#ifndef CADMORPH_MESH_VTK_INTERNAL_H
#define CADMORPH_MESH_VTK_INTERNAL_H

#include "text.h"

/* ---- base64 (RFC 4648, standard alphabet) ---- */

/* A decoding stream over text. Padding inside the text is accepted: VTK and meshio encode the
 * header and the data of an array separately and concatenate the two encodings. Whitespace
 * is skipped. */
typedef struct cm_b64 {
    const char *p, *end;
    uint8_t pend[3];
    int npend, ipend;
} cm_b64;

void cm_b64_init(cm_b64 *s, const char *text, const char *end);
/* Decodes exactly n bytes into dst. Returns 0, or -1 for a character outside the alphabet,
 * -2 when the text ends first. */
int cm_b64_read(cm_b64 *s, uint8_t *dst, size_t n);
/* Encoded length of n bytes (with padding). */
size_t cm_b64_encoded_size(size_t n);
/* Encodes n bytes into dst (cm_b64_encoded_size(n) chars, no NUL). */
void cm_b64_encode(const uint8_t *src, size_t n, char *dst);

/* ---- XML: elements, attributes and the text directly inside an element ---- */

typedef struct cm_xml_attr {
    const char *name;
    size_t name_len;
    char *value; /* entities decoded, NUL-terminated, owned */
} cm_xml_attr;

typedef struct cm_xml_elem {
    const char *name;
    size_t name_len;
    int parent;                /* -1 for the root */
    size_t attr0, n_attr;      /* into cm_xml.attr */
    size_t pos;                /* byte offset of '<' */
    size_t text_begin, text_end; /* first non-blank direct text (DataArray contents) */
    int has_text;
} cm_xml_elem;

typedef struct cm_xml {
    const char *data;
    size_t size;
    cm_xml_elem *elem;
    size_t n_elem, cap_elem;
    cm_xml_attr *attr;
    size_t n_attr, cap_attr;
    size_t appended;           /* byte offset after the '_' of <AppendedData>, or SIZE_MAX */
    int appended_elem;         /* element index of <AppendedData>, -1 if none */
} cm_xml;

/* Deepest element nesting accepted. */
#define CM_XML_MAX_DEPTH 64

/* Scans data; stops at the '_' that starts <AppendedData> (what follows is not XML). Elements
 * nested deeper than CM_XML_MAX_DEPTH are a format error. */
cm_status cm_xml_parse(cm_context *ctx, const char *path, const char *data, size_t size, cm_xml *x);
void cm_xml_free(cm_xml *x);
/* Attribute value or NULL. */
const char *cm_xml_get(const cm_xml *x, int elem, const char *name);
/* Next child of parent named name (NULL: any) after child index `after` (-1: from the start);
 * -1 if none. */
int cm_xml_child(const cm_xml *x, int parent, const char *name, int after);
int cm_xml_is(const cm_xml *x, int elem, const char *name);
/* 1-based line of a byte offset. */
long cm_xml_line(const cm_xml *x, size_t pos);

/* ---- VTK scalar types ---- */

typedef enum cm_vtk_scalar {
    CM_VTK_INT8 = 0,
    CM_VTK_UINT8,
    CM_VTK_INT16,
    CM_VTK_UINT16,
    CM_VTK_INT32,
    CM_VTK_UINT32,
    CM_VTK_INT64,
    CM_VTK_UINT64,
    CM_VTK_FLOAT32,
    CM_VTK_FLOAT64,
    CM_VTK_SCALAR_COUNT
} cm_vtk_scalar;

size_t cm_vtk_scalar_size(cm_vtk_scalar t);
int cm_vtk_scalar_is_float(cm_vtk_scalar t);
/* From an XML type name ("Float32", "UInt8", ...); CM_VTK_SCALAR_COUNT if unknown. */
cm_vtk_scalar cm_vtk_scalar_from_xml(const char *name);
/* From a legacy type name ("float", "vtktypeint64", ...); CM_VTK_SCALAR_COUNT if unknown. */
cm_vtk_scalar cm_vtk_scalar_from_legacy(const char *name, size_t len);
/* Reverses the byte order of n values in place. */
void cm_vtk_swap(cm_vtk_scalar t, void *data, size_t n);
/* Converts n little-endian-host values (unaligned allowed). */
void cm_vtk_to_double(cm_vtk_scalar t, const void *src, size_t n, double *dst);
/* Returns the index of the first value that is not an integer in int64 range, or n. */
size_t cm_vtk_to_int64(cm_vtk_scalar t, const void *src, size_t n, int64_t *dst);

/* ---- cells ---- */

/* VTK cell arrays with begin offsets: cell c has conn[off[c] .. off[c+1]). Polyhedra take
 * their face stream from faces[face_off[c] .. face_off[c+1]) when faces is given (XML),
 * otherwise from conn (legacy). where: message prefix ("path" or "path:12"). */
typedef struct cm_vtk_cells {
    size_t n;
    const int64_t *type;
    const int64_t *off;
    const int64_t *conn;
    size_t n_conn;
    const int64_t *faces;
    const int64_t *face_off;
    size_t n_faces;
} cm_vtk_cells;

cm_status cm_vtk_cells_to_mesh(cm_context *ctx, const cm_vtk_cells *cells, const char *where,
                               cm_mesh *mesh);
/* Fails with a message naming where and the node if a coordinate is not finite. */
cm_status cm_vtk_check_points(cm_context *ctx, const cm_mesh *mesh, const char *where);
/* The distinct nodes of a polyhedron face stream in order of first use; returns the count.
 * ids must hold as many entries as the stream. */
size_t cm_vtk_polyhedron_points(const int64_t *stream, int64_t *ids);

/* ---- .vtu DataArray decoding ---- */

typedef struct cm_vtu_decoder {
    cm_context *ctx;
    const char *path;
    const cm_xml *x;
    int hdr64;       /* header_type="UInt64" */
    int compressed;  /* compressor="vtkZLibDataCompressor" */
    int app_base64;  /* <AppendedData encoding="base64"> */
    size_t app_end;  /* end of the appended data */
} cm_vtu_decoder;

typedef struct cm_vtu_array {
    const char *name;     /* Name attribute or NULL */
    cm_vtk_scalar type;   /* ascii integers come back as INT64 */
    int components;
    int unsupported_type; /* set with CM_ERR_UNSUPPORTED for String/Bit arrays */
    size_t count;         /* values (tuples x components) */
    uint8_t *bytes;       /* host byte order, owned */
} cm_vtu_array;

/* Decodes DataArray elem into a. An array that declares (binary header) or holds (ascii) more
 * than max_values values (tuples x components; SIZE_MAX: no bound) is refused before it is
 * allocated or inflated. */
cm_status cm_vtu_array_decode(const cm_vtu_decoder *d, int elem, size_t max_values, cm_vtu_array *a);
void cm_vtu_array_free(cm_vtu_array *a);

#endif
