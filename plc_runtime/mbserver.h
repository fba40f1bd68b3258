/*
** mbserver.h: the Modbus TCP server. One thread accepts; each client gets
** its own thread (libmodbus frames the requests, mbmap serves them), so a
** slow, silent or half-sending client only ever waits on itself. Clients
** beyond max_clients, or whose descriptor libmodbus's select() could not
** watch (>= FD_SETSIZE), are closed at once and counted as refused.
*/
#ifndef MBSERVER_H
#define MBSERVER_H

#include "config.h"
#include "mbmap.h"

typedef struct mb_server mb_server;

/* Listen on the configured address; NULL with a message in err. */
mb_server *mb_server_start(const plc_config *c, mb_shared *m, char *err, size_t errlen);
/* Stop accepting, finish the requests being served (their replies are
** sent), close every client, join the threads. */
void mb_server_stop(mb_server *s);

#endif
