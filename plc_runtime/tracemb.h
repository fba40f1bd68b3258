/*
** tracemb.h: the trace and forcing register block of the Modbus server
** (holding registers 60000-60428, docs/trace.md): a status block, a
** command mailbox (one FC 16 write: owner token, command, arguments) and a
** read-out window whose content a selector chooses (a channel's samples,
** cycle numbers, PLC ticks, a variable's name, the forced list). A remote
** tool needs nothing but the Modbus port.
**
** The idea: every request is served whole in the server thread, checked
** before anything changes, so a bad one is an exception and changes
** nothing; trace commands need the owner's token, and a running trace's
** setup is frozen, so a second client cannot corrupt it. The capture read
** is a completed one (trace.h), never one the scan is filling.
*/
#ifndef TRACEMB_H
#define TRACEMB_H

#include <stddef.h>
#include <stdint.h>
#include "force.h"
#include "mbmap.h"
#include "program.h"
#include "trace.h"

#define TB_BASE    MB_TRACE_BASE          /* status, 32 registers (read) */
#define TB_STATUS_N 32
#define TB_CMD     60100           /* mailbox (FC 16 only) */
#define TB_CMD_N   123
#define TB_SEL     60300           /* selector: what, first (32-bit) */
#define TB_SEL_N   3
#define TB_WIN     60304           /* window (read) */
#define TB_WIN_N   125
#define TB_END     (TB_WIN + TB_WIN_N)

typedef struct tracemb tracemb;

tracemb *tb_new(trace *t, forcing *f, const plc_program *p, uint64_t period_ns);
void tb_free(tracemb *b);
/* Does the request PDU touch the block? */
int tb_touches(const uint8_t *pdu, size_t n);
/* Serve a request that touches the block (FC 3, 6, 16, 23; others are not
** passed here); the reply PDU in rsp, its length returned. *exc is set
** when the reply is an exception. */
size_t tb_serve(tracemb *b, const uint8_t *pdu, size_t n, uint8_t *rsp, int *exc);
/* The block as the Modbus map takes it (mbmap.h). */
mb_block tb_block(tracemb *b);
/* Server thread, often: publish a forcing change that waits; 1 while one does. */
int tb_flush(tracemb *b);

#endif
