/*
** refserver.c: the reference the Modbus benchmark compares plcrt with, the
** smallest multi-client server libmodbus allows: select() over the clients,
** modbus_receive and modbus_reply on a mapping of 8192 holding registers.
** No image, no scan: what it costs is libmodbus's own framing and reply.
** usage: refserver PORT
*/
#include <errno.h>
#include <modbus.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

int main(int argc, char **argv)
{
    if (argc != 2) { fprintf(stderr, "usage: refserver PORT\n"); return 2; }
    modbus_t *ctx = modbus_new_tcp("127.0.0.1", atoi(argv[1]));
    modbus_mapping_t *map = modbus_mapping_new(0, 0, 8192, 0);
    int lfd = ctx && map ? modbus_tcp_listen(ctx, 64) : -1;
    if (lfd < 0) { fprintf(stderr, "refserver: %s\n", modbus_strerror(errno)); return 1; }
    printf("refserver: listening\n");
    fflush(stdout);
    fd_set all;
    FD_ZERO(&all);
    FD_SET(lfd, &all);
    int maxfd = lfd;
    uint8_t q[MODBUS_TCP_MAX_ADU_LENGTH];
    for (;;) {
        fd_set rd = all;
        if (select(maxfd + 1, &rd, NULL, NULL, NULL) < 0) return 1;
        for (int fd = 0; fd <= maxfd; fd++) {
            if (!FD_ISSET(fd, &rd)) continue;
            if (fd == lfd) {
                int c = accept(lfd, NULL, NULL);
                if (c >= 0 && c < FD_SETSIZE) { FD_SET(c, &all); if (c > maxfd) maxfd = c; }
                else if (c >= 0) close(c);
                continue;
            }
            modbus_set_socket(ctx, fd);
            int n = modbus_receive(ctx, q);
            if (n > 0) modbus_reply(ctx, q, n, map);
            else if (n < 0) { close(fd); FD_CLR(fd, &all); }
        }
    }
}
