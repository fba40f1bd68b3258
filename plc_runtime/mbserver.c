/* mbserver.c: see mbserver.h. */
#include <errno.h>
#include <modbus.h>
#include <poll.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>
#include "log.h"
#include "mbserver.h"

typedef struct client {
    mb_server *srv;
    int fd, used, done;
    pthread_t th;
} client;

struct mb_server {
    mb_shared *m;
    modbus_t *listen_ctx;
    int lfd, idle_ms, max;
    char bind[64];
    int port;
    pthread_t th;
    pthread_mutex_t lock;          /* guards the client slots */
    _Atomic int stop;
    client *cl;
};

static int send_all(int fd, const uint8_t *p, size_t n)
{
    while (n) {
        ssize_t w = send(fd, p, n, MSG_NOSIGNAL);
        if (w < 0) { if (errno == EINTR) continue; return -1; }
        p += w; n -= (size_t)w;
    }
    return 0;
}

static void *client_thread(void *arg)
{
    client *c = arg;
    mb_server *s = c->srv;
    uint8_t req[MODBUS_TCP_MAX_ADU_LENGTH], rsp[MB_PDU_MAX + 7];
    modbus_t *ctx = modbus_new_tcp(s->bind, s->port);
    if (ctx) {
        modbus_set_socket(ctx, c->fd);
        modbus_set_byte_timeout(ctx, 0, 500000);   /* a half frame: dropped after 0.5 s */
        int hl = modbus_get_header_length(ctx);
        while (!atomic_load(&s->stop)) {
            struct pollfd pf = { c->fd, POLLIN, 0 };
            int r = poll(&pf, 1, s->idle_ms ? s->idle_ms : -1);
            if (r < 0 && errno == EINTR) continue;
            if (r <= 0 || atomic_load(&s->stop)) break;   /* idle too long, or stopping */
            int n = modbus_receive(ctx, req);
            if (n < 0) break;                              /* closed, timeout, bad frame */
            if (n == 0) continue;
            if (n <= hl) break;
            size_t pl = mb_process(s->m, req + hl, (size_t)(n - hl), rsp + 7);
            memcpy(rsp, req, 4);                           /* transaction, protocol */
            rsp[4] = (uint8_t)((pl + 1) >> 8);
            rsp[5] = (uint8_t)(pl + 1);
            rsp[6] = req[6];                               /* unit */
            if (send_all(c->fd, rsp, pl + 7)) break;
        }
        modbus_free(ctx);         /* does not close the socket */
    }
    pthread_mutex_lock(&s->lock);
    close(c->fd);
    c->fd = -1;
    c->done = 1;
    atomic_fetch_sub(&s->m->clients, 1);
    pthread_mutex_unlock(&s->lock);
    return NULL;
}

/* Join finished client threads, freeing their slots. */
static void reap(mb_server *s, int all)
{
    for (int i = 0; i < s->max; i++) {
        client *c = &s->cl[i];
        pthread_mutex_lock(&s->lock);
        int join = c->used && (c->done || all);
        pthread_mutex_unlock(&s->lock);
        if (join) {
            pthread_join(c->th, NULL);
            c->used = c->done = 0;
        }
    }
}

static void *accept_thread(void *arg)
{
    mb_server *s = arg;
    while (!atomic_load(&s->stop)) {
        struct pollfd pf = { s->lfd, POLLIN, 0 };
        int r = poll(&pf, 1, 100);
        reap(s, 0);
        if (r <= 0) continue;
        int fd = accept4(s->lfd, NULL, NULL, SOCK_CLOEXEC);
        if (fd < 0) continue;
        client *slot = NULL;
        for (int i = 0; i < s->max && !slot; i++)
            if (!s->cl[i].used) slot = &s->cl[i];
        if (!slot || fd >= FD_SETSIZE) {
            close(fd);
            atomic_fetch_add(&s->m->refused, 1);
            continue;
        }
        struct timeval tv = { 2, 0 };    /* a client that does not read its replies */
        setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
        *slot = (client){ s, fd, 1, 0, 0 };
        atomic_fetch_add(&s->m->clients, 1);
        if (pthread_create(&slot->th, NULL, client_thread, slot)) {
            close(fd);
            slot->used = 0;
            atomic_fetch_sub(&s->m->clients, 1);
            atomic_fetch_add(&s->m->refused, 1);
        }
    }
    return NULL;
}

mb_server *mb_server_start(const plc_config *c, mb_shared *m, char *err, size_t errlen)
{
    mb_server *s = calloc(1, sizeof *s);
    if (!s || !(s->cl = calloc((size_t)c->mb_max_clients, sizeof *s->cl))) {
        free(s);
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    s->m = m;
    s->max = c->mb_max_clients;
    s->idle_ms = c->mb_idle_timeout * 1000;
    snprintf(s->bind, sizeof s->bind, "%s", c->mb_bind);
    s->port = c->mb_port;
    pthread_mutex_init(&s->lock, NULL);
    s->listen_ctx = modbus_new_tcp(s->bind, s->port);
    if (!s->listen_ctx || (s->lfd = modbus_tcp_listen(s->listen_ctx, 64)) < 0) {
        snprintf(err, errlen, "cannot listen on %s:%d: %s", s->bind, s->port,
                 modbus_strerror(errno));
        if (s->listen_ctx) modbus_free(s->listen_ctx);
        free(s->cl);
        free(s);
        return NULL;
    }
    if (pthread_create(&s->th, NULL, accept_thread, s)) {
        snprintf(err, errlen, "cannot start the Modbus thread");
        close(s->lfd);
        modbus_free(s->listen_ctx);
        free(s->cl);
        free(s);
        return NULL;
    }
    plc_log(LOG_INFO, "modbus: listening on %s:%d (at most %d clients)", s->bind, s->port, s->max);
    return s;
}

void mb_server_stop(mb_server *s)
{
    if (!s) return;
    atomic_store(&s->stop, 1);
    pthread_join(s->th, NULL);
    close(s->lfd);
    /* wake readers; a request being served still gets its reply */
    pthread_mutex_lock(&s->lock);
    for (int i = 0; i < s->max; i++)
        if (s->cl[i].used && s->cl[i].fd >= 0) shutdown(s->cl[i].fd, SHUT_RD);
    pthread_mutex_unlock(&s->lock);
    reap(s, 1);
    modbus_free(s->listen_ctx);
    pthread_mutex_destroy(&s->lock);
    free(s->cl);
    free(s);
}
