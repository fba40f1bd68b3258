/*
** mbserver.h: the Modbus TCP server. One thread serves every client: it
** polls non-blocking sockets, frames the requests itself from the MBAP
** header (the length field says where the next request begins, whatever
** the function code) and has mbmap serve them. No client can hold it or
** the scan: a frame must be complete 0.5 s after its first byte, a reply
** the client does not take within 2 s closes it, a client silent for
** idle_timeout is closed, and at max_clients the client idle the longest
** gives way to a new one. A protocol id other than 0, or a length no
** Modbus TCP frame has, closes the connection.
*/
#ifndef MBSERVER_H
#define MBSERVER_H

#include "config.h"
#include "mbmap.h"

typedef struct mb_server mb_server;

/* Take the configured address and port (so that a second plcrt on the
** same port stops before it touches any I/O); NULL with a message in err.
** Nothing is served before mb_server_run: connections wait in the queue. */
mb_server *mb_server_listen(const plc_config *c, mb_shared *m, char *err, size_t errlen);
/* Start serving (the server's thread). 0, or -1 with a message in err. */
int mb_server_run(mb_server *s, char *err, size_t errlen);
/* Stop serving (also before mb_server_run) (a request being served gets its reply first), close every
** client, join the thread: no write is taken after it returns. */
void mb_server_stop(mb_server *s);

#endif
