/*
** sdnotify.h: plcrt tells the service manager (systemd, Type=notify) that
** it is ready and, while the scan runs, that it is alive. The protocol is
** one AF_UNIX datagram per message to the socket named in $NOTIFY_SOCKET
** ("READY=1", "WATCHDOG=1", "STOPPING=1"; '@' starts an abstract name), a
** few lines written here rather than a link to libsystemd: plcrt then runs
** the same with or without systemd and needs no further library.
**
** The one idea: the housekeeping thread calls sdnotify_tick each time it
** wakes, with the scan's cycle counter. READY=1 goes once the first cycle
** has run; WATCHDOG=1 goes at half the watchdog time ($WATCHDOG_USEC, for
** this process per $WATCHDOG_PID), and only when the counter moved since
** the last one: a stalled scan stops the pings and the service manager
** restarts plcrt. Nothing here is called from the scan thread.
*/
#ifndef SDNOTIFY_H
#define SDNOTIFY_H

#include <stdint.h>
#include <sys/socket.h>
#include <sys/un.h>

typedef struct sdnotify {
    int fd;                   /* -1: no service manager listens */
    struct sockaddr_un addr;
    socklen_t len;
    uint64_t watchdog_ns;     /* 0: no watchdog asked */
    uint64_t last_ping_ns, last_cycles;
    int ready;
} sdnotify;

/* From the environment; never fails (no $NOTIFY_SOCKET: every call is a no-op). */
void sdnotify_open(sdnotify *n);
/* Housekeeping: READY=1 after the first cycle, WATCHDOG=1 while cycles move. */
void sdnotify_tick(sdnotify *n, uint64_t now_ns, uint64_t cycles);
/* STOPPING=1, then the socket is closed. */
void sdnotify_close(sdnotify *n);
/* One message (e.g. "STATUS=..."); 0 if sent or nobody listens. */
int sdnotify_send(sdnotify *n, const char *msg);

#endif
