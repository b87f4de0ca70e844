/* lamprig tests — scratch directories and files. */
#ifndef LR_TEST_FS_H
#define LR_TEST_FS_H

#include <stddef.h>

/* Creates a fresh directory under $TMPDIR (or /tmp); returns its malloc'd path. Aborts the
 * test binary when it cannot. */
char *lr_test_tmpdir(void);
/* Removes dir and everything below it, then frees the path. */
void lr_test_rmtree(char *dir);
/* "dir/name" in a malloc'd string. */
char *lr_test_path(const char *dir, const char *name);
/* Writes len bytes (len (size_t)-1: strlen(data)) to dir/name, creating subdirectories of name
 * as needed; returns the malloc'd full path. Aborts on failure. */
char *lr_test_write(const char *dir, const char *name, const void *data, size_t len);
/* Writes len bytes (len (size_t)-1: strlen(data)) to path. Aborts on failure. */
void lr_test_put(const char *path, const void *data, size_t len);
/* Reads a whole file; returns malloc'd bytes (NUL-terminated) and sets *len. Aborts on failure. */
unsigned char *lr_test_read(const char *path, size_t *len);
/* Mounts a tmpfs of `kib` KiB on the existing folder dir, read-only when read_only (Linux
 * mount(2); needs root, as the tests run in CI). Returns 0, or -1 (errno set) when it cannot:
 * the caller skips what needs it. */
int lr_test_mount_tmpfs(const char *dir, unsigned kib, int read_only);
/* Undoes lr_test_mount_tmpfs (a lazy unmount). */
void lr_test_umount(const char *dir);

#endif
