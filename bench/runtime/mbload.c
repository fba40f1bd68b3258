/*
** mbload.c: Modbus TCP load for the benchmark: N clients (one thread and one
** libmodbus connection each) read 125 holding registers (FC 3) back to back
** for a given time; prints the requests per second of all of them.
** usage: mbload PORT CLIENTS SECONDS
*/
#include <errno.h>
#include <modbus.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

static int port;
static _Atomic int stop, failed;
static _Atomic long total;

static void *client(void *arg)
{
    (void)arg;
    uint16_t regs[125];
    long n = 0;
    modbus_t *ctx = modbus_new_tcp("127.0.0.1", port);
    if (!ctx || modbus_connect(ctx)) { atomic_store(&failed, 1); return NULL; }
    while (!atomic_load(&stop)) {
        if (modbus_read_registers(ctx, 0, 125, regs) != 125) { atomic_store(&failed, 1); break; }
        n++;
    }
    modbus_close(ctx);
    modbus_free(ctx);
    atomic_fetch_add(&total, n);
    return NULL;
}

int main(int argc, char **argv)
{
    if (argc != 4) { fprintf(stderr, "usage: mbload PORT CLIENTS SECONDS\n"); return 2; }
    port = atoi(argv[1]);
    int n = atoi(argv[2]);
    double secs = atof(argv[3]);
    pthread_t th[256];
    if (n < 1 || n > 256) return 2;
    for (int i = 0; i < n; i++) pthread_create(&th[i], NULL, client, NULL);
    struct timespec t = { (time_t)secs, (long)((secs - (time_t)secs) * 1e9) };
    nanosleep(&t, NULL);
    atomic_store(&stop, 1);
    for (int i = 0; i < n; i++) pthread_join(th[i], NULL);
    printf("%.0f requests/s%s\n", atomic_load(&total) / secs, atomic_load(&failed) ? " (errors)" : "");
    return atomic_load(&failed);
}
