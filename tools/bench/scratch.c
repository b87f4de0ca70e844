/* Scratch files and ports of the bench's rig sections (bench.h). */
#include "tools/bench/bench.h"

#include <arpa/inet.h>
#include <limits.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <unistd.h>

#include "render/base/file.h"

int lrb_free_port(int sock_type)
{
    int fd = socket(AF_INET, sock_type, 0);
    struct sockaddr_in a = {.sin_family = AF_INET};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t al = sizeof a;
    int port = -1;
    if (fd >= 0 && bind(fd, (struct sockaddr *)&a, sizeof a) == 0 &&
        getsockname(fd, (struct sockaddr *)&a, &al) == 0)
        port = ntohs(a.sin_port);
    if (fd >= 0)
        close(fd);
    return port;
}

int lrb_write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fputs(text, f);
    return fclose(f) != 0;
}

char *lrb_read_rig_file(const char *configs, const char *name)
{
    char src[PATH_MAX + 64];
    snprintf(src, sizeof src, "%s/rig/%s", configs, name);
    char *text = NULL;
    size_t n = 0;
    lr_err e = {0};
    return lr_file_read(src, 1 << 16, &text, &n, &e) ? NULL : text;
}
