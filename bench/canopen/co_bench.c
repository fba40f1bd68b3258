/* Benchmark peer: N simulated CiA 401 nodes (ids 1..N) on one CAN_RAW
 * socket, answering NMT, SDO (expedited) and SYNC like the python slaves,
 * fast enough for 1 ms cycles with 32 nodes. Each TPDO1 carries in byte 0
 * the number of the SYNC it answers; the master's echo program sends it back
 * in RPDO1, so the time from SYNC k to the RPDO1 carrying k (kernel receive
 * timestamps on this socket) is the master's SYNC-to-RPDO latency.
 *   co_bench -i vcan0 -n N -t seconds -c cycle_us
 * Prints the figures and the bus load the traffic would put on 1 Mbit/s. */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <net/if.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>
#include <linux/can.h>
#include <linux/can/raw.h>

#define MAXN 127
#define MAXS 200000

typedef struct { uint32_t od[64][3]; int n; int state; uint16_t hb_ms; double hb_next; } node;
static node nodes[MAXN + 1];
static int fd;

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec / 1e9;
}

static void tx(uint32_t id, int len, const uint8_t *d)
{
    struct can_frame f = { .can_id = id, .can_dlc = (uint8_t)len };
    memcpy(f.data, d, (size_t)len);
    while (write(fd, &f, sizeof f) < 0 && (errno == ENOBUFS || errno == EAGAIN))
        usleep(50);
}

static uint32_t *od(node *n, uint16_t i, uint8_t s)
{
    for (int k = 0; k < n->n; k++)
        if (n->od[k][0] == i && n->od[k][1] == s)
            return &n->od[k][2];
    if (n->n >= 64)
        return &n->od[63][2];
    n->od[n->n][0] = i;
    n->od[n->n][1] = s;
    n->od[n->n][2] = 0;
    return &n->od[n->n++][2];
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* bits of a standard data frame on the wire: 47 + 8n, plus stuff bits over
 * the 34 + 8n bits from SOF to the CRC: worst case one per 4 after the
 * first, typical (random data) about one per 19 (2^-4 chance per bit of
 * 5 equal bits ending there, counted from the data as sent) */
static double frame_bits(int n, int worst)
{
    double stuffed = 34 + 8 * n;
    return 47 + 8 * n + (worst ? floor((stuffed - 1) / 4) : stuffed / 19.0);
}

int main(int argc, char **argv)
{
    const char *ifname = "vcan0";
    int nn = 1, opt;
    double secs = 3, cycle_us = 1000;
    while ((opt = getopt(argc, argv, "i:n:t:c:")) != -1) {
        if (opt == 'i') ifname = optarg;
        else if (opt == 'n') nn = atoi(optarg);
        else if (opt == 't') secs = atof(optarg);
        else if (opt == 'c') cycle_us = atof(optarg);
    }
    if (nn < 1 || nn > MAXN) {
        fprintf(stderr, "co_bench: -n 1..%d\n", MAXN);
        return 2;
    }
    fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
    struct ifreq ifr;
    memset(&ifr, 0, sizeof ifr);
    snprintf(ifr.ifr_name, sizeof ifr.ifr_name, "%s", ifname);
    if (fd < 0 || ioctl(fd, SIOCGIFINDEX, &ifr) < 0) {
        fprintf(stderr, "co_bench: CAN interface %s: %s\n", ifname, strerror(errno));
        return 2;
    }
    struct sockaddr_can a = { .can_family = AF_CAN, .can_ifindex = ifr.ifr_ifindex };
    int one = 1, rcv = 4 << 20;
    setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof one);
    setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcv, sizeof rcv);
    if (bind(fd, (struct sockaddr *)&a, sizeof a) < 0) {
        perror("co_bench: bind");
        return 2;
    }
    static double sync_t[256], lat[MAXS];
    int nlat = 0, running = 0;
    long syncs = 0, rpdos = 0, tpdos = 0, frames_master = 0, bytes_master = 0, missing = 0;
    uint8_t sync_no = 0;
    double t_meas = 0, t_end = now() + 60;   /* start-up must finish within 60 s */
    static uint8_t last_seq[MAXN + 1];
    for (;;) {
        double t = now();
        if (t >= t_end)
            break;
        for (int i = 1; i <= nn; i++)      /* heartbeat producers */
            if (nodes[i].hb_ms && t >= nodes[i].hb_next) {
                uint8_t st = (uint8_t)nodes[i].state;
                tx(0x700u + i, 1, &st);
                nodes[i].hb_next = t + nodes[i].hb_ms / 1000.0;
            }
        struct pollfd p = { .fd = fd, .events = POLLIN };
        if (poll(&p, 1, 5) <= 0)
            continue;
        /* read everything queued with one call */
        static struct can_frame rf[256];
        static struct iovec riov[256];
        static struct mmsghdr rmm[256];
        static char rcb[256][CMSG_SPACE(sizeof(struct timespec))];
        for (int i = 0; i < 256; i++) {
            riov[i] = (struct iovec){ &rf[i], sizeof rf[i] };
            memset(&rmm[i], 0, sizeof rmm[i]);
            rmm[i].msg_hdr.msg_iov = &riov[i];
            rmm[i].msg_hdr.msg_iovlen = 1;
            rmm[i].msg_hdr.msg_control = rcb[i];
            rmm[i].msg_hdr.msg_controllen = sizeof rcb[i];
        }
        int got = recvmmsg(fd, rmm, 256, MSG_DONTWAIT, NULL);
        for (int g = 0; g < got; g++) {
        struct can_frame f = rf[g];
        struct msghdr mh = rmm[g].msg_hdr;
        if (rmm[g].msg_len != sizeof f)
            continue;
        double ts = t;
        for (struct cmsghdr *c = CMSG_FIRSTHDR(&mh); c; c = CMSG_NXTHDR(&mh, c))
            if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_TIMESTAMPNS) {
                struct timespec k;
                memcpy(&k, CMSG_DATA(c), sizeof k);
                ts = k.tv_sec + k.tv_nsec / 1e9;
            }
        uint32_t id = f.can_id & CAN_SFF_MASK;
        if (t_meas && ts >= t_meas) {
            frames_master++;
            bytes_master += f.can_dlc;
        }
        if (id == 0 && f.can_dlc >= 2) {                  /* NMT */
            for (int i = 1; i <= nn; i++) {
                if (f.data[1] && f.data[1] != i)
                    continue;
                if (f.data[0] == 0x81 || f.data[0] == 0x82) {
                    uint8_t z = 0;
                    nodes[i].state = 0x7F;
                    tx(0x700u + i, 1, &z);
                } else if (f.data[0] == 0x01)
                    nodes[i].state = 5;
            }
            int all = 1;
            for (int i = 1; i <= nn; i++)
                all &= nodes[i].state == 5;
            if (all && !running) {
                running = 1;
                t_meas = now() + 0.5;                 /* settle */
                t_end = t_meas + secs;
            }
        } else if (id == 0x080) {                          /* SYNC */
            syncs += t_meas && ts >= t_meas;
            sync_no++;
            sync_t[sync_no] = ts;
            static struct can_frame out[2 * MAXN];
            static struct iovec iov2[2 * MAXN];
            static struct mmsghdr mm[2 * MAXN];
            int k = 0;
            for (int i = 1; i <= nn; i++) {
                if (nodes[i].state != 5)
                    continue;
                for (int p = 0; p < 2; p++, k++) {
                    memset(&out[k], 0, sizeof out[k]);
                    out[k].can_id = (uint32_t)(0x180 + 0x100 * p + i);
                    out[k].can_dlc = 8;
                    out[k].data[0] = p ? 0 : sync_no;
                    iov2[k] = (struct iovec){ &out[k], sizeof out[k] };
                    memset(&mm[k], 0, sizeof mm[k]);
                    mm[k].msg_hdr.msg_iov = &iov2[k];
                    mm[k].msg_hdr.msg_iovlen = 1;
                }
                tpdos += 2 * (t_meas && ts >= t_meas);
            }
            for (int sent = 0; sent < k; ) {
                int r = sendmmsg(fd, mm + sent, (unsigned)(k - sent), 0);
                if (r > 0)
                    sent += r;
                else
                    usleep(50);
            }
        } else if (id > 0x600 && id <= 0x600 + (uint32_t)nn && f.can_dlc == 8) {   /* SDO */
            node *n = &nodes[id - 0x600];
            uint8_t r[8] = { 0 };
            memcpy(r + 1, f.data + 1, 3);
            uint16_t idx = (uint16_t)(f.data[1] | f.data[2] << 8);
            uint8_t sub = f.data[3];
            if (f.data[0] == 0x40) {
                r[0] = 0x43;
                uint32_t v = idx == 0x1000 ? 0x191 : *od(n, idx, sub);
                memcpy(r + 4, &v, 4);
            } else if ((f.data[0] & 0xE3) == 0x23) {
                uint32_t v = 0;
                memcpy(&v, f.data + 4, 4 - ((f.data[0] >> 2) & 3));
                *od(n, idx, sub) = v;
                if (idx == 0x1017)
                    n->hb_ms = (uint16_t)v;
                r[0] = 0x60;
            } else {
                r[0] = 0x80;
                r[6] = 0x04;
                r[7] = 0x05;
            }
            tx(id - 0x600 + 0x580, 8, r);
        } else if (id > 0x200 && id <= 0x200 + (uint32_t)nn) {                      /* RPDO1 */
            if (!(t_meas && ts >= t_meas))
                continue;
            rpdos++;
            int i = (int)(id - 0x200);
            uint8_t k = f.data[0];
            if (k != last_seq[i]) {
                if (last_seq[i] && (uint8_t)(k - last_seq[i]) > 1)
                    missing += (uint8_t)(k - last_seq[i]) - 1;
                last_seq[i] = k;
                if (sync_t[k] && nlat < MAXS)
                    lat[nlat++] = (ts - sync_t[k]) * 1e6;
            }
        } else if (id > 0x300 && id <= 0x300 + (uint32_t)nn) {
            rpdos += t_meas && ts >= t_meas;
        }
        }
    }
    if (!running) {
        printf("nodes %d: start-up did not finish\n", nn);
        return 1;
    }
    qsort(lat, (size_t)nlat, sizeof lat[0], cmp);
    double sum = 0;
    for (int i = 0; i < nlat; i++)
        sum += lat[i];
    double per_cycle_bits_nom = frame_bits(0, 0) + nn * 4 * frame_bits(8, 0) + nn * frame_bits(1, 0) * (cycle_us / 100000.0);
    double per_cycle_bits_worst = frame_bits(0, 1) + nn * 4 * frame_bits(8, 1) + nn * frame_bits(1, 1) * (cycle_us / 100000.0);
    double load_typ = per_cycle_bits_nom / cycle_us * 100.0;      /* 1 bit per us at 1 Mbit/s */
    double load_worst = per_cycle_bits_worst / cycle_us * 100.0;
    printf("nodes %2d, cycle %.0f us, %.1f s: SYNC %ld, TPDO %ld (%.0f/s), RPDO %ld (%.0f/s), "
           "echoes lost %ld\n", nn, cycle_us, secs, syncs, tpdos, tpdos / secs, rpdos, rpdos / secs, missing);
    if (nlat)
        printf("nodes %2d: SYNC-to-RPDO latency us: mean %.0f, median %.0f, p99 %.0f, max %.0f (%d samples)\n",
               nn, sum / nlat, lat[nlat / 2], lat[(int)(nlat * 0.99)], lat[nlat - 1], nlat);
    printf("nodes %2d: on a real 1 Mbit/s bus each cycle needs %.0f bits (%.0f worst-case stuffing): "
           "bus load %.0f %% (%.0f %%) -> %s\n", nn, per_cycle_bits_nom, per_cycle_bits_worst,
           load_typ, load_worst, load_worst <= 100 ? "fits" : load_typ <= 100 ? "fits only without worst-case stuffing" : "does NOT fit");
    double min_cycle = per_cycle_bits_worst / 0.7;   /* keep the bus below 70 % */
    printf("nodes %2d: shortest cycle for <= 70 %% load (worst-case stuffing): %.0f us\n", nn, min_cycle);
    return 0;
}
