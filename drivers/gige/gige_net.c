/* gige_net.c - the GigE Vision output's own network work (gige_net.h). */
#include "drivers/gige/gige_net.h"

#include <arpa/inet.h>
#include <dirent.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

int nc__gige_probe_open(const char *addr)
{
    struct sockaddr_in sa = {.sin_family = AF_INET, .sin_port = htons(3956)};
    if (inet_pton(AF_INET, addr, &sa.sin_addr) != 1)
        return -1;
    int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    if (fd >= 0 && connect(fd, (struct sockaddr *)&sa, sizeof sa) < 0) {
        close(fd);
        fd = -1;
    }
    return fd;
}

void nc__gige_probe(int fd)
{
    static uint16_t id;
    uint8_t buf[64];
    while (recv(fd, buf, sizeof buf, 0) > 0) /* earlier answers */
        ;
    if (++id == 0)
        id = 1;
    /* GVCP: key 0x42, flags (an answer wanted), READREG_CMD 0x0080, 4 bytes
     * of data, the request id; then the register's address (0: version). */
    const uint8_t cmd[12] = {0x42, 0x01, 0x00, 0x80, 0x00, 0x04, (uint8_t)(id >> 8), (uint8_t)id, 0, 0, 0, 0};
    (void)!send(fd, cmd, sizeof cmd, 0);
}

static int is_discovery(int fd)
{
    struct sockaddr_in sa;
    socklen_t len = sizeof sa;
    int type = 0;
    socklen_t tlen = sizeof type;
    return getsockopt(fd, SOL_SOCKET, SO_TYPE, &type, &tlen) == 0 && type == SOCK_DGRAM &&
           getsockname(fd, (struct sockaddr *)&sa, &len) == 0 && sa.sin_family == AF_INET &&
           sa.sin_addr.s_addr == htonl(INADDR_BROADCAST) && sa.sin_port == htons(3956);
}

int nc__gige_discovery_fds(int *fds, int max)
{
    DIR *d = opendir("/proc/self/fd");
    int n = 0;
    if (!d)
        return 0;
    for (struct dirent *e; (e = readdir(d)) && n < max;) {
        char *end;
        long fd = strtol(e->d_name, &end, 10);
        if (*end == 0 && fd != dirfd(d) && is_discovery((int)fd))
            fds[n++] = (int)fd;
    }
    closedir(d);
    return n;
}

void nc__gige_quiet_discovery(const int *before, int nbefore)
{
    int fds[16], n = nc__gige_discovery_fds(fds, 16);
    for (int i = 0; i < n; i++) {
        int old = 0;
        for (int j = 0; j < nbefore; j++)
            old |= fds[i] == before[j];
        /* Non-blocking, as GLib's sockets are: the device reads each of its
         * sockets whenever one has a message. */
        int quiet = old ? -1 : socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
        if (quiet >= 0) { /* the device keeps polling fds[i]: now a socket nothing reaches */
            dup3(quiet, fds[i], O_CLOEXEC);
            close(quiet);
        }
    }
}
