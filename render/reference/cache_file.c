/* A checked binary cache file (render/reference/cache_file.h). */
#include "render/reference/cache_file.h"

#include <stdlib.h>
#include <string.h>

#include "render/base/atomic_file.h"
#include "render/base/file.h"
#include "render/reference/reference.h"

static size_t head_bytes(int nwords) { return 8 + ((size_t)nwords + 1) * sizeof(uint64_t); }

/* The hash covers the header words and the payload: a flipped byte anywhere but the magic
 * (checked as it is) reads as absent. */
static uint64_t content_hash(const unsigned char *words, size_t word_bytes,
                             const unsigned char *payload, size_t payload_bytes)
{
    lr_ref_hash h;
    lr_ref_hash_init(&h);
    lr_ref_hash_bytes(&h, words, word_bytes);
    lr_ref_hash_bytes(&h, payload, payload_bytes);
    return h.h;
}

int lr_cache_file_write(const char *path, const char magic[8], const uint64_t *words, int nwords,
                        const lr_cache_piece *pieces, int npieces, const char *what, lr_err *e)
{
    size_t head = head_bytes(nwords), len = head;
    for (int i = 0; i < npieces; i++)
        len += pieces[i].bytes;
    unsigned char *buf = malloc(len);
    if (!buf)
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory (%zu bytes)", what, len);
    size_t off = head;
    for (int i = 0; i < npieces; i++) {
        if (pieces[i].bytes)
            memcpy(buf + off, pieces[i].p, pieces[i].bytes);
        off += pieces[i].bytes;
    }
    memcpy(buf, magic, 8);
    size_t wb = (size_t)nwords * sizeof *words;
    if (wb)
        memcpy(buf + 8, words, wb);
    uint64_t hash = content_hash(buf + 8, wb, buf + head, len - head);
    memcpy(buf + head - sizeof hash, &hash, sizeof hash);
    int rc = lr_atomic_write(path, buf, len, e);
    free(buf);
    return rc;
}

bool lr_cache_file_read(const char *path, const char magic[8], uint64_t *words, int nwords,
                        char **data, const unsigned char **payload, size_t *payload_len)
{
    char *d = NULL;
    size_t len = 0;
    lr_err e = {0};
    if (lr_file_read(path, LR_FILE_MAX_CACHE, &d, &len, &e))
        return false;
    size_t head = head_bytes(nwords);
    uint64_t hash;
    bool ok = len >= head && !memcmp(d, magic, 8);
    if (ok) {
        if (nwords > 0)
            memcpy(words, d + 8, (size_t)nwords * sizeof *words);
        memcpy(&hash, d + head - sizeof hash, sizeof hash);
        const unsigned char *u = (const unsigned char *)d;
        ok = content_hash(u + 8, (size_t)nwords * sizeof *words, u + head, len - head) == hash;
    }
    if (!ok) {
        free(d);
        return false;
    }
    *data = d;
    *payload = (const unsigned char *)d + head;
    *payload_len = len - head;
    return true;
}
