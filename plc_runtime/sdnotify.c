/* sdnotify.c: the service manager's notify protocol (sdnotify.h). */
#include "sdnotify.h"

#include <errno.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "log.h"

void sdnotify_open(sdnotify *n) {
    memset(n, 0, sizeof *n);
    n->fd = -1;
    const char *path = getenv("NOTIFY_SOCKET");
    if (!path || !*path) return;
    size_t l = strlen(path);
    if ((path[0] != '/' && path[0] != '@') || l >= sizeof n->addr.sun_path) {
        plc_log(LOG_WARN, "NOTIFY_SOCKET '%s': not a socket path: the service manager is not told", path);
        return;
    }
    n->addr.sun_family = AF_UNIX;
    memcpy(n->addr.sun_path, path, l);
    if (path[0] == '@') n->addr.sun_path[0] = 0;   /* abstract name */
    n->len = (socklen_t)(offsetof(struct sockaddr_un, sun_path) + l);
    n->fd = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (n->fd < 0) {
        plc_log(LOG_WARN, "NOTIFY_SOCKET: socket: %s", strerror(errno));
        return;
    }
    const char *usec = getenv("WATCHDOG_USEC"), *pid = getenv("WATCHDOG_PID");
    if (usec && (!pid || strtol(pid, NULL, 10) == (long)getpid())) {
        char *end;
        unsigned long long us = strtoull(usec, &end, 10);
        if (*end || !us) plc_log(LOG_WARN, "WATCHDOG_USEC '%s': not a time: no watchdog pings", usec);
        else n->watchdog_ns = us * 1000u;
    }
    /* a child started by plcrt must not talk for it */
    unsetenv("NOTIFY_SOCKET");
    unsetenv("WATCHDOG_USEC");
    unsetenv("WATCHDOG_PID");
}

int sdnotify_send(sdnotify *n, const char *msg) {
    if (n->fd < 0) return 0;
    if (sendto(n->fd, msg, strlen(msg), MSG_NOSIGNAL, (struct sockaddr *)&n->addr, n->len) < 0) {
        plc_log(LOG_WARN, "NOTIFY_SOCKET: %s: %s", msg, strerror(errno));
        return -1;
    }
    return 0;
}

void sdnotify_tick(sdnotify *n, uint64_t now_ns, uint64_t cycles) {
    if (n->fd < 0 || !cycles) return;
    if (!n->ready) {
        n->ready = 1;
        sdnotify_send(n, "READY=1\nSTATUS=scan running");
        n->last_ping_ns = now_ns;
        n->last_cycles = cycles;
        return;
    }
    if (n->watchdog_ns && cycles != n->last_cycles && now_ns - n->last_ping_ns >= n->watchdog_ns / 2) {
        sdnotify_send(n, "WATCHDOG=1");
        n->last_ping_ns = now_ns;
        n->last_cycles = cycles;
    }
}

void sdnotify_close(sdnotify *n) {
    if (n->fd < 0) return;
    sdnotify_send(n, "STOPPING=1");
    close(n->fd);
    n->fd = -1;
}
