/* A purpose-built XML scanner for VTK XML files: elements, attributes and the first non-blank
 * text directly inside each element. No DTDs or namespaces; CDATA is not used by VTK writers. */
#include "vtk_internal.h"

#include <stdlib.h>
#include <string.h>

static int is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

static int is_name_char(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == ':' || c == '-' || c == '.';
}

long cm_xml_line(const cm_xml *x, size_t pos)
{
    long line = 1;
    if (pos > x->size) pos = x->size;
    for (const char *p = x->data, *e = x->data + pos; (p = memchr(p, '\n', (size_t)(e - p))); ++p)
        ++line;
    return line;
}

static cm_status syntax(cm_context *ctx, const char *path, const cm_xml *x, size_t pos,
                        const char *what)
{
    return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: XML: %s", path, cm_xml_line(x, pos), what);
}

static char *decode_value(const char *s, size_t n)
{
    char *v = malloc(n + 1);
    if (!v) return NULL;
    size_t k = 0;
    for (size_t i = 0; i < n; ++i) {
        static const struct { const char *ent; char c; } ents[] = {
            {"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&apos;", '\''}};
        int done = 0;
        if (s[i] == '&')
            for (size_t e = 0; e < sizeof ents / sizeof *ents && !done; ++e) {
                size_t L = strlen(ents[e].ent);
                if (i + L <= n && !memcmp(s + i, ents[e].ent, L)) {
                    v[k++] = ents[e].c;
                    i += L - 1;
                    done = 1;
                }
            }
        if (!done) v[k++] = s[i];
    }
    v[k] = '\0';
    return v;
}

static int push_elem(cm_xml *x)
{
    if (x->n_elem == x->cap_elem) {
        size_t cap = x->cap_elem ? 2 * x->cap_elem : 64;
        cm_xml_elem *e = realloc(x->elem, cap * sizeof *e);
        if (!e) return 0;
        x->elem = e;
        x->cap_elem = cap;
    }
    ++x->n_elem;
    return 1;
}

static int push_attr(cm_xml *x)
{
    if (x->n_attr == x->cap_attr) {
        size_t cap = x->cap_attr ? 2 * x->cap_attr : 128;
        cm_xml_attr *a = realloc(x->attr, cap * sizeof *a);
        if (!a) return 0;
        x->attr = a;
        x->cap_attr = cap;
    }
    ++x->n_attr;
    return 1;
}

/* Skips "<?...?>", "<!--...-->" and "<!...>" starting at p; returns the position after. */
static size_t skip_special(const char *d, size_t size, size_t p)
{
    const char *end = NULL;
    if (p + 3 < size && d[p + 1] == '!' && d[p + 2] == '-' && d[p + 3] == '-') {
        for (size_t i = p + 4; i + 2 < size; ++i)
            if (d[i] == '-' && d[i + 1] == '-' && d[i + 2] == '>') return i + 3;
        return SIZE_MAX;
    }
    end = memchr(d + p, '>', size - p);
    return end ? (size_t)(end - d) + 1 : SIZE_MAX;
}

cm_status cm_xml_parse(cm_context *ctx, const char *path, const char *data, size_t size, cm_xml *x)
{
    memset(x, 0, sizeof *x);
    x->data = data;
    x->size = size;
    x->appended = SIZE_MAX;
    x->appended_elem = -1;
    int cur = -1; /* open element */
    int depth = 0; /* of cur */
    size_t p = 0;
    cm_status s = CM_OK;
    while (p < size) {
        const char *lt = memchr(data + p, '<', size - p);
        size_t seg_end = lt ? (size_t)(lt - data) : size;
        if (cur >= 0 && !x->elem[cur].has_text) {
            /* The first non-blank text directly inside an element is its content (VTK puts
             * <InformationKey> children after a DataArray's values). */
            size_t q = p;
            while (q < seg_end && is_space(data[q])) ++q;
            if (q < seg_end) {
                x->elem[cur].text_begin = p;
                x->elem[cur].text_end = seg_end;
                x->elem[cur].has_text = 1;
            }
        }
        if (!lt) break;
        p = seg_end;
        if (p + 1 >= size) return syntax(ctx, path, x, p, "file ends inside a tag");
        char c1 = data[p + 1];
        if (c1 == '?' || c1 == '!') {
            size_t q = skip_special(data, size, p);
            if (q == SIZE_MAX) return syntax(ctx, path, x, p, "unterminated comment or declaration");
            p = q;
            continue;
        }
        if (c1 == '/') {
            size_t b = p + 2, e = b;
            while (e < size && is_name_char(data[e])) ++e;
            if (cur < 0) return syntax(ctx, path, x, p, "closing tag without an open element");
            cm_xml_elem *o = &x->elem[cur];
            if (e - b != o->name_len || memcmp(data + b, o->name, o->name_len)) {
                char msg[160];
                snprintf(msg, sizeof msg, "expected </%.*s>, got </%.*s>", (int)(o->name_len > 40 ? 40 : o->name_len),
                         o->name, (int)(e - b > 40 ? 40 : e - b), data + b);
                return syntax(ctx, path, x, p, msg);
            }
            while (e < size && is_space(data[e])) ++e;
            if (e >= size || data[e] != '>') return syntax(ctx, path, x, p, "malformed closing tag");
            cur = o->parent;
            --depth;
            p = e + 1;
            continue;
        }
        /* opening tag */
        size_t b = p + 1, e = b;
        while (e < size && is_name_char(data[e])) ++e;
        if (e == b) return syntax(ctx, path, x, p, "expected an element name after '<'");
        /* VTK files nest 5 or 6 deep; millions of unclosed elements are not a mesh, and each
         * costs memory */
        if (depth >= CM_XML_MAX_DEPTH) {
            char msg[80];
            snprintf(msg, sizeof msg, "elements nested deeper than %d", CM_XML_MAX_DEPTH);
            return syntax(ctx, path, x, p, msg);
        }
        if (!push_elem(x)) return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", path);
        int me = (int)x->n_elem - 1;
        cm_xml_elem *el = &x->elem[me];
        el->name = data + b;
        el->name_len = e - b;
        el->parent = cur;
        el->attr0 = x->n_attr;
        el->n_attr = 0;
        el->pos = p;
        el->text_begin = el->text_end = 0;
        el->has_text = 0;
        size_t q = e;
        int self_closing = 0;
        for (;;) {
            while (q < size && is_space(data[q])) ++q;
            if (q >= size) return syntax(ctx, path, x, p, "file ends inside a tag");
            if (data[q] == '>') {
                ++q;
                break;
            }
            if (data[q] == '/' && q + 1 < size && data[q + 1] == '>') {
                q += 2;
                self_closing = 1;
                break;
            }
            size_t nb = q;
            while (q < size && is_name_char(data[q])) ++q;
            size_t ne = q;
            while (q < size && is_space(data[q])) ++q;
            if (ne == nb || q >= size || data[q] != '=')
                return syntax(ctx, path, x, nb, "malformed attribute (expected name=\"value\")");
            ++q;
            while (q < size && is_space(data[q])) ++q;
            if (q >= size || (data[q] != '"' && data[q] != '\''))
                return syntax(ctx, path, x, nb, "attribute value must be quoted");
            char quote = data[q++];
            const char *ve = memchr(data + q, quote, size - q);
            if (!ve) return syntax(ctx, path, x, nb, "unterminated attribute value");
            if (!push_attr(x)) return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", path);
            cm_xml_attr *a = &x->attr[x->n_attr - 1];
            a->name = data + nb;
            a->name_len = ne - nb;
            a->value = decode_value(data + q, (size_t)(ve - (data + q)));
            if (!a->value) {
                --x->n_attr;
                return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", path);
            }
            el = &x->elem[me];
            ++el->n_attr;
            q = (size_t)(ve - data) + 1;
        }
        el = &x->elem[me];
        el->text_begin = el->text_end = q;
        p = q;
        if (self_closing) continue;
        cur = me;
        ++depth;
        if (el->name_len == 12 && !memcmp(el->name, "AppendedData", 12)) {
            /* Everything after the '_' is data (raw bytes or base64), not XML. */
            while (p < size && is_space(data[p])) ++p;
            if (p >= size || data[p] != '_')
                return syntax(ctx, path, x, p, "expected '_' at the start of <AppendedData>");
            x->appended = p + 1;
            x->appended_elem = me;
            return s;
        }
    }
    if (cur >= 0) {
        const cm_xml_elem *o = &x->elem[cur];
        char msg[120];
        snprintf(msg, sizeof msg, "file ends before </%.*s> (truncated?)",
                 (int)(o->name_len > 40 ? 40 : o->name_len), o->name);
        return syntax(ctx, path, x, size, msg);
    }
    if (x->n_elem == 0) return syntax(ctx, path, x, 0, "no element found");
    return s;
}

void cm_xml_free(cm_xml *x)
{
    for (size_t i = 0; i < x->n_attr; ++i) free(x->attr[i].value);
    free(x->attr);
    free(x->elem);
    memset(x, 0, sizeof *x);
}

const char *cm_xml_get(const cm_xml *x, int elem, const char *name)
{
    if (elem < 0 || (size_t)elem >= x->n_elem) return NULL;
    const cm_xml_elem *e = &x->elem[elem];
    size_t n = strlen(name);
    for (size_t i = e->attr0; i < e->attr0 + e->n_attr; ++i)
        if (x->attr[i].name_len == n && !memcmp(x->attr[i].name, name, n)) return x->attr[i].value;
    return NULL;
}

int cm_xml_is(const cm_xml *x, int elem, const char *name)
{
    size_t n = strlen(name);
    return elem >= 0 && (size_t)elem < x->n_elem && x->elem[elem].name_len == n &&
           !memcmp(x->elem[elem].name, name, n);
}

int cm_xml_child(const cm_xml *x, int parent, const char *name, int after)
{
    for (size_t i = (size_t)(after < 0 ? parent + 1 : after + 1); i < x->n_elem; ++i)
        if (x->elem[i].parent == parent && (!name || cm_xml_is(x, (int)i, name))) return (int)i;
    return -1;
}
