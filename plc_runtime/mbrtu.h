/*
** mbrtu.h: the Modbus RTU server, plcrt's map (mbmap.h, docs/modbus.md) on
** a serial line for serial HMIs and SCADA ([modbus_rtu], docs/config.md).
**
** One thread: it waits for a frame's first byte (a short tick, so that a
** stop is seen), reads the frame with libmodbus's RTU framing (CRC checked,
** frames for other slaves ignored), has mbmap serve it and sends the
** reply; a broadcast (slave 0) is served without a reply. It serves under
** the map's `serve` lock, taking turns with the TCP server, so that a
** request is checked whole before any of it lands, as over TCP; the scan
** never waits for either. A malformed frame (a CRC error, noise, a frame
** cut short) is counted, the line flushed, and the next frame served.
*/
#ifndef MBRTU_H
#define MBRTU_H

#include "config.h"
#include "mbmap.h"

typedef struct mb_rtu mb_rtu;

/* Open c->rtu_device with the configured settings; NULL with a message in
** err. Nothing is served before mb_rtu_run. */
mb_rtu *mb_rtu_open(const plc_config *c, mb_shared *m, char *err, size_t errlen);
/* Start serving (its thread). 0, or -1 with a message in err. */
int mb_rtu_run(mb_rtu *r, char *err, size_t errlen);
/* Stop (a request being served gets its reply first), close the port. */
void mb_rtu_stop(mb_rtu *r);

#endif
