/* lamprig — a checked binary cache file: what translucent radiosity's F and S
 * (render/transrad/cache.c) and the objects' light rows (render/bounce/objlight_cache.c) keep
 * on disk between starts.
 *
 * Layout: an 8-byte magic, the caller's header words (uint64, native order), a 64-bit FNV-1a
 * hash (render/reference/hash.c) of the header words and the payload, then the payload, the
 * caller's pieces one after the other. Written whole through render/base/atomic_file (a temp
 * file renamed over), so a reader sees the old file or the new one. A read checks the magic,
 * that the file holds the header, and the hash; the caller then checks its words (key,
 * sizes) and values. A file that
 * fails is treated as absent: a rebuild, never a wrong answer. */
#ifndef LR_CACHE_FILE_H
#define LR_CACHE_FILE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "render/base/err.h"

typedef struct lr_cache_piece {
    const void *p;
    size_t bytes;
} lr_cache_piece;

/* Writes path: magic (8 bytes), words[0..nwords), the payload hash, the pieces. `what` names
 * the cache in errors (LR_ENOMEM, LR_EIO from the atomic write). */
int lr_cache_file_write(const char *path, const char magic[8], const uint64_t *words, int nwords,
                        const lr_cache_piece *pieces, int npieces, const char *what, lr_err *e);

/* Reads path and checks it as above. On true *data is the whole file (the caller frees it),
 * words[0..nwords) its header words, *payload and *payload_len what follows the hash. False
 * (nothing to free) when the file is missing, short, of another magic or its hash differs. */
bool lr_cache_file_read(const char *path, const char magic[8], uint64_t *words, int nwords,
                        char **data, const unsigned char **payload, size_t *payload_len);

#endif
