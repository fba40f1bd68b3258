/* A small stand-alone CANopen master on the protocol core, for the bus
 * tests and benchmarks: starts the given CiA 401 nodes, then each cycle
 * exchanges PDOs and sends SYNC; program "echo" copies every node's
 * digital inputs to its digital outputs and its analog inputs to its analog
 * outputs. Events are printed with the time in ms since start.
 *   co_testmaster -i vcan0 -n 2,3 [-c cycle_us] [-t seconds] [-s sync_every]
 *                 [-p echo|none] [-H producer_ms:consumer_ms]          */
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "co_master.h"
#include "co_socketcan.h"

static volatile sig_atomic_t stop;
static co_time t_start;

static co_time now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (co_time)ts.tv_sec * 1000000000ull + (co_time)ts.tv_nsec;
}

static void logcb(void *ctx, int err, const char *msg)
{
    (void)ctx;
    printf("%10.3f %s %s\n", (double)(now_ns() - t_start) / 1e6, err ? "error:" : "info:", msg);
    fflush(stdout);
}

static void on_sig(int s) { (void)s; stop = 1; }

int main(int argc, char **argv)
{
    const char *ifname = "vcan0", *prog = "echo";
    char *ids = NULL;
    long cycle_us = 1000, sync_every = 1;
    double seconds = 1e9;
    unsigned hb_prod = 100, hb_cons = 250;
    int opt;
    while ((opt = getopt(argc, argv, "i:n:c:t:s:p:H:")) != -1) {
        switch (opt) {
        case 'i': ifname = optarg; break;
        case 'n': ids = optarg; break;
        case 'c': cycle_us = atol(optarg); break;
        case 't': seconds = atof(optarg); break;
        case 's': sync_every = atol(optarg); break;
        case 'p': prog = optarg; break;
        case 'H':
            if (sscanf(optarg, "%u:%u", &hb_prod, &hb_cons) != 2) {
                fprintf(stderr, "co_testmaster: -H wants producer_ms:consumer_ms\n");
                return 2;
            }
            break;
        default:
            fprintf(stderr, "usage: co_testmaster -i IF -n ID[,ID...] [-c us] [-t s] [-s n] [-p echo|none] [-H p:c]\n");
            return 2;
        }
    }
    if (!ids || cycle_us < 100) {
        fprintf(stderr, "co_testmaster: give node ids with -n and a cycle >= 100 us\n");
        return 2;
    }
    co_node nodes[127];
    int nn = 0;
    for (char *tok = strtok(ids, ","); tok && nn < 127; tok = strtok(NULL, ",")) {
        long id = strtol(tok, NULL, 0);
        if (id < 1 || id > 127) {
            fprintf(stderr, "co_testmaster: node id %s not in 1..127\n", tok);
            return 2;
        }
        co_node_cfg_cia401(&nodes[nn].cfg, (uint8_t)id);
        nodes[nn].cfg.check_type = 1;
        nodes[nn].cfg.hb_producer_ms = (uint16_t)hb_prod;
        nodes[nn].cfg.hb_consumer_ms = (uint16_t)hb_cons;
        nn++;
    }
    char err[256];
    int fd = co_can_open(ifname, err, sizeof err);
    if (fd < 0) {
        fprintf(stderr, "co_testmaster: %s\n", err);
        return 2;
    }
    signal(SIGINT, on_sig);
    signal(SIGTERM, on_sig);
    static co_master m;
    co_master_init(&m, nodes, nn, (unsigned)sync_every);
    m.log = logcb;
    t_start = now_ns();
    co_master_start(&m, t_start);
    int echo = !strcmp(prog, "echo"), settled = 0;
    co_frame f;
    static co_frame batch[64];
    int nb = 0;
    unsigned long overruns = 0;
    co_time period = (co_time)cycle_us * 1000, next = now_ns();
    co_time end = t_start + (co_time)(seconds * 1e9);
    struct timespec ts;
    while (!stop && now_ns() < end) {
        next += period;
        ts.tv_sec = (time_t)(next / 1000000000ull);
        ts.tv_nsec = (long)(next % 1000000000ull);
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR && !stop)
            ;
        co_time now = now_ns();
        if (now > next + period) {          /* late: skip, never replay cycles */
            overruns++;
            next = now;
        }
        int r;
        while ((r = co_can_recv(fd, &f, NULL)) == 1)
            co_master_rx(&m, &f, now);
        if (r < 0)
            co_master_bus(&m, co_can_link_up(fd, ifname) == 1 ? CO_BUS_OK : CO_BUS_DOWN, strerror(errno));
        co_master_tick(&m, now);
        if (!settled && co_master_settled(&m)) {
            settled = 1;
            logcb(NULL, 0, "start-up done");
        }
        for (int i = 0; i < nn && echo; i++) {
            co_node *n = &nodes[i];
            if (n->rx_new & 1)
                memcpy(n->tx[0], n->rx[0], 8);
            if (n->rx_new & 2)
                memcpy(n->tx[1], n->rx[1], 8);
            n->rx_new = 0;
        }
        co_master_cycle(&m, now);
        /* send this cycle's frames, batched; what the queue refuses waits,
         * in order, for the next cycle */
        for (;;) {
            while (nb < 64 && co_master_pop(&m, &batch[nb]))
                nb++;
            if (!nb)
                break;
            r = co_can_send_many(fd, batch, nb);
            if (r < 0) {
                co_master_bus(&m, CO_BUS_DOWN, strerror(errno));
                nb = 0;
                break;
            }
            memmove(batch, batch + r, sizeof batch[0] * (size_t)(nb - r));
            nb -= r;
            if (nb)
                break;
        }
    }
    for (int i = 0; i < nn; i++) {
        co_node *n = &nodes[i];
        printf("node %u: %s faults 0x%02X starts %u unexpected_boot %u hb_lost %u emcy %u "
               "sdo_errors %u rx %u tx %u\n", n->cfg.id, co_phase_name(n->phase), n->fault,
               n->starts, n->unexpected_boot, n->hb_lost, n->emcy_count, n->sdo_errors,
               n->rx_pdos, n->tx_pdos);
    }
    printf("bus: sync %u err_frames %u busoff %u dropped %u overruns %lu\n", m.sync.sent,
           m.err_frames, m.busoff_count, m.tx_dropped, overruns);
    close(fd);
    return 0;
}
