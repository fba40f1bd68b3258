/*
** mbloop.c: the bound the remote I/O benchmark compares plcrt's modbus_io
** polling with: a plain libmodbus client loop, one thread and one
** connection per device, each reading 125 holding registers as fast as the
** server answers, nothing else. Prints the polls per second per device and
** the duration of one poll (median, p99, in us): the age an input has at
** best when a program takes it just as the next poll ends.
** usage: mbloop PORT DEVICES SECONDS
*/
#include <errno.h>
#include <modbus.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define MAXS 2000000

static int port, seconds;
static double t_end;

typedef struct { long n; double *dur; } res;

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + t.tv_nsec / 1e9;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static void *loop(void *arg)
{
    res *r = arg;
    uint16_t regs[125];
    modbus_t *c = modbus_new_tcp("127.0.0.1", port);
    if (!c || modbus_connect(c)) { fprintf(stderr, "mbloop: %s\n", modbus_strerror(errno)); exit(1); }
    while (now() < t_end) {
        double t0 = now();
        if (modbus_read_registers(c, 0, 125, regs) != 125) { fprintf(stderr, "mbloop: %s\n", modbus_strerror(errno)); exit(1); }
        if (r->n < MAXS) r->dur[r->n] = now() - t0;
        r->n++;
    }
    modbus_close(c);
    modbus_free(c);
    return NULL;
}

int main(int argc, char **argv)
{
    if (argc != 4) { fprintf(stderr, "usage: mbloop PORT DEVICES SECONDS\n"); return 2; }
    port = atoi(argv[1]);
    int n = atoi(argv[2]);
    seconds = atoi(argv[3]);
    pthread_t th[256];
    res r[256];
    t_end = now() + seconds;
    for (int i = 0; i < n && i < 256; i++) {
        r[i].n = 0;
        r[i].dur = malloc(MAXS * sizeof(double));
        pthread_create(&th[i], NULL, loop, &r[i]);
    }
    long total = 0, k = 0;
    double *all = malloc(MAXS * sizeof(double));
    for (int i = 0; i < n; i++) {
        pthread_join(th[i], NULL);
        total += r[i].n;
        for (long j = 0; j < r[i].n && j < MAXS && k < MAXS; j++) all[k++] = r[i].dur[j];
    }
    qsort(all, (size_t)k, sizeof *all, cmp);
    printf("%.1f %.1f %.1f\n", (double)total / n / seconds, k ? all[k / 2] * 1e6 : 0, k ? all[k * 99 / 100] * 1e6 : 0);
    return 0;
}
