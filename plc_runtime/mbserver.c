/* mbserver.c: see mbserver.h. */
#include <errno.h>
#include <fcntl.h>
#include <modbus.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>
#include "log.h"
#include "mbserver.h"
#include "scan.h"

#define MS             1000000ull
#define FRAME_NS       (500 * MS)    /* a frame's last byte after its first */
#define SEND_NS        (2000 * MS)   /* a reply the client does not take */
#define WRITES_NS      (MS / 4)      /* while writes wait for the scan */
#define MBAP           7             /* transaction, protocol, length, unit */
#define ADU_MAX        260           /* Modbus TCP's largest frame */

typedef struct client {
    int fd;
    uint8_t in[2 * ADU_MAX];         /* bytes received, not yet served */
    size_t nin;
    uint8_t out[ADU_MAX];            /* a reply the socket did not take yet */
    size_t nout;
    uint64_t frame_ns;               /* when the first byte of in[] came */
    uint64_t last_ns;                /* connected, or its last request served */
    uint64_t last_seq;               /* the same as a rank: no two alike */
    uint64_t out_ns;                 /* when out[] began to wait */
} client;

struct mb_server {
    mb_shared *m;
    modbus_t *listen_ctx;
    int lfd, wake, max, n;
    char bind[64];
    int port;
    uint64_t idle_ns, listen_pause, seq;
    pthread_t th;
    int running;                     /* the thread started (mb_server_run) */
    _Atomic int stop;
    client *cl;                      /* n in use, packed */
    struct pollfd *pf;               /* wake, listener, clients */
};

static void drop(mb_server *s, int i, _Atomic uint64_t *why)
{
    close(s->cl[i].fd);
    s->cl[i] = s->cl[--s->n];
    if (why) atomic_fetch_add(why, 1);
    atomic_fetch_sub(&s->m->clients, 1);
}

/* Send what the socket takes; 0, or -1 when the connection is lost. */
static int flush_out(client *c, uint64_t now)
{
    size_t off = 0;
    while (off < c->nout) {
        ssize_t w = send(c->fd, c->out + off, c->nout - off, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (w < 0) {
            if (errno == EINTR) continue;
            if (errno == EAGAIN || errno == EWOULDBLOCK) break;
            return -1;
        }
        off += (size_t)w;
    }
    if (off) {
        memmove(c->out, c->out + off, c->nout - off);
        c->nout -= off;
        c->out_ns = now;
    }
    return 0;
}

/* Serve the whole frames in c->in, in order, while replies go out.
** 0, or -1 when the connection must close (a protocol id other than 0, a
** length no Modbus TCP frame has). */
static int serve_frames(mb_server *s, client *c, uint64_t now)
{
    size_t at = 0;
    while (!c->nout && c->nin - at >= MBAP) {
        const uint8_t *f = c->in + at;
        unsigned proto = (unsigned)f[2] << 8 | f[3], len = (unsigned)f[4] << 8 | f[5];
        if (proto != 0 || len < 2 || len > ADU_MAX - 6) return -1;
        if (c->nin - at < 6 + len) break;
        /* the length field says where the next request begins, whatever the
        ** function code: an unknown one is answered (exception 01) in step */
        pthread_mutex_lock(&s->m->serve);
        size_t pl = mb_process(s->m, f + MBAP, len - 1, c->out + MBAP);
        pthread_mutex_unlock(&s->m->serve);
        memcpy(c->out, f, 4);                         /* transaction, protocol */
        c->out[4] = (uint8_t)((pl + 1) >> 8);
        c->out[5] = (uint8_t)(pl + 1);
        c->out[6] = f[6];                             /* unit */
        c->nout = pl + MBAP;
        c->out_ns = now;
        c->last_ns = now;
        c->last_seq = ++s->seq;
        at += 6 + len;
        if (flush_out(c, now)) return -1;
    }
    if (at) {
        memmove(c->in, c->in + at, c->nin - at);
        c->nin -= at;
        c->frame_ns = now;        /* what is left began to come just now */
    }
    return 0;
}

/* Read what came; 0, or -1 when the connection closed or must close. */
static int receive(mb_server *s, client *c, uint64_t now)
{
    for (;;) {
        if (c->nin == sizeof c->in) break;          /* served as replies go out */
        ssize_t r = recv(c->fd, c->in + c->nin, sizeof c->in - c->nin, MSG_DONTWAIT);
        if (r < 0) {
            if (errno == EINTR) continue;
            if (errno == EAGAIN || errno == EWOULDBLOCK) break;
            return -1;
        }
        if (r == 0) return -1;
        if (!c->nin) c->frame_ns = now;
        c->nin += (size_t)r;
        if (serve_frames(s, c, now)) return -1;
    }
    return 0;
}

static void admit(mb_server *s, uint64_t now)
{
    for (;;) {
        int fd = accept4(s->lfd, NULL, NULL, SOCK_CLOEXEC | SOCK_NONBLOCK);
        if (fd < 0) {
            if (errno == EINTR) continue;
            if (errno != EAGAIN && errno != EWOULDBLOCK) {     /* out of descriptors */
                atomic_fetch_add(&s->m->refused, 1);
                s->listen_pause = now + 100 * MS;
            }
            return;
        }
        /* a reply goes out at once: a client with requests in flight
        ** (pipelined) would otherwise wait on its delayed ACK, ~40 ms */
        int one = 1;
        setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
        if (s->n == s->max) {                 /* the longest idle gives way */
            int old = 0;
            for (int i = 1; i < s->n; i++)
                if (s->cl[i].last_seq < s->cl[old].last_seq) old = i;
            drop(s, old, &s->m->evicted);
        }
        s->cl[s->n++] = (client){ .fd = fd, .last_ns = now, .last_seq = ++s->seq };
        atomic_fetch_add(&s->m->clients, 1);
    }
}

/* Close clients past a deadline; the nearest deadline still ahead. */
static uint64_t expire(mb_server *s, uint64_t now)
{
    uint64_t next = now + 100 * MS;
    for (int i = 0; i < s->n; i++) {
        client *c = &s->cl[i];
        uint64_t d;
        _Atomic uint64_t *why = &s->m->dropped;
        if (c->nout) d = c->out_ns + SEND_NS;
        else if (c->nin) d = c->frame_ns + FRAME_NS;
        else if (s->idle_ns) { d = c->last_ns + s->idle_ns; why = &s->m->evicted; }
        else continue;
        if (d <= now) {
            drop(s, i--, why);
            continue;
        }
        if (d < next) next = d;
    }
    return next;
}

static void *server_thread(void *arg)
{
    mb_server *s = arg;
    while (!atomic_load(&s->stop)) {
        uint64_t now = scan_now_ns();
        uint64_t next = expire(s, now);
        uint64_t wait = next - now;
        pthread_mutex_lock(&s->m->serve);
        int pending = mb_flush(s->m);
        pthread_mutex_unlock(&s->m->serve);
        if (pending && wait > WRITES_NS) wait = WRITES_NS;        /* hand writes over soon */
        struct timespec to = { (time_t)(wait / 1000000000u), (long)(wait % 1000000000u) };
        int listening = now >= s->listen_pause;
        s->pf[0] = (struct pollfd){ s->wake, POLLIN, 0 };
        s->pf[1] = (struct pollfd){ listening ? s->lfd : -1, POLLIN, 0 };
        for (int i = 0; i < s->n; i++) {
            client *c = &s->cl[i];
            short ev = c->nout ? POLLOUT : c->nin == sizeof c->in ? 0 : POLLIN;
            s->pf[2 + i] = (struct pollfd){ c->fd, ev, 0 };
        }
        int nc = s->n;
        if (ppoll(s->pf, (nfds_t)(2 + nc), &to, NULL) <= 0) continue;
        now = scan_now_ns();
        /* clients first (the array is packed: walk it from the end, so that
        ** dropping one moves a client already handled) */
        for (int i = nc - 1; i >= 0; i--) {
            client *c = &s->cl[i];
            short re = s->pf[2 + i].revents;
            if (!re) continue;
            int bad = 0;
            if (re & POLLOUT) bad = flush_out(c, now) || serve_frames(s, c, now);
            if (!bad && (re & (POLLIN | POLLHUP | POLLERR))) bad = receive(s, c, now);
            if (bad) drop(s, i, &s->m->dropped);
        }
        if (s->pf[1].revents & POLLIN) admit(s, now);
    }
    return NULL;
}

int mb_server_run(mb_server *s, char *err, size_t errlen)
{
    if (pthread_create(&s->th, NULL, server_thread, s)) {
        snprintf(err, errlen, "cannot start the Modbus thread");
        return -1;
    }
    s->running = 1;
    plc_log(LOG_INFO, "modbus: listening on %s:%d (at most %d clients)", s->bind, s->port, s->max);
    return 0;
}

mb_server *mb_server_listen(const plc_config *c, mb_shared *m, char *err, size_t errlen)
{
    mb_server *s = calloc(1, sizeof *s);
    if (!s || !(s->cl = calloc((size_t)c->mb_max_clients, sizeof *s->cl))
        || !(s->pf = calloc((size_t)c->mb_max_clients + 2, sizeof *s->pf))) {
        if (s) free(s->cl);
        free(s);
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    s->m = m;
    s->max = c->mb_max_clients;
    snprintf(s->bind, sizeof s->bind, "%s", c->mb_bind);
    s->port = c->mb_port;
    s->idle_ns = (uint64_t)c->mb_idle_timeout * 1000 * MS;
    s->wake = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    s->listen_ctx = modbus_new_tcp(c->mb_bind, c->mb_port);
    if (s->wake < 0 || !s->listen_ctx || (s->lfd = modbus_tcp_listen(s->listen_ctx, 64)) < 0) {
        snprintf(err, errlen, "cannot listen on %s:%d: %s", c->mb_bind, c->mb_port, modbus_strerror(errno));
        goto fail;
    }
    fcntl(s->lfd, F_SETFL, fcntl(s->lfd, F_GETFL) | O_NONBLOCK);
    return s;
fail:
    if (s->wake >= 0) close(s->wake);
    if (s->listen_ctx) modbus_free(s->listen_ctx);
    free(s->pf);
    free(s->cl);
    free(s);
    return NULL;
}

void mb_server_stop(mb_server *s)
{
    if (!s) return;
    atomic_store(&s->stop, 1);
    uint64_t one = 1;
    if (write(s->wake, &one, sizeof one) < 0) { /* the poll times out anyway */ }
    if (s->running) pthread_join(s->th, NULL);
    close(s->lfd);
    while (s->n) drop(s, s->n - 1, NULL);
    close(s->wake);
    modbus_free(s->listen_ctx);
    free(s->pf);
    free(s->cl);
    free(s);
}
