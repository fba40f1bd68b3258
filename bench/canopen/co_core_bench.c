/* CPU cost of the master's protocol core per cycle, without a bus: for 1, 8
 * and 32 CiA 401 nodes (2 TPDOs in, 2 RPDOs + SYNC out per node and cycle),
 * frames fed to co_master_rx, then co_master_tick, co_master_cycle and every
 * frame popped. Compared with the 1 ms cycle it has to fit in. */
#include <stdio.h>
#include <string.h>
#include <time.h>
#include "co_master.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec / 1e9;
}

int main(void)
{
    static co_node nodes[32];
    static co_master m;
    int counts[] = { 1, 8, 32 };
    for (int c = 0; c < 3; c++) {
        int nn = counts[c];
        for (int i = 0; i < nn; i++)
            co_node_cfg_cia401(&nodes[i].cfg, (uint8_t)(i + 1));
        co_master_init(&m, nodes, nn, 1);
        for (int i = 0; i < nn; i++) {
            nodes[i].phase = CO_PH_RUN;
            nodes[i].hb.active = 0;
        }
        const int cycles = 200000 / nn;
        co_frame f;
        long out = 0;
        double t0 = now();
        for (int k = 0; k < cycles; k++) {
            co_time t = (co_time)k * 1000000;
            for (int i = 0; i < nn; i++)
                for (int p = 0; p < 2; p++) {
                    memset(&f, 0, sizeof f);
                    f.id = (uint32_t)(0x180 + 0x100 * p + i + 1);
                    f.len = 8;
                    f.data[0] = (uint8_t)k;
                    co_master_rx(&m, &f, t);
                }
            co_master_tick(&m, t);
            for (int i = 0; i < nn; i++) {
                memcpy(nodes[i].tx[0], nodes[i].rx[0], 8);
                memcpy(nodes[i].tx[1], nodes[i].rx[1], 8);
                nodes[i].rx_new = 0;
            }
            co_master_cycle(&m, t);
            while (co_master_pop(&m, &f))
                out++;
        }
        double us = (now() - t0) / cycles * 1e6;
        printf("core, %2d nodes: %.2f us of CPU per cycle (%d PDOs in, %d frames out), "
               "%.2f %% of a 1 ms cycle\n", nn, us, 2 * nn, (int)(out / cycles), us / 10.0);
    }
    return 0;
}
