/* mbrtu.c: see mbrtu.h. */
#include <errno.h>
#include <modbus.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/select.h>
#include "log.h"
#include "mbrtu.h"

struct mb_rtu {
    mb_shared *m;
    modbus_t *ctx;
    int fd;
    char device[128];
    pthread_t th;
    int running;
    _Atomic int stop;
};

static void serve(mb_rtu *r, const uint8_t *q, int n)
{
    uint8_t rsp[1 + MB_PDU_MAX];
    pthread_mutex_lock(&r->m->serve);
    size_t pl = mb_process(r->m, q + 1, (size_t)n - 3, rsp + 1);
    pthread_mutex_unlock(&r->m->serve);
    atomic_fetch_add(&r->m->rtu_served, 1);
    if (q[0] == 0) return;                       /* broadcast: no reply */
    rsp[0] = q[0];
    if (modbus_send_raw_request(r->ctx, rsp, (int)pl + 1) < 0)
        plc_log(LOG_DEBUG, "modbus_rtu: reply not sent: %s", modbus_strerror(errno));
}

static void *rtu_thread(void *arg)
{
    mb_rtu *r = arg;
    uint8_t q[MODBUS_RTU_MAX_ADU_LENGTH];
    while (!atomic_load(&r->stop)) {
        pthread_mutex_lock(&r->m->serve);
        int pending = mb_flush(r->m);
        pthread_mutex_unlock(&r->m->serve);
        fd_set rd;
        FD_ZERO(&rd);
        FD_SET(r->fd, &rd);
        struct timeval tv = { 0, pending ? 250 : 100000 };
        if (select(r->fd + 1, &rd, NULL, NULL, &tv) <= 0) continue;
        int n = modbus_receive(r->ctx, q);
        if (n == 0) continue;                    /* for another slave */
        if (n < 4) {                             /* CRC error, noise, a frame cut short */
            atomic_fetch_add(&r->m->rtu_bad, 1);
            modbus_flush(r->ctx);
            continue;
        }
        serve(r, q, n);
    }
    return NULL;
}

mb_rtu *mb_rtu_open(const plc_config *c, mb_shared *m, char *err, size_t errlen)
{
    mb_rtu *r = calloc(1, sizeof *r);
    if (!r) { snprintf(err, errlen, "out of memory"); return NULL; }
    r->m = m;
    snprintf(r->device, sizeof r->device, "%s", c->rtu_device);
    r->ctx = modbus_new_rtu(c->rtu_device, c->rtu_baud, c->rtu_parity, c->rtu_data_bits, c->rtu_stop_bits);
    if (!r->ctx || modbus_set_slave(r->ctx, c->rtu_slave) || modbus_connect(r->ctx)) {
        snprintf(err, errlen, "cannot open %s: %s", c->rtu_device, modbus_strerror(errno));
        if (r->ctx) modbus_free(r->ctx);
        free(r);
        return NULL;
    }
    r->fd = modbus_get_socket(r->ctx);
    /* a frame's bytes follow each other: 0.1 s of silence ends a broken one */
    modbus_set_byte_timeout(r->ctx, 0, 100000);
    return r;
}

int mb_rtu_run(mb_rtu *r, char *err, size_t errlen)
{
    if (pthread_create(&r->th, NULL, rtu_thread, r)) {
        snprintf(err, errlen, "cannot start the Modbus RTU thread");
        return -1;
    }
    r->running = 1;
    plc_log(LOG_INFO, "modbus_rtu: serving on %s", r->device);
    return 0;
}

void mb_rtu_stop(mb_rtu *r)
{
    if (!r) return;
    atomic_store(&r->stop, 1);
    if (r->running) pthread_join(r->th, NULL);
    modbus_close(r->ctx);
    modbus_free(r->ctx);
    free(r);
}
