/* SocketCAN link: a CAN_RAW socket, error frames enabled, non-blocking. */
#ifndef CO_SOCKETCAN_H
#define CO_SOCKETCAN_H

#include <stddef.h>
#include "co_frame.h"

/* Open and bind a raw CAN socket on ifname. Returns the descriptor, or -1
 * with a message naming the interface in err (no CAN support in the kernel,
 * no such interface, not a CAN interface, ...). */
int co_can_open(const char *ifname, char *err, size_t errlen);
/* 1 sent, 0 would block (queue full), -1 error (errno set: ENETDOWN...). */
int co_can_send(int fd, const co_frame *f);
/* Send up to n frames with one system call (sendmmsg); returns how many
 * went out (0 if the queue is full), -1 on error (errno set). */
int co_can_send_many(int fd, const co_frame *f, int n);
/* 1 a frame in *f (error frames carry CO_ERR_FLAG), 0 nothing, -1 error.
 * age (if not NULL): ns since the kernel received the frame (its receive
 * timestamp), 0 when the kernel gave none. */
int co_can_recv(int fd, co_frame *f, co_time *age);
/* 1 if the interface is up and running, 0 if not, -1 if it is gone. */
int co_can_link_up(int fd, const char *ifname);
/* Wait up to timeout_ns for the socket to become readable. */
int co_can_wait(int fd, long long timeout_ns);

#endif
