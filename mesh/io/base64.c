/* Base64 for VTK XML binary data: a streaming decoder that accepts padding between
 * separately encoded chunks (header, then data) and an encoder for the writer. */
#include "vtk_internal.h"

#include <string.h>

static const char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/* 0..63: value; 64: '='; 65: whitespace; 66: invalid. */
static const uint8_t table[256] = {
    66, 66, 66, 66, 66, 66, 66, 66, 66, 65, 65, 65, 65, 65, 66, 66,
    66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66,
    65, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 62, 66, 66, 66, 63,
    52, 53, 54, 55, 56, 57, 58, 59, 60, 61, 66, 66, 66, 64, 66, 66,
    66,  0,  1,  2,  3,  4,  5,  6,  7,  8,  9, 10, 11, 12, 13, 14,
    15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 66, 66, 66, 66, 66,
    66, 26, 27, 28, 29, 30, 31, 32, 33, 34, 35, 36, 37, 38, 39, 40,
    41, 42, 43, 44, 45, 46, 47, 48, 49, 50, 51, 66, 66, 66, 66, 66,
    66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66,
    66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66,
    66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66,
    66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66,
    66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66,
    66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66,
    66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66,
    66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66, 66,
};

void cm_b64_init(cm_b64 *s, const char *text, const char *end)
{
    s->p = text;
    s->end = end;
    s->npend = s->ipend = 0;
}

/* Decodes the next quad into out; returns bytes produced (0..3), -1 bad char, -2 end. */
static int next_quad(cm_b64 *s, uint8_t out[3])
{
    uint8_t q[4];
    int k = 0;
    const char *p = s->p;
    if (s->end - p >= 4 && table[(unsigned char)p[0]] < 64 && table[(unsigned char)p[1]] < 64 &&
        table[(unsigned char)p[2]] < 64 && table[(unsigned char)p[3]] < 64) {
        for (; k < 4; ++k) q[k] = table[(unsigned char)p[k]];
        p += 4;
    } else {
        while (k < 4) {
            if (p >= s->end) {
                s->p = p;
                return -2;
            }
            uint8_t v = table[(unsigned char)*p++];
            if (v == 65) continue;
            if (v == 66) {
                s->p = p - 1;
                return -1;
            }
            q[k++] = v;
        }
    }
    s->p = p;
    /* '=' only in the last two places, and "x=y?" is not a valid quad. */
    if (q[0] == 64 || q[1] == 64 || (q[2] == 64 && q[3] != 64)) return -1;
    out[0] = (uint8_t)(q[0] << 2 | q[1] >> 4);
    if (q[2] == 64) return 1;
    out[1] = (uint8_t)((q[1] & 15) << 4 | q[2] >> 2);
    if (q[3] == 64) return 2;
    out[2] = (uint8_t)((q[2] & 3) << 6 | q[3]);
    return 3;
}

int cm_b64_read(cm_b64 *s, uint8_t *dst, size_t n)
{
    while (n > 0 && s->ipend < s->npend) {
        *dst++ = s->pend[s->ipend++];
        --n;
    }
    while (n > 0) {
        uint8_t out[3];
        int r = next_quad(s, out);
        if (r < 0) return r;
        if ((size_t)r <= n) {
            memcpy(dst, out, (size_t)r);
            dst += r;
            n -= (size_t)r;
        } else {
            memcpy(dst, out, n);
            memcpy(s->pend, out, (size_t)r);
            s->npend = r;
            s->ipend = (int)n;
            n = 0;
        }
    }
    return 0;
}

size_t cm_b64_encoded_size(size_t n) { return (n + 2) / 3 * 4; }

void cm_b64_encode(const uint8_t *src, size_t n, char *dst)
{
    size_t i = 0;
    for (; i + 3 <= n; i += 3) {
        uint32_t v = (uint32_t)src[i] << 16 | (uint32_t)src[i + 1] << 8 | src[i + 2];
        *dst++ = alphabet[v >> 18];
        *dst++ = alphabet[(v >> 12) & 63];
        *dst++ = alphabet[(v >> 6) & 63];
        *dst++ = alphabet[v & 63];
    }
    if (i < n) {
        uint32_t v = (uint32_t)src[i] << 16 | (i + 1 < n ? (uint32_t)src[i + 1] << 8 : 0);
        *dst++ = alphabet[v >> 18];
        *dst++ = alphabet[(v >> 12) & 63];
        *dst++ = i + 1 < n ? alphabet[(v >> 6) & 63] : '=';
        *dst++ = '=';
    }
}
