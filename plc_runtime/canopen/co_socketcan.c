#include <errno.h>
#include <net/if.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>
#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <linux/if_arp.h>
#include "co_socketcan.h"

int co_can_open(const char *ifname, char *err, size_t errlen)
{
    int fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
    if (fd < 0) {
        if (errno == EAFNOSUPPORT || errno == EPROTONOSUPPORT)
            snprintf(err, errlen, "CAN interface %s: this kernel has no CAN support "
                     "(modules can, can-raw not loaded)", ifname);
        else
            snprintf(err, errlen, "CAN interface %s: socket: %s", ifname, strerror(errno));
        return -1;
    }
    struct ifreq ifr;
    memset(&ifr, 0, sizeof ifr);
    if (strlen(ifname) >= sizeof ifr.ifr_name) {
        snprintf(err, errlen, "CAN interface %s: name too long", ifname);
        goto bad;
    }
    strcpy(ifr.ifr_name, ifname);
    if (ioctl(fd, SIOCGIFINDEX, &ifr) < 0) {
        snprintf(err, errlen, "CAN interface %s: no such interface", ifname);
        goto bad;
    }
    int index = ifr.ifr_ifindex;
    if (ioctl(fd, SIOCGIFHWADDR, &ifr) == 0 && ifr.ifr_hwaddr.sa_family != ARPHRD_CAN) {
        snprintf(err, errlen, "CAN interface %s: not a CAN interface", ifname);
        goto bad;
    }
    can_err_mask_t mask = CAN_ERR_MASK;
    setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &mask, sizeof mask);
    int on = 1;                 /* receive timestamps: a frame's age (co_can_recv) */
    setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
    struct sockaddr_can addr;
    memset(&addr, 0, sizeof addr);
    addr.can_family = AF_CAN;
    addr.can_ifindex = index;
    if (bind(fd, (struct sockaddr *)&addr, sizeof addr) < 0) {
        snprintf(err, errlen, "CAN interface %s: bind: %s", ifname, strerror(errno));
        goto bad;
    }
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
    return fd;
bad:
    close(fd);
    return -1;
}

int co_can_send(int fd, const co_frame *f)
{
    struct can_frame cf;
    memset(&cf, 0, sizeof cf);
    cf.can_id = f->id & CAN_SFF_MASK;
    if (f->rtr)
        cf.can_id |= CAN_RTR_FLAG;
    cf.can_dlc = f->len > 8 ? 8 : f->len;
    memcpy(cf.data, f->data, cf.can_dlc);
    ssize_t r = write(fd, &cf, sizeof cf);
    if (r == (ssize_t)sizeof cf)
        return 1;
    if (r < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS))
        return 0;
    return -1;
}

int co_can_send_many(int fd, const co_frame *f, int n)
{
    struct can_frame cf[64];
    struct iovec iov[64];
    struct mmsghdr mh[64];
    if (n > 64)
        n = 64;
    memset(cf, 0, sizeof cf[0] * (size_t)n);
    memset(mh, 0, sizeof mh[0] * (size_t)n);
    for (int i = 0; i < n; i++) {
        cf[i].can_id = (f[i].id & CAN_SFF_MASK) | (f[i].rtr ? CAN_RTR_FLAG : 0);
        cf[i].can_dlc = f[i].len > 8 ? 8 : f[i].len;
        memcpy(cf[i].data, f[i].data, cf[i].can_dlc);
        iov[i] = (struct iovec){ &cf[i], sizeof cf[i] };
        mh[i].msg_hdr.msg_iov = &iov[i];
        mh[i].msg_hdr.msg_iovlen = 1;
    }
    int r = sendmmsg(fd, mh, (unsigned)n, 0);
    if (r < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS))
        return 0;
    return r;
}

/* ns from the kernel's receive timestamp of msg to now (both wall clock:
 * what SO_TIMESTAMPNS gives); 0 without one or if the clock stepped back */
static co_time frame_age(struct msghdr *msg)
{
    for (struct cmsghdr *c = CMSG_FIRSTHDR(msg); c; c = CMSG_NXTHDR(msg, c)) {
        if (c->cmsg_level != SOL_SOCKET || c->cmsg_type != SCM_TIMESTAMPNS)
            continue;
        struct timespec ts, now;
        memcpy(&ts, CMSG_DATA(c), sizeof ts);
        clock_gettime(CLOCK_REALTIME, &now);
        long long d = (long long)(now.tv_sec - ts.tv_sec) * 1000000000LL + (now.tv_nsec - ts.tv_nsec);
        return d > 0 ? (co_time)d : 0;
    }
    return 0;
}

int co_can_recv(int fd, co_frame *f, co_time *age)
{
    struct can_frame cf;
    union {                     /* aligned room for the timestamp's cmsg */
        char buf[CMSG_SPACE(sizeof(struct timespec))];
        struct cmsghdr align;
    } ctl;
    for (;;) {
        struct iovec iov = { &cf, sizeof cf };
        struct msghdr msg = { .msg_iov = &iov, .msg_iovlen = 1,
                              .msg_control = ctl.buf, .msg_controllen = sizeof ctl.buf };
        ssize_t r = recvmsg(fd, &msg, 0);
        if (r < 0)
            return (errno == EAGAIN || errno == EWOULDBLOCK) ? 0 : -1;
        if (r != (ssize_t)sizeof cf || (cf.can_id & CAN_EFF_FLAG && !(cf.can_id & CAN_ERR_FLAG)))
            continue;                       /* CAN FD or 29-bit: not CANopen */
        memset(f, 0, sizeof *f);
        f->len = cf.can_dlc > 8 ? 8 : cf.can_dlc;
        memcpy(f->data, cf.data, f->len);
        if (cf.can_id & CAN_ERR_FLAG)
            f->id = CO_ERR_FLAG | (cf.can_id & CAN_ERR_MASK);
        else {
            f->id = cf.can_id & CAN_SFF_MASK;
            f->rtr = !!(cf.can_id & CAN_RTR_FLAG);
        }
        if (age)
            *age = frame_age(&msg);
        return 1;
    }
}

int co_can_link_up(int fd, const char *ifname)
{
    struct ifreq ifr;
    memset(&ifr, 0, sizeof ifr);
    snprintf(ifr.ifr_name, sizeof ifr.ifr_name, "%s", ifname);
    if (ioctl(fd, SIOCGIFFLAGS, &ifr) < 0)
        return -1;
    return (ifr.ifr_flags & IFF_UP) && (ifr.ifr_flags & IFF_RUNNING) ? 1 : 0;
}

int co_can_wait(int fd, long long timeout_ns)
{
    struct pollfd p = { .fd = fd, .events = POLLIN };
    int ms = timeout_ns <= 0 ? 0 : (int)((timeout_ns + 999999) / 1000000);
    return poll(&p, 1, ms);
}
